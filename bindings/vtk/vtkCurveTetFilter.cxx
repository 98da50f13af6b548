// vtkCurveTetFilter: curvetet's C ABI (curvetet.h) in a VTK pipeline. See the header.
#include "vtkCurveTetFilter.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnstructuredGrid.h"

#include <curvetet.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkCurveTetFilter);

namespace
{
struct SurfaceFree
{
  void operator()(curvetet_surface* s) const { curvetet_surface_free(s); }
};
struct MeshFree
{
  void operator()(curvetet_mesh* m) const { curvetet_mesh_free(m); }
};
using SurfacePtr = std::unique_ptr<curvetet_surface, SurfaceFree>;
using MeshPtr = std::unique_ptr<curvetet_mesh, MeshFree>;

// The input surface as curvetet wants it: the used points (compacted, in input order),
// triangles of 3 (linear) or 6 (quadratic) nodes, and one tag per triangle.
struct SurfaceArrays
{
  std::vector<double> xyz;
  std::vector<uint32_t> tri;
  std::vector<int32_t> tags;
  int nodesPerTriangle = 3;
  size_t NumberOfTriangles() const { return this->tri.size() / this->nodesPerTriangle; }
};

// Reads the triangles of `input`; returns an error message, "" on success.
std::string ReadSurface(vtkDataSet* input, const char* tagArrayName, SurfaceArrays& out)
{
  const vtkIdType np = input->GetNumberOfPoints();
  if (np > static_cast<vtkIdType>(UINT32_MAX))
  {
    return "too many points for curvetet (32-bit node indices)";
  }
  std::vector<vtkIdType> map(static_cast<size_t>(np), -1);
  std::vector<vtkIdType> cells; // input cell ids of the triangles, for the tags
  vtkNew<vtkIdList> ids;
  if (auto* pd = vtkPolyData::SafeDownCast(input))
  {
    if (pd->GetNumberOfVerts() + pd->GetNumberOfLines() + pd->GetNumberOfStrips() > 0)
    {
      return "the polydata has vertices, lines or strips; curvetet needs a closed surface of "
             "triangles only (use vtkTriangleFilter)";
    }
    out.nodesPerTriangle = 3;
  }
  else
  {
    // An unstructured grid: all quadratic triangles, or all linear ones.
    const vtkIdType nc = input->GetNumberOfCells();
    out.nodesPerTriangle = nc > 0 && input->GetCellType(0) == VTK_QUADRATIC_TRIANGLE ? 6 : 3;
    const int want = out.nodesPerTriangle == 6 ? VTK_QUADRATIC_TRIANGLE : VTK_TRIANGLE;
    for (vtkIdType c = 0; c < nc; ++c)
    {
      if (input->GetCellType(c) != want)
      {
        std::ostringstream msg;
        msg << "cell " << c << " has VTK cell type " << input->GetCellType(c)
            << "; curvetet needs all cells VTK_QUADRATIC_TRIANGLE (22) or all VTK_TRIANGLE (5)";
        return msg.str();
      }
    }
  }
  // Collect the triangles, then number the used points in input order (so a surface
  // without unused points keeps its point ids).
  const vtkIdType nc = input->GetNumberOfCells();
  std::vector<vtkIdType> conn;
  for (vtkIdType c = 0; c < nc; ++c)
  {
    input->GetCellPoints(c, ids);
    if (ids->GetNumberOfIds() != out.nodesPerTriangle)
    {
      std::ostringstream msg;
      msg << "cell " << c << " has " << ids->GetNumberOfIds()
          << " points; curvetet needs triangles (use vtkTriangleFilter)";
      return msg.str();
    }
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
    {
      conn.push_back(ids->GetId(k));
      map[ids->GetId(k)] = 0;
    }
    cells.push_back(c);
  }
  uint32_t used = 0;
  for (vtkIdType i = 0; i < np; ++i)
  {
    if (map[i] == 0)
    {
      map[i] = used++;
      double p[3];
      input->GetPoint(i, p);
      out.xyz.insert(out.xyz.end(), p, p + 3);
    }
  }
  out.tri.reserve(conn.size());
  for (vtkIdType id : conn)
  {
    out.tri.push_back(static_cast<uint32_t>(map[id]));
  }
  if (cells.empty())
  {
    return "the input has no triangles";
  }
  vtkDataArray* tags = tagArrayName ? input->GetCellData()->GetArray(tagArrayName) : nullptr;
  out.tags.assign(cells.size(), 0);
  if (tags && tags->GetNumberOfComponents() == 1)
  {
    for (size_t t = 0; t < cells.size(); ++t)
    {
      out.tags[t] = static_cast<int32_t>(tags->GetTuple1(cells[t]));
    }
  }
  return "";
}

// Cells of `nodes` nodes each, 0-based node indices in `conn`.
void SetCells(vtkUnstructuredGrid* grid, int type, int nodes, const std::vector<uint32_t>& conn)
{
  vtkNew<vtkIdTypeArray> ids;
  ids->SetNumberOfValues(static_cast<vtkIdType>(conn.size()));
  std::copy(conn.begin(), conn.end(), ids->GetPointer(0));
  vtkNew<vtkCellArray> cells;
  cells->SetData(nodes, ids);
  grid->SetCells(type, cells);
}
} // namespace

