// curvetet as the volume mesher of a Gmsh model (Gmsh C++ API, over curvetet's C ABI).
//
//   gmsh::option::setNumber("Mesh.ElementOrder", 2);
//   gmsh::model::mesh::generate(2);            // a second-order (6-node) surface mesh
//   curvetet_gmsh::generate();                 // 10-node tetrahedra in every volume
//   gmsh::write("volume.msh");
//
// CMake: find_package(CurveTet COMPONENTS Gmsh), link CurveTet::gmsh.
#ifndef CURVETET_GMSH_HPP
#define CURVETET_GMSH_HPP

#include <curvetet.h>

#include <stdexcept>

namespace curvetet_gmsh {

// Mesh every volume entity of the current Gmsh model with curvetet.
//
// The model must have a second-order surface mesh (6-node triangles, Gmsh type 9) on the
// boundary of each volume, and no 3D mesh yet. For each volume, the triangles of its
// boundary surfaces are gathered (oriented outward, a cavity's shell inward), meshed by
// curvetet, and the new interior nodes (classified on the volume) and 10-node tetrahedra
// (type 11, Gmsh node order) are added to the volume with gmsh::model::mesh::addNodes and
// addElementsByType. Boundary nodes are Gmsh's own (same tags, untouched coordinates), so
// a surface shared by two volumes stays conforming. The boundary triangles keep their
// surface entity's tag as curvetet's boundary tag.
//
// `opt`: curvetet's options (curvetet_options_default), or nullptr for the defaults.
//
// Throws std::runtime_error, with curvetet's message, when any volume cannot be meshed
// (no volume, a surface without a 6-node triangle mesh, an open or self-intersecting
// boundary, the front failing, ...). Every volume is meshed before the model is touched:
// on failure the model is left unchanged.
void generate(const curvetet_options *opt = nullptr);

}  // namespace curvetet_gmsh

#endif  // CURVETET_GMSH_HPP
