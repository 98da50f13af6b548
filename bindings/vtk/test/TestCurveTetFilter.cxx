// ctest programs of vtkCurveTetFilter (bindings/vtk/CMakeLists.txt registers them):
//   TestCurveTetFilter pipeline SURFACE.stl|SURFACE.off OUTDIR
//       vtkSTLReader -> vtkCurveTetFilter -> vtkXMLUnstructuredGridWriter; the .vtu read back
//       has only VTK_QUADRATIC_TETRA cells, a positive Jacobian at sample points (VTK's own
//       vtkQuadraticTetra derivatives), ScaledJacobian equal to VTK's own evaluation, and a
//       volume equal to the one enclosed by the curved boundary; progress is monotone.
//       (An .off is first converted to an ASCII STL with vtkSTLWriter.)
//   TestCurveTetFilter p2 SURFACE_p2.msh
//       a vtkUnstructuredGrid of VTK_QUADRATIC_TRIANGLE cells (the file read with curvetet's
//       C reader) -> filter: boundary nodes bit-identical, tags kept, uniform size.
//   TestCurveTetFilter bad SURFACE.off
//       open surface, wrong cell types, lines: vtkErrorMacro with curvetet's message, empty
//       outputs, no crash; the same filter then meshes a good surface.
//   TestCurveTetFilter off2stl SURFACE.off SURFACE.stl   (input of the consumer test)
//   TestCurveTetFilter abort SURFACE.off
//       AbortExecute set from a progress observer stops the meshing: empty output, no error;
//       the next update runs to the end.
//   TestCurveTetFilter smooth SURFACE.off
//       a raw marching-cubes surface with SmoothIterations 10: it meshes, its vertices moved.
//   TestCurveTetFilter thorough SURFACE.off
//       a surface whose mesh starts poor (hinge_lin.off): with Thorough on, fewer cells end
//       below ScaledJacobian 0.85 than with the default.
#include "vtkCurveTetFilter.h"

#include <curvetet.h>

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkMassProperties.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkQuadraticTetra.h>
#include <vtkQuadraticTriangle.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace
{
int g_checks = 0;
int g_failures = 0;

#define CHECK(cond)                                                                                \
  do                                                                                               \
  {                                                                                                \
    ++g_checks;                                                                                    \
    if (!(cond))                                                                                   \
    {                                                                                              \
      ++g_failures;                                                                                \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);               \
    }                                                                                              \
  } while (0)

#define REQUIRE(cond)                                                                              \
  do                                                                                               \
  {                                                                                                \
    CHECK(cond);                                                                                   \
    if (!(cond))                                                                                   \
      return;                                                                                      \
  } while (0)

// A linear surface from a 0-based OFF file (the repository's test data).
vtkSmartPointer<vtkPolyData> ReadOff(const std::string& path)
{
  std::ifstream in(path);
  std::string magic;
  size_t nv = 0, nf = 0, ne = 0;
  in >> magic >> nv >> nf >> ne;
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  if (!in || magic != "OFF")
  {
    std::fprintf(stderr, "cannot read %s\n", path.c_str());
    return pd;
  }
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (size_t i = 0; i < nv; ++i)
  {
    double p[3];
    in >> p[0] >> p[1] >> p[2];
    pts->InsertNextPoint(p);
  }
  vtkNew<vtkCellArray> polys;
  for (size_t f = 0; f < nf; ++f)
  {
    int n = 0;
    in >> n;
    std::vector<vtkIdType> ids(n);
    for (auto& id : ids)
      in >> id;
    polys->InsertNextCell(n, ids.data());
  }
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

// Writes the .off surface `off` as an ASCII STL.
bool OffToStl(const std::string& off, const std::string& stl)
{
  vtkNew<vtkSTLWriter> w;
  w->SetInputData(ReadOff(off));
  w->SetFileName(stl.c_str());
  w->SetFileTypeToASCII();
  return w->Write() == 1;
}

// The STL to read: `path` itself, or an .off converted to ASCII STL in `outDir`.
std::string AsStl(const std::string& path, const std::string& outDir)
{
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".stl") == 0)
    return path;
  std::string stl = outDir + "/surface_from_off.stl";
  CHECK(OffToStl(path, stl));
  return stl;
}

// Error and warning events of an object, counted and kept.
struct Messages
{
  int errors = 0;
  int warnings = 0;
  std::string last;
  static void Callback(vtkObject*, unsigned long event, void* client, void* call)
  {
    auto* self = static_cast<Messages*>(client);
    (event == vtkCommand::ErrorEvent ? self->errors : self->warnings)++;
    self->last = call ? static_cast<const char*>(call) : "";
  }
  void Watch(vtkObject* o)
  {
    vtkNew<vtkCallbackCommand> cb;
    cb->SetCallback(&Messages::Callback);
    cb->SetClientData(this);
    o->AddObserver(vtkCommand::ErrorEvent, cb);
    o->AddObserver(vtkCommand::WarningEvent, cb);
  }
};

