// Tests of curvetet_gmsh::generate on Gmsh models (ctest: gmsh_cpp_*).
//   curvetet_gmsh_test torus|two_volumes|cavity|failures OUTDIR CURVETET_CLI
#include "curvetet_gmsh.hpp"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

int failures = 0;

#define CHECK(cond, ...)                                                     \
  do {                                                                       \
    if (!(cond)) {                                                           \
      std::fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                                     \
      std::fprintf(stderr, "\n");                                            \
      failures++;                                                            \
    }                                                                        \
  } while (0)

using Key = std::array<std::size_t, 6>;

Key sorted_key(const std::size_t *n, const int (&idx)[6]) {
  Key k;
  for (int i = 0; i < 6; i++) k[i] = n[idx[i]];
  std::sort(k.begin(), k.end());
  return k;
}

// All nodes: tag -> coordinates.
std::map<std::size_t, std::array<double, 3>> all_nodes() {
  std::vector<std::size_t> tags;
  std::vector<double> xyz, param;
  gmsh::model::mesh::getNodes(tags, xyz, param, -1, -1, false, false);
  std::map<std::size_t, std::array<double, 3>> m;
  for (std::size_t i = 0; i < tags.size(); i++) m[tags[i]] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
  return m;
}

// Surface triangles (type 9) of all surfaces, as sorted node keys, with their element tags.
std::map<Key, std::size_t> surface_triangles(int surface = -1) {
  std::vector<std::size_t> elems, nodes;
  gmsh::model::mesh::getElementsByType(9, elems, nodes, surface);
  std::map<Key, std::size_t> m;
  static const int id[6] = {0, 1, 2, 3, 4, 5};
  for (std::size_t e = 0; e < elems.size(); e++) m[sorted_key(&nodes[6 * e], id)] = elems[e];
  return m;
}

// Faces of 10-node tets (Gmsh order) -> number of tets using them.
void count_faces(const std::vector<std::size_t> &tets, std::map<Key, int> &faces) {
  // Faces (corners + their edges' mid nodes): edges (0,1)=4 (1,2)=5 (2,0)=6 (3,0)=7 (3,2)=8 (3,1)=9.
  static const int f[4][6] = {{0, 1, 2, 4, 5, 6}, {0, 1, 3, 4, 9, 7}, {1, 2, 3, 5, 8, 9}, {0, 2, 3, 6, 8, 7}};
  for (std::size_t t = 0; 10 * t < tets.size(); t++)
    for (const auto &face : f) faces[sorted_key(&tets[10 * t], face)]++;
}

// Curved volume of the 10-node tets of a volume entity (tag -1: all), by quadrature: the
// Jacobian determinant of a 10-node tet is cubic, so "Gauss3" (exact to degree 3) is exact;
// Gmsh 4.8's "Gauss4" weights sum to 1/6 only to 3e-12 relative.
double tet_volume(int tag = -1) {
  std::vector<double> local, weights, jac, det, coord;
  gmsh::model::mesh::getIntegrationPoints(11, "Gauss3", local, weights);
  gmsh::model::mesh::getJacobians(11, local, jac, det, coord, tag);
  double v = 0;
  for (std::size_t i = 0; i < det.size(); i++) v += det[i] * weights[i % weights.size()];
  return v;
}

std::size_t count_elements() {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elems, nodes;
  gmsh::model::mesh::getElements(types, elems, nodes);
  std::size_t n = 0;
  for (const auto &v : elems) n += v.size();
  return n;
}

void init() {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
}

void surface_mesh_order2(double h) {
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  gmsh::option::setNumber("Mesh.ElementOrder", 2);
  gmsh::model::mesh::generate(2);
}

// The tets (type 11 only) and their conformity against the surface triangles.
void check_volume_mesh(const char *what, const std::map<Key, std::size_t> &surface_tris) {
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3);
  CHECK(types == std::vector<int>{11}, "%s: volume element types are not {11} (%zu types)", what, types.size());
  std::vector<std::size_t> elems, tets;
  gmsh::model::mesh::getElementsByType(11, elems, tets);
  CHECK(!elems.empty(), "%s: no tets", what);
  std::map<Key, int> faces;
  count_faces(tets, faces);
  std::size_t once = 0, bad = 0, boundary_missing = 0;
  for (const auto &[k, n] : faces) {
    if (n == 1) {
      once++;
      if (!surface_tris.count(k)) boundary_missing++;
    } else if (n != 2) {
      bad++;
    }
  }
  CHECK(bad == 0, "%s: %zu faces used by more than two tets", what, bad);
  CHECK(boundary_missing == 0, "%s: %zu boundary faces of the tets are not surface triangles", what, boundary_missing);
  CHECK(once == surface_tris.size(), "%s: %zu boundary faces, %zu surface triangles", what, once,
        surface_tris.size());
  std::printf("%s: %zu tets, %zu boundary faces\n", what, elems.size(), once);
}

