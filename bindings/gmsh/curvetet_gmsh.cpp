// curvetet_gmsh::generate: curvetet as the volume mesher of the current Gmsh model.
// Uses only Gmsh C++ API calls that Gmsh 4.8 (Debian 12) and later versions share, and
// curvetet only through its C ABI (curvetet.h).
#include "curvetet_gmsh.hpp"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace curvetet_gmsh {
namespace {

constexpr int kTri6 = 9;   // Gmsh: 6-node second-order triangle
constexpr int kTet10 = 11; // Gmsh: 10-node second-order tetrahedron

[[noreturn]] void fail(const std::string &msg) {
  throw std::runtime_error("curvetet_gmsh: " + msg);
}

std::string curvetet_error(curvetet_status st) {
  return std::string(curvetet_error_name(st)) + ": " + curvetet_last_error_message();
}

struct SurfaceFree {
  void operator()(curvetet_surface *s) const { curvetet_surface_free(s); }
};
struct MeshFree {
  void operator()(curvetet_mesh *m) const { curvetet_mesh_free(m); }
};
using SurfacePtr = std::unique_ptr<curvetet_surface, SurfaceFree>;
using MeshPtr = std::unique_ptr<curvetet_mesh, MeshFree>;

// One volume entity, meshed but not yet added to the model.
struct Region {
  int volume = 0;
  std::vector<std::size_t> boundary_tags; // curvetet's surface node i is Gmsh node boundary_tags[i]
  MeshPtr mesh;
};

// All nodes of the model: tag -> coordinates.
struct ModelNodes {
  std::unordered_map<std::size_t, std::size_t> index; // tag -> position in xyz / 3
  std::vector<double> xyz;
  std::size_t max_tag = 0;

  ModelNodes() {
    std::vector<std::size_t> tags;
    std::vector<double> param;
    gmsh::model::mesh::getNodes(tags, xyz, param, -1, -1, false, false);
    index.reserve(tags.size());
    for (std::size_t i = 0; i < tags.size(); i++) {
      index.emplace(tags[i], i);
      max_tag = std::max(max_tag, tags[i]);
    }
  }
};

// Surface triangles of one volume's boundary, with Gmsh node tags, and the surface entity of each.
struct Boundary {
  std::vector<std::size_t> tri6; // Gmsh node tags, 6 per triangle
  std::vector<int> entity;       // per triangle: index into `surfaces`
  std::vector<std::size_t> elements; // per triangle: its Gmsh element tag
  std::vector<int> surfaces;     // surface entity tags
  std::vector<bool> reversed;    // per surface: its triangles are to be reversed
};

std::string type_name(int type) {
  std::string name;
  int dim = 0, order = 0, num_nodes = 0, num_primary = 0;
  std::vector<double> local;
  gmsh::model::mesh::getElementProperties(type, name, dim, order, num_nodes, local, num_primary);
  return name;
}

Boundary gather_boundary(int volume) {
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 3, volume);
  if (!types.empty())
    fail("volume " + std::to_string(volume) +
         " already has a 3D mesh; clear it (gmsh::model::mesh::clear) or generate only up to dimension 2");

  gmsh::vectorpair faces;
  gmsh::model::getBoundary({{3, volume}}, faces, /*combined=*/false, /*oriented=*/true,
                           /*recursive=*/false);
  if (faces.empty()) fail("volume " + std::to_string(volume) + " has no boundary surface");