struct Progress
{
  std::vector<double> values;
  double abortAt = 2.0; // > 1: never
  vtkAlgorithm* filter = nullptr;
  static void Callback(vtkObject*, unsigned long, void* client, void* call)
  {
    auto* self = static_cast<Progress*>(client);
    double p = *static_cast<double*>(call);
    self->values.push_back(p);
    if (p >= self->abortAt)
      self->filter->SetAbortExecute(1);
  }
  void Watch(vtkAlgorithm* f)
  {
    filter = f;
    vtkNew<vtkCallbackCommand> cb;
    cb->SetCallback(&Progress::Callback);
    cb->SetClientData(this);
    f->AddObserver(vtkCommand::ProgressEvent, cb);
  }
};

double Det3(const double J[3][3])
{
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
    J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
    J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

// det of d(x)/d(r,s,t) of a quadratic tetra (VTK node order) at pcoords, with VTK's own
// shape function derivatives.
double TetJacobian(const double x[10][3], const double pc[3])
{
  double d[30];
  vtkQuadraticTetra::InterpolationDerivs(pc, d);
  double J[3][3] = {};
  for (int k = 0; k < 10; ++k)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        J[a][b] += x[k][a] * d[10 * b + k];
  return Det3(J);
}

// Equiangular skewness of the corner tet (paper eq. 2) from its six dihedral angles, computed
// here independently of curvetet: max[(tmax - te)/(180 - te), (te - tmin)/te], te = acos(1/3).
double Skewness(const double x[10][3])
{
  const int edges[6][4] = { { 0, 1, 2, 3 }, { 0, 2, 1, 3 }, { 0, 3, 1, 2 }, { 1, 2, 0, 3 },
    { 1, 3, 0, 2 }, { 2, 3, 0, 1 } };
  double lo = 180.0, hi = 0.0;
  for (const auto& e : edges)
  {
    const double* a = x[e[0]];
    double d[3], u[3], v[3];
    for (int i = 0; i < 3; ++i)
      d[i] = x[e[1]][i] - a[i];
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    const double* pk = x[e[2]];
    const double* pl = x[e[3]];
    const double du = ((pk[0] - a[0]) * d[0] + (pk[1] - a[1]) * d[1] + (pk[2] - a[2]) * d[2]) / dd;
    const double dv = ((pl[0] - a[0]) * d[0] + (pl[1] - a[1]) * d[1] + (pl[2] - a[2]) * d[2]) / dd;
    for (int i = 0; i < 3; ++i)
    {
      u[i] = pk[i] - a[i] - du * d[i]; // the faces' directions across the edge
      v[i] = pl[i] - a[i] - dv * d[i];
    }
    const double c[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
      u[0] * v[1] - u[1] * v[0] };
    const double angle = std::atan2(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                           u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) * 180.0 / M_PI;
    lo = std::min(lo, angle);
    hi = std::max(hi, angle);
  }
  const double te = std::acos(1.0 / 3.0) * 180.0 / M_PI;
  return std::max((hi - te) / (180.0 - te), (te - lo) / te);
}

// 4-point Gauss-Legendre on [0, 1].
const double kGaussX[4] = { 0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563,
  0.5 + 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.8611363115940526 };
const double kGaussW[4] = { 0.5 * 0.3478548451374538, 0.5 * 0.6521451548625461,
  0.5 * 0.6521451548625461, 0.5 * 0.3478548451374538 };

struct CellStats
{
  double volume = 0.0;           // integral of det J (exact: a cubic, collapsed Gauss 4^3)
  double minDet = HUGE_VAL;      // over the order-6 lattice and the Gauss points
  double sampledSJ = 0.0;        // min/max det J over the order-6 lattice (84 points)
};

CellStats MeasureTet(const double x[10][3])
{
  CellStats s;
  // The order-6 lattice of the reference tet, corners included.
  const int n = 6;
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j)
      for (int k = 0; i + j + k <= n; ++k)
      {
        const double pc[3] = { double(i) / n, double(j) / n, double(k) / n };
        double d = TetJacobian(x, pc);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
  s.minDet = lo;
  s.sampledSJ = hi > 0 ? lo / hi : -1.0;
  // Collapsed (Duffy) Gauss rule: r = u, s = v (1 - u), t = w (1 - u)(1 - v).
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 4; ++c)
      {
        const double u = kGaussX[a], v = kGaussX[b], w = kGaussX[c];
        const double pc[3] = { u, v * (1 - u), w * (1 - u) * (1 - v) };
        const double wt = kGaussW[a] * kGaussW[b] * kGaussW[c] * (1 - u) * (1 - u) * (1 - v);
        double d = TetJacobian(x, pc);
        s.minDet = std::min(s.minDet, d);
        s.volume += wt * d;
      }
  return s;
}