int run_cli(const std::string &cli, const std::string &file) {
  const std::string cmd = "\"" + cli + "\" check \"" + file + "\"";
  std::printf("$ %s\n", cmd.c_str());
  std::fflush(stdout);
  return std::system(cmd.c_str());
}

// An OCC torus: mesh, write (binary .msh 4.1), re-open, check.
void test_torus(const std::string &out, const std::string &cli) {
  init();
  const double R = 1.0, r = 0.35;
  gmsh::model::occ::addTorus(0, 0, 0, R, r);
  gmsh::model::occ::synchronize();
  surface_mesh_order2(0.12);
  const auto nodes_before = all_nodes();
  const auto tris = surface_triangles();

  curvetet_options opt;
  curvetet_options_default(&opt);
  curvetet_gmsh::generate(&opt);

  check_volume_mesh("torus", tris);
  const double v = tet_volume(), exact = 2 * M_PI * M_PI * R * r * r;
  std::printf("torus: curved volume %.9f, exact %.9f\n", v, exact);
  CHECK(std::fabs(v - exact) < 1e-3 * exact, "torus volume %.9f vs %.9f", v, exact);

  const std::string file = out + "/torus.msh";
  gmsh::option::setNumber("Mesh.Binary", 1);
  gmsh::write(file);
  gmsh::clear();
  gmsh::open(file);
  // Re-opened: only 10-node tets in 3D, the same surface triangles, bit-identical nodes.
  check_volume_mesh("torus (re-opened)", tris);
  CHECK(surface_triangles() == tris, "the re-opened surface triangles differ");
  const auto nodes_after = all_nodes();
  std::size_t differ = 0;
  for (const auto &[tag, x] : nodes_before) {
    auto it = nodes_after.find(tag);
    if (it == nodes_after.end() || std::memcmp(it->second.data(), x.data(), sizeof x) != 0) differ++;
  }
  CHECK(differ == 0, "%zu surface nodes changed or vanished", differ);
  CHECK(nodes_after.size() > nodes_before.size(), "no interior nodes");
  gmsh::finalize();
  CHECK(run_cli(cli, file) == 0, "curvetet check %s failed", file.c_str());
}