  Boundary b;
  for (const auto &f : faces) {
    const int s = std::abs(f.second);
    if (std::find(b.surfaces.begin(), b.surfaces.end(), s) != b.surfaces.end())
      continue; // a surface listed twice (e.g. embedded): it is not a boundary
    gmsh::model::mesh::getElementTypes(types, 2, s);
    if (types.empty())
      fail("surface " + std::to_string(s) + " (boundary of volume " + std::to_string(volume) +
           ") has no mesh: call gmsh::model::mesh::generate(2) first, with Mesh.ElementOrder = 2");
    for (int t : types)
      if (t != kTri6)
        fail("surface " + std::to_string(s) + " (boundary of volume " + std::to_string(volume) +
             ") has elements of type " + std::to_string(t) + " (" + type_name(t) +
             "); curvetet needs a second-order triangle mesh (6-node triangles, type 9): set "
             "Mesh.ElementOrder = 2 before generate(2), or call gmsh::model::mesh::setOrder(2)");
    std::vector<std::size_t> elems, nodes;
    gmsh::model::mesh::getElementsByType(kTri6, elems, nodes, s);
    const int e = static_cast<int>(b.surfaces.size());
    b.surfaces.push_back(s);
    b.reversed.push_back(f.second < 0);
    b.tri6.insert(b.tri6.end(), nodes.begin(), nodes.end());
    b.elements.insert(b.elements.end(), elems.begin(), elems.end());
    b.entity.insert(b.entity.end(), elems.size(), e);
  }
  return b;
}

// The 6 nodes of a triangle with reversed orientation: [c0, c2, c1, m20, m12, m01].
constexpr int kFlip[6] = {0, 2, 1, 5, 4, 3};

// Orient the boundary outward: Gmsh's oriented boundary signs are a first guess (they are
// not reliable for a cavity's shell in every Gmsh version). Surfaces sharing an edge must
// run through it in opposite directions, which fixes each connected shell up to one flip;
// then the shell enclosing the largest volume (the outer one) is made outward and the
// others (cavities) inward. curvetet checks the result again, exactly.
void orient(Boundary &b, const ModelNodes &nodes) {
  const std::size_t ns = b.surfaces.size();
  const std::size_t nt = b.entity.size();
  auto corner = [&](std::size_t t, int k) {
    const int j = b.reversed[b.entity[t]] ? kFlip[k] : k;
    return b.tri6[6 * t + j];
  };
  // Entity graph: (a, b, same) where `same` = a and b run through a shared edge the same way.
  struct Use {
    int entity;
    bool forward;
  };
  std::unordered_map<std::uint64_t, Use> first;
  std::vector<std::vector<std::pair<int, bool>>> adj(ns);
  auto key = [](std::size_t u, std::size_t v) {
    return (static_cast<std::uint64_t>(std::min(u, v)) << 32) ^ static_cast<std::uint64_t>(std::max(u, v));
  };
  for (std::size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      const std::size_t u = corner(t, k), v = corner(t, (k + 1) % 3);
      const Use use{b.entity[t], u < v};
      auto [it, inserted] = first.emplace(key(u, v), use);
      if (!inserted && it->second.entity != use.entity) {
        const bool same = it->second.forward == use.forward;
        adj[it->second.entity].push_back({use.entity, same});
        adj[use.entity].push_back({it->second.entity, same});
      }
    }
  // Shells: connected components of the entity graph; flip relative to each shell's root.
  std::vector<int> shell(ns, -1);
  std::vector<bool> flip(ns, false);
  int num_shells = 0;
  for (std::size_t r = 0; r < ns; r++) {
    if (shell[r] >= 0) continue;
    std::vector<int> stack{static_cast<int>(r)};
    shell[r] = num_shells;
    while (!stack.empty()) {
      const int e = stack.back();
      stack.pop_back();
      for (auto [o, same] : adj[e])
        if (shell[o] < 0) {
          shell[o] = num_shells;
          flip[o] = flip[e] != same;
          stack.push_back(o);
        }
    }
    num_shells++;
  }
  for (std::size_t e = 0; e < ns; e++)
    if (flip[e]) b.reversed[e] = !b.reversed[e];
  // Signed volume enclosed by each shell's chord triangles (relative to one node, to keep
  // the sums small).
  std::vector<double> vol(num_shells, 0.0);
  const double *o = &nodes.xyz[3 * nodes.index.at(b.tri6[0])];
  for (std::size_t t = 0; t < nt; t++) {
    double p[3][3];
    for (int k = 0; k < 3; k++) {
      const double *x = &nodes.xyz[3 * nodes.index.at(corner(t, k))];
      for (int d = 0; d < 3; d++) p[k][d] = x[d] - o[d];
    }
    vol[shell[b.entity[t]]] += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
                               p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
                               p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
  }
  int outer = 0;
  for (int s = 1; s < num_shells; s++)
    if (std::abs(vol[s]) > std::abs(vol[outer])) outer = s;
  for (std::size_t e = 0; e < ns; e++) {
    const int s = shell[e];
    const bool want_positive = s == outer;
    if ((vol[s] > 0) != want_positive && vol[s] != 0) b.reversed[e] = !b.reversed[e];
  }
}