// Volume enclosed by quadratic triangles (outward): (1/3) sum of integral x . (x_r x x_s),
// a degree-4 polynomial, integrated exactly by a collapsed 4x4 Gauss rule.
double EnclosedVolume(vtkUnstructuredGrid* g)
{
  double vol = 0.0;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c)
  {
    g->GetCellPoints(c, ids);
    double x[6][3];
    for (int k = 0; k < 6; ++k)
      g->GetPoint(ids->GetId(k), x[k]);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
      {
        const double u = kGaussX[a], v = kGaussX[b];
        const double pc[3] = { u, v * (1 - u), 0 };
        const double wt = kGaussW[a] * kGaussW[b] * (1 - u);
        double f[6], d[12];
        vtkQuadraticTriangle::InterpolationFunctions(pc, f);
        vtkQuadraticTriangle::InterpolationDerivs(pc, d);
        double p[3] = {}, tr[3] = {}, ts[3] = {};
        for (int k = 0; k < 6; ++k)
          for (int i = 0; i < 3; ++i)
          {
            p[i] += f[k] * x[k][i];
            tr[i] += d[k] * x[k][i];
            ts[i] += d[6 + k] * x[k][i];
          }
        const double n[3] = { tr[1] * ts[2] - tr[2] * ts[1], tr[2] * ts[0] - tr[0] * ts[2],
          tr[0] * ts[1] - tr[1] * ts[0] };
        vol += wt * (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / 3.0;
      }
  }
  return vol;
}

// Checks a volume grid as the filter documents it; returns the integrated volume.
double CheckVolumeGrid(vtkUnstructuredGrid* g, const char* what)
{
  const vtkIdType nc = g->GetNumberOfCells();
  CHECK(nc > 0);
  vtkDataArray* sj = g->GetCellData()->GetArray("ScaledJacobian");
  vtkDataArray* skew = g->GetCellData()->GetArray("EquiangularSkewness");
  CHECK(sj != nullptr && skew != nullptr);
  if (!sj || !skew || nc == 0)
    return 0.0;
  CHECK(sj->GetNumberOfTuples() == nc && skew->GetNumberOfTuples() == nc);
  int wrongType = 0, nonPositive = 0, sjMismatch = 0, skewMismatch = 0, badRange = 0;
  double volume = 0.0, minDet = HUGE_VAL, maxSjDiff = 0.0, maxSkewDiff = 0.0, minSj = 1.0;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < nc; ++c)
  {
    if (g->GetCellType(c) != VTK_QUADRATIC_TETRA)
    {
      ++wrongType;
      continue;
    }
    g->GetCellPoints(c, ids);
    double x[10][3];
    for (int k = 0; k < 10; ++k)
      g->GetPoint(ids->GetId(k), x[k]);
    CellStats s = MeasureTet(x);
    volume += s.volume;
    minDet = std::min(minDet, s.minDet);
    if (!(s.minDet > 0))
      ++nonPositive;
    const double a = sj->GetTuple1(c), k = skew->GetTuple1(c);
    minSj = std::min(minSj, a);
    if (!(a > 0 && a <= 1 && k >= 0 && k < 1))
      ++badRange;
    maxSjDiff = std::max(maxSjDiff, std::fabs(a - s.sampledSJ));
    if (std::fabs(a - s.sampledSJ) > 1e-9)
      ++sjMismatch;
    const double k2 = Skewness(x);
    maxSkewDiff = std::max(maxSkewDiff, std::fabs(k - k2));
    if (std::fabs(k - k2) > 1e-9)
      ++skewMismatch;
  }
  std::printf("  %s: %lld points, %lld cells; min det J %.3g; ScaledJacobian min %.4f (VTK's "
              "evaluation differs by %.2g at most); EquiangularSkewness differs from the "
              "test's dihedral angles by %.2g at most; volume %.12g\n",
    what, static_cast<long long>(g->GetNumberOfPoints()), static_cast<long long>(nc), minDet,
    minSj, maxSjDiff, maxSkewDiff, volume);
  CHECK(wrongType == 0);
  CHECK(nonPositive == 0);
  CHECK(badRange == 0);
  CHECK(sjMismatch == 0);
  CHECK(skewMismatch == 0);
  return volume;
}