// A box with a spherical inclusion, fragmented: the sphere surface is shared.
void test_two_volumes() {
  init();
  const double c = 1.0, rad = 0.5;
  gmsh::model::occ::addBox(0, 0, 0, 2, 2, 2);
  gmsh::model::occ::addSphere(c, c, c, rad);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fragment({{3, 1}}, {{3, 2}}, out, map);
  gmsh::model::occ::synchronize();
  surface_mesh_order2(0.25);
  const auto nodes_before = all_nodes();
  const auto tris = surface_triangles();

  // Which volume is the ball: the one with one boundary surface.
  gmsh::vectorpair vols;
  gmsh::model::getEntities(vols, 3);
  CHECK(vols.size() == 2, "%zu volumes after fragment", vols.size());
  int ball = -1, shell = -1, sphere_surface = -1;
  for (const auto &v : vols) {
    gmsh::vectorpair b;
    gmsh::model::getBoundary({v}, b, false, true, false);
    if (b.size() == 1) {
      ball = v.second;
      sphere_surface = std::abs(b[0].second);
    } else {
      shell = v.second;
    }
  }
  CHECK(ball > 0 && shell > 0, "cannot tell the ball from the box");

  curvetet_gmsh::generate();

  // The union is conforming; its boundary is the box's six faces.
  const auto sphere_tris = surface_triangles(sphere_surface);
  std::map<Key, std::size_t> box_tris;
  for (const auto &[k, e] : tris)
    if (!sphere_tris.count(k)) box_tris[k] = e;
  check_volume_mesh("box + ball", box_tris);

  // Each region separately: conforming, its boundary its own surfaces.
  std::set<std::size_t> region_nodes[2];
  for (int i = 0; i < 2; i++) {
    const int vol = i == 0 ? ball : shell;
    std::vector<std::size_t> elems, tets;
    gmsh::model::mesh::getElementsByType(11, elems, tets, vol);
    CHECK(!elems.empty(), "volume %d has no tets", vol);
    std::map<Key, int> faces;
    count_faces(tets, faces);
    std::size_t once = 0, foreign = 0;
    const auto &own = i == 0 ? sphere_tris : tris;
    for (const auto &[k, n] : faces)
      if (n == 1) {
        once++;
        if (!own.count(k)) foreign++;
      }
    CHECK(foreign == 0, "volume %d: %zu boundary faces not on its surfaces", vol, foreign);
    CHECK(once == own.size(), "volume %d: %zu boundary faces, %zu surface triangles", vol, once, own.size());
    region_nodes[i].insert(tets.begin(), tets.end());
    if (i == 0) { // every tet of the ball is inside the ball (its corners are; the ball is convex)
      std::size_t outside = 0;
      const auto nodes = all_nodes();
      for (std::size_t t = 0; 10 * t < tets.size(); t++) {
        double g[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
          for (int d = 0; d < 3; d++) g[d] += nodes.at(tets[10 * t + k])[d] / 4;
        if (std::hypot(g[0] - c, g[1] - c, g[2] - c) > rad) outside++;
      }
      CHECK(outside == 0, "%zu tets of the ball lie outside it", outside);
    }
  }
  // Shared nodes: exactly the interface's nodes (reused, not duplicated).
  std::vector<std::size_t> shared;
  std::set_intersection(region_nodes[0].begin(), region_nodes[0].end(), region_nodes[1].begin(),
                        region_nodes[1].end(), std::back_inserter(shared));
  std::set<std::size_t> interface;
  for (const auto &[k, e] : sphere_tris) interface.insert(k.begin(), k.end());
  CHECK(std::set<std::size_t>(shared.begin(), shared.end()) == interface,
        "shared nodes (%zu) != interface nodes (%zu)", shared.size(), interface.size());
  // No node moved; new nodes only inside.
  const auto nodes_after = all_nodes();
  std::size_t moved = 0;
  for (const auto &[tag, x] : nodes_before)
    if (std::memcmp(nodes_after.at(tag).data(), x.data(), sizeof x) != 0) moved++;
  CHECK(moved == 0, "%zu surface nodes moved", moved);

  const double vb = tet_volume(ball), vs = tet_volume(shell);
  const double exact_ball = 4.0 / 3.0 * M_PI * rad * rad * rad;
  std::printf("ball %.12f (exact %.12f), box minus ball %.12f, sum %.15f (box 8)\n", vb, exact_ball, vs, vb + vs);
  // To rounding (a missing or doubled tet would be ~1e-3).
  CHECK(std::fabs(vb + vs - 8.0) < 1e-12 * 8, "volumes sum to %.15f, not 8", vb + vs);
  CHECK(std::fabs(vb - exact_ball) < 2e-3 * exact_ball, "ball volume %.9f vs %.9f", vb, exact_ball);
  gmsh::finalize();
}

// One volume with two shells: Gmsh 4.8's oriented boundary gives the cavity's sphere a
// positive sign; the wrapper must turn it inward. Gmsh's own tools work on the result.
void test_cavity() {
  init();
  gmsh::model::occ::addBox(0, 0, 0, 2, 2, 2);
  gmsh::model::occ::addSphere(1, 1, 1, 0.5);
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::cut({{3, 1}}, {{3, 2}}, out, map);
  gmsh::model::occ::synchronize();
  surface_mesh_order2(0.25);
  const auto tris = surface_triangles();
  curvetet_gmsh::generate();
  check_volume_mesh("box minus ball", tris);
  const double v = tet_volume(), exact = 8 - 4.0 / 3.0 * M_PI * 0.125;
  std::printf("box minus ball: %.9f (exact %.9f)\n", v, exact);
  CHECK(std::fabs(v - exact) < 1e-4 * exact, "volume %.9f vs %.9f", v, exact);
  // Jacobians at the nodes and at Gauss points, as Gmsh computes them, are positive.
  std::string name;
  int dim, order, nn, np;
  std::vector<double> pts, local, weights, jac, det, coord;
  gmsh::model::mesh::getElementProperties(11, name, dim, order, nn, pts, np);
  gmsh::model::mesh::getIntegrationPoints(11, "Gauss6", local, weights);
  pts.insert(pts.end(), local.begin(), local.end());
  gmsh::model::mesh::getJacobians(11, pts, jac, det, coord);
  CHECK(!det.empty() && *std::min_element(det.begin(), det.end()) > 0, "a Jacobian is not positive");
  gmsh::model::mesh::optimize("HighOrder");
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3);
  CHECK(types == std::vector<int>{11}, "after Gmsh's optimizer: not only type 11");
  gmsh::finalize();
}

