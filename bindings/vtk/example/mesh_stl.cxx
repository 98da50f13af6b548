// Mesh the volume inside an STL surface with curved quadratic tetrahedra, in VTK.
//   mesh_stl surface.stl volume.vtu
#include <vtkCurveTetFilter.h>
#include <vtkNew.h>
#include <vtkSTLReader.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <iostream>

int main(int argc, char* argv[])
{
  if (argc != 3)
  {
    std::cerr << "usage: " << argv[0] << " surface.stl volume.vtu\n";
    return 2;
  }
  vtkNew<vtkSTLReader> reader; // a closed, outward triangle surface
  reader->SetFileName(argv[1]);

  vtkNew<vtkCurveTetFilter> mesher; // curves the surface, then fills it with 10-node tets
  mesher->SetInputConnection(reader->GetOutputPort());
  mesher->SetFeatureAngle(40.0); // sharper edges stay sharp
  mesher->SetOptimize(true);

  vtkNew<vtkXMLUnstructuredGridWriter> writer; // VTK_QUADRATIC_TETRA cells, with the
  writer->SetInputConnection(mesher->GetOutputPort(0)); // ScaledJacobian and
  writer->SetFileName(argv[2]);                          // EquiangularSkewness cell data
  if (!writer->Write() || mesher->GetOutput()->GetNumberOfCells() == 0)
  {
    std::cerr << "meshing failed: " << mesher->GetLastErrorMessage() << "\n";
    return 1;
  }
  std::cout << mesher->GetOutput()->GetNumberOfCells() << " quadratic tetrahedra, "
            << mesher->GetOutput(1)->GetNumberOfCells() << " boundary triangles\n";
  return 0;
}