void TestPipeline(const std::string& surface, const std::string& outDir)
{
  const std::string stl = AsStl(surface, outDir);
  vtkNew<vtkSTLReader> reader;
  reader->SetFileName(stl.c_str());
  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputConnection(reader->GetOutputPort());
  Messages msgs;
  msgs.Watch(filter);
  Progress progress;
  progress.Watch(filter);
  const std::string vtu = outDir + "/torus_volume.vtu";
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputConnection(filter->GetOutputPort(0));
  writer->SetFileName(vtu.c_str());
  writer->SetDataModeToBinary();
  CHECK(writer->Write() == 1);
  CHECK(msgs.errors == 0);
  CHECK(std::strlen(filter->GetReportJSON()) > 0 && filter->GetReportJSON()[0] == '{');

  // Progress: monotone, ends at 1, several steps.
  CHECK(progress.values.size() >= 5);
  CHECK(std::is_sorted(progress.values.begin(), progress.values.end()));
  CHECK(!progress.values.empty() && progress.values.back() == 1.0);

  // The STL's points come first, unchanged (float in the STL, exactly representable).
  vtkPolyData* in = reader->GetOutput();
  vtkUnstructuredGrid* out = filter->GetOutput(0);
  REQUIRE(out->GetNumberOfPoints() > in->GetNumberOfPoints());
  int moved = 0;
  for (vtkIdType i = 0; i < in->GetNumberOfPoints(); ++i)
  {
    double a[3], b[3];
    in->GetPoint(i, a);
    out->GetPoint(i, b);
    moved += std::memcmp(a, b, sizeof a) != 0;
  }
  CHECK(moved == 0);

  // Read back what VTK wrote.
  vtkNew<vtkXMLUnstructuredGridReader> back;
  back->SetFileName(vtu.c_str());
  back->Update();
  vtkUnstructuredGrid* g = back->GetOutput();
  CHECK(g->GetNumberOfCells() == out->GetNumberOfCells());
  CHECK(g->GetNumberOfPoints() == out->GetNumberOfPoints());
  const double vTets = CheckVolumeGrid(g, "torus .vtu read back");

  // The boundary port: one quadratic triangle per STL facet, the same volume enclosed.
  vtkUnstructuredGrid* boundary = filter->GetOutput(1);
  CHECK(boundary->GetNumberOfCells() == in->GetNumberOfCells());
  CHECK(boundary->GetPoints() == out->GetPoints());
  CHECK(boundary->GetNumberOfCells() > 0 && boundary->GetCellType(0) == VTK_QUADRATIC_TRIANGLE);
  CHECK(boundary->GetCellData()->GetArray("BoundaryTag") != nullptr);
  const double vCurved = EnclosedVolume(boundary);
  vtkNew<vtkMassProperties> mass;
  mass->SetInputData(in);
  mass->Update();
  const double vLinear = mass->GetVolume();
  std::printf("  volume: tets %.12g, enclosed by the curved boundary %.12g (rel. diff %.2g), by "
              "the STL %.12g; torus 2 pi^2 R r^2 = %.12g\n",
    vTets, vCurved, std::fabs(vTets - vCurved) / vCurved, vLinear,
    2 * M_PI * M_PI * 1.0 * 0.35 * 0.35);
  CHECK(std::fabs(vTets - vCurved) <= 1e-9 * vCurved);
  // Curving moves the mid nodes outward on this convex-ish surface: a little more than the
  // facets enclose, within 3% (the P2 surface of the same torus encloses 2.41796).
  CHECK(vTets > vLinear && vTets < 1.03 * vLinear);
  CHECK(std::fabs(vTets - 2 * M_PI * M_PI * 0.35 * 0.35) < 0.01 * vTets);
}