void expect_failure(const char *what, const char *needle) {
  const std::size_t nodes = all_nodes().size(), elems = count_elements();
  try {
    curvetet_gmsh::generate();
    CHECK(false, "%s: generate() did not throw", what);
  } catch (const std::runtime_error &e) {
    std::printf("%s: %s\n", what, e.what());
    CHECK(std::strstr(e.what(), needle) != nullptr, "%s: message lacks \"%s\"", what, needle);
  }
  CHECK(all_nodes().size() == nodes && count_elements() == elems, "%s: the model changed", what);
}

void test_failures() {
  init();
  // No volume.
  gmsh::model::occ::addRectangle(0, 0, 0, 1, 1);
  gmsh::model::occ::synchronize();
  surface_mesh_order2(0.3);
  expect_failure("no volume", "no volume");
  gmsh::clear();

  // A first-order surface mesh.
  gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.3);
  gmsh::model::mesh::generate(2);
  expect_failure("first-order surface", "6-node triangles");
  // No surface mesh at all.
  gmsh::model::mesh::clear();
  expect_failure("no surface mesh", "no mesh");
  gmsh::clear();

  // An open surface: a discrete volume bounded by three faces of a P2 tetrahedron.
  const int s = gmsh::model::addDiscreteEntity(2);
  gmsh::model::addDiscreteEntity(3, -1, {s});
  // Corners 1..4, mid nodes of the six edges.
  const double p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<std::size_t> tags;
  std::vector<double> xyz;
  std::map<std::pair<int, int>, std::size_t> mid;
  for (int i = 0; i < 4; i++) {
    tags.push_back(i + 1);
    xyz.insert(xyz.end(), p[i], p[i] + 3);
  }
  for (int i = 0; i < 4; i++)
    for (int j = i + 1; j < 4; j++) {
      mid[{i, j}] = mid[{j, i}] = tags.size() + 1;
      tags.push_back(tags.size() + 1);
      for (int d = 0; d < 3; d++) xyz.push_back((p[i][d] + p[j][d]) / 2);
    }
  gmsh::model::mesh::addNodes(2, s, tags, xyz);
  const int faces[3][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}}; // outward; face (0,3,2) missing
  std::vector<std::size_t> tri;
  for (const auto &f : faces) {
    for (int k = 0; k < 3; k++) tri.push_back(f[k] + 1);
    for (int k = 0; k < 3; k++) tri.push_back(mid[{f[k], f[(k + 1) % 3]}]);
  }
  gmsh::model::mesh::addElementsByType(s, 9, {1, 2, 3}, tri);
  expect_failure("open surface", "CURVETET_ERR_INVALID_SURFACE");
  expect_failure("open surface (Gmsh numbers)",
                 ("[in Gmsh's numbers: triangle 0 = element 1 of surface " + std::to_string(s) +
                  "; node 0 = node 1").c_str());
  gmsh::clear();

  // Already meshed in 3D (by Gmsh).
  gmsh::model::occ::addSphere(0, 0, 0, 1);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.4);
  gmsh::model::mesh::generate(3);
  expect_failure("already meshed", "already has a 3D mesh");
  gmsh::finalize();
}

}  // namespace

int main(int argc, char **argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s torus|two_volumes|cavity|failures OUTDIR CURVETET_CLI\n", argv[0]);
    return 2;
  }
  const std::string which = argv[1], out = argv[2], cli = argv[3];
  std::filesystem::create_directories(out);
  try {
    if (which == "torus")
      test_torus(out, cli);
    else if (which == "two_volumes")
      test_two_volumes();
    else if (which == "cavity")
      test_cavity();
    else if (which == "failures")
      test_failures();
    else {
      std::fprintf(stderr, "unknown test %s\n", which.c_str());
      return 2;
    }
  } catch (const std::exception &e) {
    std::fprintf(stderr, "unexpected exception: %s\n", e.what());
    return 1;
  }
  if (failures) std::fprintf(stderr, "%d check(s) failed\n", failures);
  return failures ? 1 : 0;
}