vtkCurveTetFilter::vtkCurveTetFilter()
  : Alpha(1.5)
  , Size(0.0)
  , UniformSize(0)
  , Optimize(1)
  , Thorough(0)
  , FeatureAngle(40.0)
  , SmoothIterations(0)
  , NumberOfThreads(0)
  , BoundaryTagArrayName(nullptr)
{
  this->SetBoundaryTagArrayName("BoundaryTag");
  this->SetNumberOfOutputPorts(2);
}

vtkCurveTetFilter::~vtkCurveTetFilter()
{
  this->SetBoundaryTagArrayName(nullptr);
}

int vtkCurveTetFilter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkUnstructuredGrid");
  return 1;
}

int vtkCurveTetFilter::ProgressCallback(void* user, double fraction, const char* stage)
{
  auto* self = static_cast<vtkCurveTetFilter*>(user);
  // curvetet's stages: "front" (most of the time; "front (attempt 2 of 4)" and so on
  // when it starts again, from 0), "optimize" (0, then 0.5), then "certify"; the copy
  // into VTK takes the rest. Progress shown never goes back.
  double p = self->LastProgress;
  if (stage && std::strncmp(stage, "region ", 7) == 0)
  {
    // A surface of several regions: "region ID: STAGE", the fraction over all regions.
    p = 0.05 + 0.85 * fraction;
  }
  else if (stage && std::strncmp(stage, "front", 5) == 0)
  {
    p = 0.05 + 0.7 * fraction;
  }
  else if (stage && std::strcmp(stage, "optimize") == 0)
  {
    p = 0.75 + 0.1 * fraction;
  }
  else if (stage && std::strcmp(stage, "certify") == 0)
  {
    p = 0.9;
  }
  try
  {
    if (p > self->LastProgress)
    {
      self->LastProgress = p;
      self->UpdateProgress(p);
    }
    return self->GetAbortExecute() ? 1 : 0;
  }
  catch (...)
  {
    return 1; // an observer threw: nothing may unwind through curvetet; stop instead
  }
}

void vtkCurveTetFilter::Fail(const std::string& message)
{
  this->LastErrorMessage = message;
  vtkErrorMacro(<< "curvetet: " << message);
}

