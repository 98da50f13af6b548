// A box with a spherical inclusion: Gmsh builds the geometry and a second-order surface
// mesh, curvetet fills both volumes with 10-node tetrahedra.
#include <cstdio>
#include <stdexcept>
#include <gmsh.h>
#include <curvetet_gmsh.hpp>

int main(int argc, char **argv) {
  const char *out = argc > 1 ? argv[1] : "box_sphere.msh";
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("box_sphere");
  gmsh::model::occ::addBox(0, 0, 0, 2, 2, 2);
  gmsh::model::occ::addSphere(1, 1, 1, 0.5);
  gmsh::vectorpair dimTags;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fragment({{3, 1}}, {{3, 2}}, dimTags, map); // shared sphere surface
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.25);
  gmsh::option::setNumber("Mesh.ElementOrder", 2);
  gmsh::model::mesh::generate(2); // 6-node triangles

  curvetet_options opt;
  curvetet_options_default(&opt); // alpha 1.5, graded size, optimize
  try {
    curvetet_gmsh::generate(&opt); // 10-node tetrahedra (type 11) in both volumes
  } catch (const std::runtime_error &e) {
    std::fprintf(stderr, "%s\n", e.what()); // the model is unchanged
    gmsh::finalize();
    return 1;
  }
  std::vector<std::size_t> tets, nodes;
  gmsh::model::mesh::getElementsByType(11, tets, nodes);
  std::printf("%zu tetrahedra\n", tets.size());
  gmsh::write(out);
  gmsh::finalize();
  return 0;
}