void TestP2(const std::string& msh)
{
  // The surface's arrays, through curvetet's reader (VTK has no Gmsh reader).
  curvetet_surface* s = nullptr;
  REQUIRE(curvetet_surface_read(msh.c_str(), &s) == CURVETET_OK);
  const size_t nn = curvetet_surface_num_nodes(s), nt = curvetet_surface_num_triangles(s);
  std::vector<uint32_t> tri(6 * nt);
  std::vector<int32_t> tags(nt);
  CHECK(curvetet_surface_triangles(s, tri.data(), tags.data()) == CURVETET_OK);
  vtkNew<vtkDoubleArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(nn));
  std::memcpy(xyz->GetPointer(0), curvetet_surface_nodes(s), 3 * nn * sizeof(double));
  curvetet_surface_free(s);

  vtkNew<vtkUnstructuredGrid> in;
  vtkNew<vtkPoints> pts;
  pts->SetData(xyz);
  in->SetPoints(pts);
  in->Allocate(static_cast<vtkIdType>(nt));
  vtkNew<vtkIntArray> tagArray;
  tagArray->SetName("BoundaryTag");
  for (size_t t = 0; t < nt; ++t)
  {
    vtkIdType ids[6];
    for (int k = 0; k < 6; ++k)
      ids[k] = tri[6 * t + k];
    in->InsertNextCell(VTK_QUADRATIC_TRIANGLE, 6, ids);
    tagArray->InsertNextValue(100 + static_cast<int>(t % 3)); // tags of our own
  }
  in->GetCellData()->AddArray(tagArray);

  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputData(in);
  filter->SetNumberOfThreads(1);
  Messages msgs;
  msgs.Watch(filter);
  filter->Update();
  CHECK(msgs.errors == 0);
  vtkUnstructuredGrid* out = filter->GetOutput(0);
  REQUIRE(out->GetNumberOfPoints() > static_cast<vtkIdType>(nn));
  // Every input node, corner and mid, comes out first and bit-identical.
  auto* outXyz = vtkDoubleArray::SafeDownCast(out->GetPoints()->GetData());
  REQUIRE(outXyz != nullptr);
  CHECK(std::memcmp(outXyz->GetPointer(0), xyz->GetPointer(0), 3 * nn * sizeof(double)) == 0);
  const double vTets = CheckVolumeGrid(out, "sphere from quadratic triangles");

  // The boundary: the input triangles (as node sets), each once, with their tags.
  vtkUnstructuredGrid* b = filter->GetOutput(1);
  REQUIRE(b->GetNumberOfCells() == static_cast<vtkIdType>(nt));
  auto key = [](std::array<vtkIdType, 6> k, int tag) {
    std::sort(k.begin(), k.end());
    std::array<vtkIdType, 7> r;
    std::copy(k.begin(), k.end(), r.begin());
    r[6] = tag;
    return r;
  };
  std::vector<std::array<vtkIdType, 7>> a, c;
  vtkDataArray* outTags = b->GetCellData()->GetArray("BoundaryTag");
  REQUIRE(outTags != nullptr);
  vtkNew<vtkIdList> ids;
  for (size_t t = 0; t < nt; ++t)
  {
    std::array<vtkIdType, 6> k;
    std::copy(tri.begin() + 6 * t, tri.begin() + 6 * t + 6, k.begin());
    a.push_back(key(k, tagArray->GetValue(static_cast<vtkIdType>(t))));
    b->GetCellPoints(static_cast<vtkIdType>(t), ids);
    REQUIRE(ids->GetNumberOfIds() == 6);
    std::copy(ids->GetPointer(0), ids->GetPointer(0) + 6, k.begin());
    c.push_back(key(k, static_cast<int>(outTags->GetTuple1(static_cast<vtkIdType>(t)))));
  }
  std::sort(a.begin(), a.end());
  std::sort(c.begin(), c.end());
  CHECK(a == c);
  const double vCurved = EnclosedVolume(b);
  CHECK(std::fabs(vTets - vCurved) <= 1e-9 * vCurved);
  CHECK(std::fabs(vTets - 4.188659268) < 1e-6); // V_p2 of the data README
  std::printf("  sphere: boundary nodes bit-identical, %zu triangles and tags kept, volume %.10g\n",
    nt, vTets);

  std::ostringstream printed;
  filter->Print(printed);
  CHECK(printed.str().find("FeatureAngle: 40") != std::string::npos);
  CHECK(printed.str().find("BoundaryTagArrayName: BoundaryTag") != std::string::npos);

  // Properties reach curvetet: the paper's uniform size gives another mesh.
  const vtkIdType graded = out->GetNumberOfCells();
  filter->UniformSizeOn();
  filter->OptimizeOff();
  filter->Update();
  CHECK(msgs.errors == 0);
  const vtkIdType uniform = filter->GetOutput()->GetNumberOfCells();
  CHECK(uniform > 0 && uniform != graded);
  filter->SetSize(0.5);
  filter->Update();
  const vtkIdType coarse = filter->GetOutput()->GetNumberOfCells();
  CHECK(coarse > 0 && coarse < graded);
  std::printf("  sizes: graded %lld tets, uniform (paper's eq. 1) %lld, size 0.5 %lld\n",
    static_cast<long long>(graded), static_cast<long long>(uniform),
    static_cast<long long>(coarse));
}