// curvetet's messages name triangles and nodes by their 0-based index in the arrays it was
// given; say which Gmsh elements and nodes these are.
std::string in_gmsh_numbers(const std::string &msg, const Boundary &b,
                            const std::vector<std::size_t> &node_tags) {
  std::set<std::size_t> tris, nodes;
  static const std::regex tri_re(R"(triangles? (\d+))"), node_re(R"(nodes? (\d+))"),
      list_re(R"((corners|edge) \(?(\d+), (\d+)(, (\d+))?)");
  for (auto it = std::sregex_iterator(msg.begin(), msg.end(), tri_re); it != std::sregex_iterator(); ++it)
    tris.insert(std::stoul((*it)[1]));
  for (auto it = std::sregex_iterator(msg.begin(), msg.end(), node_re); it != std::sregex_iterator(); ++it)
    nodes.insert(std::stoul((*it)[1]));
  for (auto it = std::sregex_iterator(msg.begin(), msg.end(), list_re); it != std::sregex_iterator(); ++it)
    for (int g : {2, 3, 5})
      if ((*it)[g].matched) nodes.insert(std::stoul((*it)[g]));
  std::string out;
  int n = 0;
  for (std::size_t t : tris)
    if (t < b.elements.size() && n++ < 8)
      out += (out.empty() ? "" : "; ") + std::string("triangle ") + std::to_string(t) + " = element " +
             std::to_string(b.elements[t]) + " of surface " + std::to_string(b.surfaces[b.entity[t]]);
  for (std::size_t i : nodes)
    if (i < node_tags.size() && n++ < 16)
      out += (out.empty() ? "" : "; ") + std::string("node ") + std::to_string(i) + " = node " +
             std::to_string(node_tags[i]);
  return out.empty() ? "" : " [in Gmsh's numbers: " + out + "]";
}

