// Reference mesher for tests/reference.rs: CGAL Mesh_3 on a closed linear surface.
//
//   cgal_mesh3 INPUT.off OUTPUT.mesh H [FEATURE_ANGLE_DEG]
//
// Reads the triangle surface (OFF), protects its sharp edges (dihedral angle sharper than
// FEATURE_ANGLE_DEG, default 40, the same default as curvetet's --feature-angle), meshes
// the enclosed volume with Mesh_3 at target size H (facet and cell size H, facet distance
// H/10, default angle and radius-edge bounds) and writes medit (.mesh) with 17 digits.
// The mesh approximates the input surface (Mesh_3 does not keep input triangles): its
// boundary vertices lie on the input surface, its facets within about the facet distance
// of it. Deterministic: the default random generator is seeded with 0, and sliver
// perturbation and exudation run without their default time limits (by default they get
// as long as the refinement took, which makes the result depend on the machine's load);
// both stop at a 10 degree sliver bound instead.
//
// Compiled once per test run by tests/reference.rs (g++ -O2 -frounding-math ... -lgmp
// -lmpfr) and cached under target/; see tests/reference.rs for the exact command.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/IO/File_medit.h>
#include <CGAL/make_mesh_3.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Polyhedron_3<K, CGAL::Mesh_3::Mesh_polyhedron_items<int>>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<K, Polyhedron>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index,
                                                     Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: cgal_mesh3 INPUT.off OUTPUT.mesh H [FEATURE_ANGLE_DEG]\n";
    return 2;
  }
  const double h = std::atof(argv[3]);
  const double angle = argc > 4 ? std::atof(argv[4]) : 40.0;
  if (!(h > 0)) {
    std::cerr << "cgal_mesh3: bad size " << argv[3] << "\n";
    return 2;
  }
  Polyhedron poly;
  std::ifstream in(argv[1]);
  if (!(in >> poly) || poly.empty() || !poly.is_closed() ||
      !poly.is_pure_triangle()) {
    std::cerr << "cgal_mesh3: " << argv[1] << " is not a closed triangle surface\n";
    return 1;
  }
  Domain domain(poly);
  // An edge is a feature when its two facets' normals differ by more than `angle`.
  domain.detect_features(angle);
  namespace p = CGAL::parameters;
  Criteria criteria(p::edge_size = h, p::facet_angle = 25, p::facet_size = h,
                    p::facet_distance = h / 10, p::cell_radius_edge_ratio = 3,
                    p::cell_size = h);
  CGAL::get_default_random() = CGAL::Random(0);
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(
      domain, criteria, p::perturb(p::time_limit = 0, p::sliver_bound = 10),
      p::exude(p::time_limit = 0, p::sliver_bound = 10));
  std::ofstream out(argv[2]);
  out.precision(17);
  CGAL::IO::output_to_medit(out, c3t3, false, true);
  if (!out) {
    std::cerr << "cgal_mesh3: cannot write " << argv[2] << "\n";
    return 1;
  }
  std::cerr << "cgal_mesh3: " << c3t3.number_of_cells_in_complex() << " tets\n";
  return 0;
}