// A P2 surface of two regions (two boxes sharing a wall, the wall given once): the
// output has a Region cell array with both ids, each region filling its unit box, and the
// boundary output lists every input triangle once (the wall included).
void TestRegions(const std::string& msh)
{
  curvetet_surface* s = nullptr;
  REQUIRE(curvetet_surface_read(msh.c_str(), &s) == CURVETET_OK);
  CHECK(curvetet_surface_num_regions(s) == 2);
  const size_t nn = curvetet_surface_num_nodes(s), nt = curvetet_surface_num_triangles(s);
  std::vector<uint32_t> tri(6 * nt);
  CHECK(curvetet_surface_triangles(s, tri.data(), nullptr) == CURVETET_OK);
  vtkNew<vtkDoubleArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(nn));
  std::memcpy(xyz->GetPointer(0), curvetet_surface_nodes(s), 3 * nn * sizeof(double));
  curvetet_surface_free(s);
  vtkNew<vtkUnstructuredGrid> in;
  vtkNew<vtkPoints> pts;
  pts->SetData(xyz);
  in->SetPoints(pts);
  in->Allocate(static_cast<vtkIdType>(nt));
  for (size_t t = 0; t < nt; ++t)
  {
    vtkIdType ids[6];
    for (int k = 0; k < 6; ++k)
      ids[k] = tri[6 * t + k];
    in->InsertNextCell(VTK_QUADRATIC_TRIANGLE, 6, ids);
  }
  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputData(in);
  filter->SetNumberOfThreads(1);
  Messages msgs;
  msgs.Watch(filter);
  filter->Update();
  CHECK(msgs.errors == 0);
  vtkUnstructuredGrid* out = filter->GetOutput(0);
  vtkDataArray* region = out->GetCellData()->GetArray("Region");
  REQUIRE(region != nullptr);
  REQUIRE(out->GetNumberOfCells() > 0);
  double vol[3] = { 0, 0, 0 };
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    const int r = static_cast<int>(region->GetTuple1(c));
    CHECK(r == 1 || r == 2);
    if (r != 1 && r != 2)
      continue;
    out->GetCellPoints(c, ids);
    double p[4][3];
    for (int k = 0; k < 4; ++k)
      out->GetPoint(ids->GetId(k), p[k]);
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k)
    {
      u[k] = p[1][k] - p[0][k];
      v[k] = p[2][k] - p[0][k];
      w[k] = p[3][k] - p[0][k];
    }
    vol[r] += (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                u[2] * (v[0] * w[1] - v[1] * w[0])) /
      6;
  }
  CHECK(std::fabs(vol[1] - 1) < 1e-10 && std::fabs(vol[2] - 1) < 1e-10);
  CHECK(filter->GetOutput(1)->GetNumberOfCells() == static_cast<vtkIdType>(nt));
  std::printf("  two regions: %lld tets, volumes %.12f + %.12f\n",
    static_cast<long long>(out->GetNumberOfCells()), vol[1], vol[2]);
}

void ExpectFailure(vtkCurveTetFilter* filter, Messages& msgs, const char* needle, const char* what)
{
  const int before = msgs.errors;
  filter->Update();
  CHECK(msgs.errors > before);
  const bool found = std::strstr(msgs.last.c_str(), needle) != nullptr &&
    std::strstr(msgs.last.c_str(), "curvetet") != nullptr;
  CHECK(found);
  CHECK(std::strlen(filter->GetLastErrorMessage()) > 0);
  CHECK(filter->GetOutput(0)->GetNumberOfCells() == 0);
  CHECK(filter->GetOutput(0)->GetNumberOfPoints() == 0);
  CHECK(filter->GetOutput(1)->GetNumberOfCells() == 0);
  std::printf("  %s: error \"%s\"%s\n", what, filter->GetLastErrorMessage(),
    found ? "" : " (expected text missing)");
}