Region mesh_volume(int volume, const ModelNodes &nodes, const curvetet_options *opt) {
  Boundary b = gather_boundary(volume);
  if (b.entity.empty()) fail("volume " + std::to_string(volume) + " has an empty boundary mesh");
  for (std::size_t tag : b.tri6)
    if (!nodes.index.count(tag))
      fail("volume " + std::to_string(volume) + ": boundary node " + std::to_string(tag) +
           " is not in the model");
  orient(b, nodes);

  // Local numbering of the boundary nodes, in order of first use.
  Region r;
  r.volume = volume;
  std::unordered_map<std::size_t, std::uint32_t> local;
  std::vector<double> xyz;
  const std::size_t nt = b.entity.size();
  std::vector<std::uint32_t> tri6(6 * nt);
  std::vector<std::int32_t> tags(nt);
  for (std::size_t t = 0; t < nt; t++) {
    const bool rev = b.reversed[b.entity[t]];
    for (int k = 0; k < 6; k++) {
      const std::size_t tag = b.tri6[6 * t + (rev ? kFlip[k] : k)];
      auto [it, inserted] = local.emplace(tag, static_cast<std::uint32_t>(r.boundary_tags.size()));
      if (inserted) {
        r.boundary_tags.push_back(tag);
        const double *x = &nodes.xyz[3 * nodes.index.at(tag)];
        xyz.insert(xyz.end(), x, x + 3);
      }
      tri6[6 * t + k] = it->second;
    }
    tags[t] = b.surfaces[b.entity[t]];
  }

  curvetet_surface *s = nullptr;
  curvetet_status st = curvetet_surface_from_arrays(xyz.data(), r.boundary_tags.size(), tri6.data(),
                                                    nt, tags.data(), &s);
  SurfacePtr surface(s);
  if (st != CURVETET_OK) {
    const std::string msg = curvetet_error(st);
    fail("volume " + std::to_string(volume) + ": its boundary surface is not acceptable (" + msg + ")" +
         in_gmsh_numbers(msg, b, r.boundary_tags));
  }
  curvetet_mesh *m = nullptr;
  st = curvetet_generate(surface.get(), opt, &m);
  r.mesh.reset(m);
  if (st != CURVETET_OK) {
    const std::string msg = curvetet_error(st);
    fail("volume " + std::to_string(volume) + ": " + msg + in_gmsh_numbers(msg, b, r.boundary_tags));
  }
  if (curvetet_mesh_num_nodes(m) < r.boundary_tags.size())
    fail("volume " + std::to_string(volume) + ": curvetet returned fewer nodes than the surface has");
  return r;
}

std::size_t max_element_tag() {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elems, nodes;
  gmsh::model::mesh::getElements(types, elems, nodes, -1, -1);
  std::size_t max_tag = 0;
  for (const auto &v : elems)
    for (std::size_t t : v) max_tag = std::max(max_tag, t);
  return max_tag;
}

}  // namespace

void generate(const curvetet_options *opt) {
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  if (volumes.empty()) fail("the model has no volume");

  // Mesh every volume first: a failure leaves the model unchanged.
  const ModelNodes nodes;
  std::vector<Region> regions;
  for (const auto &v : volumes) regions.push_back(mesh_volume(v.second, nodes, opt));

  // Then add nodes and tetrahedra, with fresh tags after the model's largest ones.
  std::size_t next_node = nodes.max_tag + 1;
  std::size_t next_elem = max_element_tag() + 1;
  for (const Region &r : regions) {
    const curvetet_mesh *m = r.mesh.get();
    const std::size_t nb = r.boundary_tags.size();
    const std::size_t nn = curvetet_mesh_num_nodes(m);
    const double *xyz = curvetet_mesh_nodes(m);
    std::vector<std::size_t> node_tags(nn);
    std::copy(r.boundary_tags.begin(), r.boundary_tags.end(), node_tags.begin());
    std::vector<std::size_t> new_tags;
    new_tags.reserve(nn - nb);
    for (std::size_t i = nb; i < nn; i++) {
      node_tags[i] = next_node++;
      new_tags.push_back(node_tags[i]);
    }
    const std::vector<double> new_xyz(xyz + 3 * nb, xyz + 3 * nn);

    const std::size_t ntet = curvetet_mesh_num_tets(m);
    std::vector<std::uint32_t> tets(10 * ntet);
    const curvetet_status st = curvetet_mesh_tets(m, CURVETET_ORDER_GMSH, tets.data());
    if (st != CURVETET_OK) fail("volume " + std::to_string(r.volume) + ": " + curvetet_error(st));
    std::vector<std::size_t> elem_tags(ntet), elem_nodes(10 * ntet);
    for (std::size_t t = 0; t < ntet; t++) elem_tags[t] = next_elem++;
    for (std::size_t i = 0; i < tets.size(); i++) elem_nodes[i] = node_tags[tets[i]];

    if (!new_tags.empty()) gmsh::model::mesh::addNodes(3, r.volume, new_tags, new_xyz);
    gmsh::model::mesh::addElementsByType(r.volume, kTet10, elem_tags, elem_nodes);
  }
}

}  // namespace curvetet_gmsh
