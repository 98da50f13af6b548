# A box with a spherical inclusion: Gmsh builds the geometry and a second-order surface
# mesh, curvetet fills both volumes with 10-node tetrahedra.
import sys
import gmsh
import curvetet_gmsh

out = sys.argv[1] if len(sys.argv) > 1 else "box_sphere.msh"
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box_sphere")
gmsh.model.occ.addBox(0, 0, 0, 2, 2, 2)
gmsh.model.occ.addSphere(1, 1, 1, 0.5)
gmsh.model.occ.fragment([(3, 1)], [(3, 2)])  # shared sphere surface
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
gmsh.option.setNumber("Mesh.ElementOrder", 2)
gmsh.model.mesh.generate(2)  # 6-node triangles

try:
    curvetet_gmsh.generate(alpha=1.5, optimize=True)  # 10-node tetrahedra in both volumes
except curvetet_gmsh.CurvetetError as e:
    sys.exit(str(e))  # the model is unchanged
tets, _ = gmsh.model.mesh.getElementsByType(11)
print(len(tets), "tetrahedra")
gmsh.write(out)
gmsh.finalize()