void TestBad(const std::string& off)
{
  vtkSmartPointer<vtkPolyData> good = ReadOff(off);
  REQUIRE(good->GetNumberOfCells() > 10);
  vtkNew<vtkCurveTetFilter> filter;
  Messages msgs;
  msgs.Watch(filter);

  // Open: the first three facets removed.
  vtkNew<vtkPolyData> open;
  open->SetPoints(good->GetPoints());
  vtkNew<vtkCellArray> polys;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 3; c < good->GetNumberOfCells(); ++c)
  {
    good->GetCellPoints(c, ids);
    polys->InsertNextCell(ids);
  }
  open->SetPolys(polys);
  filter->SetInputData(open);
  ExpectFailure(filter, msgs, "not-closed", "open surface");

  // Lines are not a surface.
  vtkNew<vtkPolyData> lines;
  lines->DeepCopy(good);
  vtkNew<vtkCellArray> l;
  vtkIdType two[2] = { 0, 1 };
  l->InsertNextCell(2, two);
  lines->SetLines(l);
  filter->SetInputData(lines);
  ExpectFailure(filter, msgs, "triangles", "polydata with lines");

  // Tetrahedra are not triangles.
  vtkNew<vtkUnstructuredGrid> tets;
  tets->SetPoints(good->GetPoints());
  vtkIdType four[4] = { 0, 1, 2, 3 };
  tets->InsertNextCell(VTK_TETRA, 4, four);
  filter->SetInputData(tets);
  ExpectFailure(filter, msgs, "cell type", "grid of tetrahedra");

  // Nothing at all.
  vtkNew<vtkPolyData> empty;
  filter->SetInputData(empty);
  ExpectFailure(filter, msgs, "no triangles", "empty polydata");

  // The same filter still works on a good surface, given with an unused point first (the
  // used points are compacted, in input order) ...
  filter->OptimizeOff();
  vtkNew<vtkPolyData> extra;
  vtkNew<vtkPoints> extraPoints;
  extraPoints->SetDataTypeToDouble();
  extraPoints->InsertNextPoint(10.0, 10.0, 10.0);
  for (vtkIdType i = 0; i < good->GetNumberOfPoints(); ++i)
    extraPoints->InsertNextPoint(good->GetPoint(i));
  vtkNew<vtkCellArray> shifted;
  for (vtkIdType c = 0; c < good->GetNumberOfCells(); ++c)
  {
    good->GetCellPoints(c, ids);
    vtkIdType t[3] = { ids->GetId(0) + 1, ids->GetId(1) + 1, ids->GetId(2) + 1 };
    shifted->InsertNextCell(3, t);
  }
  extra->SetPoints(extraPoints);
  extra->SetPolys(shifted);
  filter->SetInputData(extra);
  const int before = msgs.errors;
  filter->Update();
  CHECK(msgs.errors == before);
  CHECK(std::strlen(filter->GetLastErrorMessage()) == 0);
  const vtkIdType nTets = filter->GetOutput()->GetNumberOfCells();
  CHECK(nTets > 0);
  double p[3];
  filter->GetOutput()->GetPoint(0, p);
  CHECK(std::memcmp(p, good->GetPoint(0), sizeof p) == 0);

  // ... and as a vtkUnstructuredGrid of linear triangles: the same mesh.
  vtkNew<vtkUnstructuredGrid> linear;
  linear->SetPoints(good->GetPoints());
  for (vtkIdType c = 0; c < good->GetNumberOfCells(); ++c)
  {
    good->GetCellPoints(c, ids);
    linear->InsertNextCell(VTK_TRIANGLE, ids);
  }
  filter->SetInputData(linear);
  filter->Update();
  CHECK(msgs.errors == before);
  CHECK(filter->GetOutput()->GetNumberOfCells() == nTets);
  CHECK(filter->GetOutput()->GetCellType(0) == VTK_QUADRATIC_TETRA);
  std::printf("  then a closed surface (polydata with an unused point, grid of triangles): %lld "
              "tets\n",
    static_cast<long long>(nTets));

  // Inside out: meshed, with curvetet's warning through vtkWarningMacro.
  vtkNew<vtkPolyData> flipped;
  flipped->SetPoints(good->GetPoints());
  vtkNew<vtkCellArray> reversed;
  for (vtkIdType c = 0; c < good->GetNumberOfCells(); ++c)
  {
    good->GetCellPoints(c, ids);
    vtkIdType t[3] = { ids->GetId(0), ids->GetId(2), ids->GetId(1) };
    reversed->InsertNextCell(3, t);
  }
  flipped->SetPolys(reversed);
  filter->SetInputData(flipped);
  const int warningsBefore = msgs.warnings;
  filter->Update();
  CHECK(msgs.errors == before);
  CHECK(msgs.warnings == warningsBefore + 1);
  CHECK(msgs.last.find("flipped") != std::string::npos);
  CHECK(filter->GetOutput()->GetNumberOfCells() > 0);
  std::printf("  inside-out surface: meshed, warning \"%s\"\n", msgs.last.c_str());
}