int vtkCurveTetFilter::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataSet* input = vtkDataSet::GetData(inputVector[0]);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  vtkUnstructuredGrid* boundary = vtkUnstructuredGrid::GetData(outputVector, 1);
  output->Initialize();
  boundary->Initialize();
  this->LastErrorMessage.clear();
  this->ReportJSON.clear();
  this->LastProgress = 0.0;
  if (!input)
  {
    this->Fail("no input");
    return 0;
  }

  SurfaceArrays in;
  std::string err = ReadSurface(input, this->BoundaryTagArrayName, in);
  if (!err.empty())
  {
    this->Fail(err);
    return 0;
  }
  curvetet_surface* rawSurface = nullptr;
  const size_t nn = in.xyz.size() / 3;
  const size_t nt = in.NumberOfTriangles();
  curvetet_status st = in.nodesPerTriangle == 6
    ? curvetet_surface_from_arrays(
        in.xyz.data(), nn, in.tri.data(), nt, in.tags.data(), &rawSurface)
    : curvetet_surface_from_linear_smoothed(in.xyz.data(), nn, in.tri.data(), nt,
        in.tags.data(), this->FeatureAngle, static_cast<uint32_t>(this->SmoothIterations),
        &rawSurface);
  SurfacePtr surface(rawSurface);
  if (st != CURVETET_OK)
  {
    this->Fail(curvetet_last_error_message());
    return 0;
  }
  for (size_t w = 0; w < curvetet_surface_num_warnings(surface.get()); ++w)
  {
    vtkWarningMacro(<< "curvetet: " << curvetet_surface_warning(surface.get(), w));
  }
  this->UpdateProgress(0.05);

  curvetet_options opt;
  curvetet_options_default(&opt);
  opt.alpha = this->Alpha;
  opt.size = this->Size;
  opt.uniform_size = this->UniformSize ? 1 : 0;
  opt.optimize = this->Optimize ? 1 : 0;
  opt.thorough = this->Thorough ? 1 : 0;
  opt.threads = static_cast<uint32_t>(std::max(0, this->NumberOfThreads));
  opt.progress = &vtkCurveTetFilter::ProgressCallback;
  opt.user_data = this;
  curvetet_mesh* rawMesh = nullptr;
  st = curvetet_generate(surface.get(), &opt, &rawMesh);
  MeshPtr mesh(rawMesh);
  if (st == CURVETET_ERR_CANCELLED)
  {
    this->LastErrorMessage = curvetet_last_error_message();
    vtkDebugMacro(<< "curvetet: " << this->LastErrorMessage);
    return 1; // aborted on request: empty outputs, no error
  }
  if (st != CURVETET_OK)
  {
    this->Fail(curvetet_last_error_message());
    return 0;
  }

  // Points: the surface's nodes first (same indices as the compacted input), then the
  // interior and mid-edge nodes.
  const size_t numNodes = curvetet_mesh_num_nodes(mesh.get());
  const size_t numTets = curvetet_mesh_num_tets(mesh.get());
  const size_t numFaces = curvetet_mesh_num_boundary_faces(mesh.get());
  vtkNew<vtkDoubleArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(static_cast<vtkIdType>(numNodes));
  std::memcpy(xyz->GetPointer(0), curvetet_mesh_nodes(mesh.get()), 3 * numNodes * sizeof(double));
  vtkNew<vtkPoints> points;
  points->SetData(xyz);

  std::vector<uint32_t> tets(10 * numTets);
  std::vector<uint32_t> faces(6 * numFaces);
  std::vector<int32_t> faceTags(numFaces);
  vtkNew<vtkDoubleArray> sj;
  sj->SetName("ScaledJacobian");
  sj->SetNumberOfValues(static_cast<vtkIdType>(numTets));
  vtkNew<vtkDoubleArray> skew;
  skew->SetName("EquiangularSkewness");
  skew->SetNumberOfValues(static_cast<vtkIdType>(numTets));
  vtkNew<vtkIntArray> region;
  region->SetName("Region");
  region->SetNumberOfValues(static_cast<vtkIdType>(numTets));
  if (curvetet_mesh_tets(mesh.get(), CURVETET_ORDER_VTK, tets.data()) != CURVETET_OK ||
    curvetet_mesh_tet_regions(mesh.get(), region->GetPointer(0)) != CURVETET_OK ||
    curvetet_mesh_boundary_faces(mesh.get(), faces.data(), faceTags.data()) != CURVETET_OK ||
    curvetet_mesh_tet_quality(mesh.get(), sj->GetPointer(0), skew->GetPointer(0)) != CURVETET_OK)
  {
    this->Fail(curvetet_last_error_message());
    return 0;
  }

  output->SetPoints(points);
  SetCells(output, VTK_QUADRATIC_TETRA, 10, tets);
  output->GetCellData()->AddArray(sj);
  output->GetCellData()->AddArray(skew);
  output->GetCellData()->AddArray(region);

  boundary->SetPoints(points);
  SetCells(boundary, VTK_QUADRATIC_TRIANGLE, 6, faces);
  vtkNew<vtkIntArray> tagArray;
  tagArray->SetName("BoundaryTag");
  tagArray->SetNumberOfValues(static_cast<vtkIdType>(numFaces));
  std::copy(faceTags.begin(), faceTags.end(), tagArray->GetPointer(0));
  boundary->GetCellData()->AddArray(tagArray);

  const char* json = curvetet_mesh_report_json(mesh.get());
  this->ReportJSON = json ? json : "";
  this->UpdateProgress(1.0);
  return 1;
}

void vtkCurveTetFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Alpha: " << this->Alpha << "\n";
  os << indent << "Size: " << this->Size << "\n";
  os << indent << "UniformSize: " << this->UniformSize << "\n";
  os << indent << "Optimize: " << this->Optimize << "\n";
  os << indent << "Thorough: " << this->Thorough << "\n";
  os << indent << "FeatureAngle: " << this->FeatureAngle << "\n";
  os << indent << "SmoothIterations: " << this->SmoothIterations << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "BoundaryTagArrayName: "
     << (this->BoundaryTagArrayName ? this->BoundaryTagArrayName : "(none)") << "\n";
  os << indent << "curvetet: " << curvetet_version() << "\n";
}