void TestAbort(const std::string& off)
{
  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputData(ReadOff(off));
  filter->OptimizeOff();
  Messages msgs;
  msgs.Watch(filter);
  Progress progress;
  progress.abortAt = 0.3;
  progress.Watch(filter);
  filter->Update();
  CHECK(msgs.errors == 0);
  CHECK(filter->GetOutput(0)->GetNumberOfCells() == 0);
  CHECK(filter->GetOutput(1)->GetNumberOfCells() == 0);
  CHECK(std::strstr(filter->GetLastErrorMessage(), "cancel") != nullptr);
  const double last = progress.values.empty() ? 0.0 : progress.values.back();
  CHECK(last >= 0.3 && last < 0.9); // stopped in the front, not at the end
  std::printf("  aborted at progress %.3f after %zu progress events: \"%s\"\n", last,
    progress.values.size(), filter->GetLastErrorMessage());

  // The executive clears AbortExecute: the next update meshes.
  progress.abortAt = 2.0;
  progress.values.clear();
  filter->Modified();
  filter->Update();
  CHECK(msgs.errors == 0);
  CHECK(filter->GetOutput(0)->GetNumberOfCells() > 0);
  CHECK(!progress.values.empty() && progress.values.back() == 1.0);
}
// A raw marching-cubes surface, smoothed by the filter (SmoothIterations 10) before
// curving: it meshes, and its vertices moved (the output's surface nodes are the
// smoothed ones).
void TestSmooth(const std::string& off)
{
  vtkSmartPointer<vtkPolyData> in = ReadOff(off);
  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputData(in);
  filter->SetSmoothIterations(10);
  CHECK(filter->GetSmoothIterations() == 10);
  Messages msgs;
  msgs.Watch(filter);
  filter->Update();
  CHECK(msgs.errors == 0);
  vtkUnstructuredGrid* out = filter->GetOutput(0);
  CHECK(out->GetNumberOfCells() > 0);
  CHECK(std::strlen(filter->GetLastErrorMessage()) == 0);
  vtkIdType moved = 0;
  for (vtkIdType i = 0; i < in->GetNumberOfPoints(); ++i)
  {
    double a[3], b[3];
    in->GetPoint(i, a);
    out->GetPoint(i, b);
    moved += (a[0] != b[0] || a[1] != b[1] || a[2] != b[2]) ? 1 : 0;
  }
  CHECK(moved > in->GetNumberOfPoints() / 2);
  std::printf("  %lld tets, %lld of %lld surface vertices moved by smoothing\n",
    static_cast<long long>(out->GetNumberOfCells()), static_cast<long long>(moved),
    static_cast<long long>(in->GetNumberOfPoints()));
}

// Cells of `grid` whose ScaledJacobian cell value is below `below`, and the smallest value.
std::pair<vtkIdType, double> CountBelow(vtkUnstructuredGrid* grid, double below)
{
  vtkDataArray* sj = grid->GetCellData()->GetArray("ScaledJacobian");
  CHECK(sj != nullptr);
  if (sj == nullptr)
    return { 0, -1.0 };
  vtkIdType n = 0;
  double lo = 1.0;
  for (vtkIdType c = 0; c < sj->GetNumberOfTuples(); ++c)
  {
    const double v = sj->GetComponent(c, 0);
    n += v < below ? 1 : 0;
    lo = std::min(lo, v);
  }
  return { n, lo };
}

void TestThorough(const std::string& off)
{
  vtkSmartPointer<vtkPolyData> in = ReadOff(off);
  vtkNew<vtkCurveTetFilter> filter;
  filter->SetInputData(in);
  Messages msgs;
  msgs.Watch(filter);
  filter->Update();
  CHECK(msgs.errors == 0);
  const auto quick = CountBelow(filter->GetOutput(0), 0.85);
  CHECK(filter->GetThorough() == 0);
  filter->ThoroughOn();
  std::ostringstream printed;
  filter->Print(printed);
  CHECK(printed.str().find("Thorough: 1") != std::string::npos);
  filter->Update();
  CHECK(msgs.errors == 0);
  const auto thorough = CountBelow(filter->GetOutput(0), 0.85);
  CHECK(thorough.first < quick.first);
  CHECK(quick.second > 0.35 && thorough.second > 0.35);
  std::printf("  cells below ScaledJacobian 0.85: default %lld (min %.3f), thorough %lld (min %.3f)\n",
    static_cast<long long>(quick.first), quick.second, static_cast<long long>(thorough.first),
    thorough.second);
}
} // namespace

int main(int argc, char* argv[])
{
  if (argc < 3)
  {
    std::fprintf(stderr, "usage: %s pipeline|p2|regions|bad|abort|smooth|thorough FILE [OUTDIR]\n", argv[0]);
    return 2;
  }
  const std::string mode = argv[1], file = argv[2];
  std::printf("vtkCurveTetFilter %s, curvetet %s\n", mode.c_str(), curvetet_version());
  if (mode == "pipeline" && argc >= 4)
    TestPipeline(file, argv[3]);
  else if (mode == "p2")
    TestP2(file);
  else if (mode == "regions")
    TestRegions(file);
  else if (mode == "bad")
    TestBad(file);
  else if (mode == "abort")
    TestAbort(file);
  else if (mode == "smooth")
    TestSmooth(file);
  else if (mode == "thorough")
    TestThorough(file);
  else if (mode == "off2stl" && argc >= 4)
    CHECK(OffToStl(file, argv[3]));
  else
  {
    std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
    return 2;
  }
  std::printf("%s: %d checks, %d failed\n", mode.c_str(), g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
