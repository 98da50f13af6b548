/**
 * @class   vtkCurveTetFilter
 * @brief   fill a closed surface with curved quadratic (10-node) tetrahedra (curvetet)
 *
 * vtkCurveTetFilter meshes the volume enclosed by a closed, consistently oriented surface
 * with certified-valid quadratic tetrahedra (VTK_QUADRATIC_TETRA, VTK's node order), using
 * curvetet's advancing front over its C ABI (curvetet.h). Every boundary node of the input
 * is kept bit-identical; no node is added on the boundary.
 *
 * Input (port 0), either:
 * - vtkPolyData of triangles (linear; e.g. from vtkSTLReader): the surface is curved first
 *   (a mid node per edge on a smooth reconstruction; edges sharper than FeatureAngle stay
 *   sharp); run vtkTriangleFilter first for polygons or strips;
 * - vtkUnstructuredGrid of VTK_QUADRATIC_TRIANGLE cells: used as the curved (P2) surface
 *   as it is (a grid of VTK_TRIANGLE cells is curved like polydata).
 * An integer cell array named by BoundaryTagArrayName (default "BoundaryTag") on the input
 * gives each triangle a tag, kept on the output's boundary.
 *
 * Output port 0: vtkUnstructuredGrid of VTK_QUADRATIC_TETRA cells. The input surface's
 * (used) points come first, in input order, with bit-identical coordinates. Cell data:
 * "ScaledJacobian" (min J / max J over the element, sampled; 1 for straight-sided) and
 * "EquiangularSkewness" (0 best, 1 degenerate).
 *
 * Output port 1: the boundary as a vtkUnstructuredGrid of VTK_QUADRATIC_TRIANGLE cells,
 * sharing port 0's points (outward, one per input triangle), with the int cell array
 * "BoundaryTag" (the input tags, 0 where the input has none): boundary conditions are set
 * on this port.
 *
 * Errors (open or self-intersecting surface, wrong cell types, meshing failure) are
 * reported with vtkErrorMacro carrying curvetet's message; both outputs are then empty.
 * Progress goes to UpdateProgress; SetAbortExecute(1) (e.g. from a progress observer)
 * cancels the meshing promptly, with empty outputs.
 */
#ifndef vtkCurveTetFilter_h
#define vtkCurveTetFilter_h

#include "vtkUnstructuredGridAlgorithm.h"

#include <string>

class vtkCurveTetFilter : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkCurveTetFilter* New();
  vtkTypeMacro(vtkCurveTetFilter, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Search radius factor of the advancing front: candidates within Alpha * h of the ideal
   * point (default 1.5, the paper's). Must be > 0.
   */
  vtkSetClampMacro(Alpha, double, 1e-6, VTK_DOUBLE_MAX);
  vtkGetMacro(Alpha, double);
  ///@}

  ///@{
  /**
   * Target edge length. <= 0 (default): chosen from the surface (graded from the boundary
   * triangle sizes, or uniform with UniformSize on).
   */
  vtkSetMacro(Size, double);
  vtkGetMacro(Size, double);
  ///@}

  ///@{
  /**
   * When Size <= 0: use the paper's uniform size (from the mean curved triangle area)
   * instead of grading from the boundary. Default off.
   */
  vtkSetMacro(UniformSize, vtkTypeBool);
  vtkGetMacro(UniformSize, vtkTypeBool);
  vtkBooleanMacro(UniformSize, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Quality improvement and high-order node optimization after generation. Default on.
   */
  vtkSetMacro(Optimize, vtkTypeBool);
  vtkGetMacro(Optimize, vtkTypeBool);
  vtkBooleanMacro(Optimize, vtkTypeBool);
  ///@}

  ///@{
  /**
   * More high-order rounds where some element starts poor (CAD parts such as the screw):
   * two to three times that stage's work there, for fewer elements left between the worst
   * one and min J / max J 0.85; the worst is about as good either way. Default off.
   */
  vtkSetMacro(Thorough, vtkTypeBool);
  vtkGetMacro(Thorough, vtkTypeBool);
  vtkBooleanMacro(Thorough, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Linear input only: edges whose dihedral angle is sharper than this (degrees) are
   * features, curved along the feature line. Default 40; in (0, 180].
   */
  vtkSetClampMacro(FeatureAngle, double, 1e-6, 180.0);
  vtkGetMacro(FeatureAngle, double);
  ///@}

  ///@{
  /**
   * Linear input only: Taubin smoothing iterations of its vertices before curving.
   * Default 0 (vertices kept). For surfaces from image segmentation (vtkMarchingCubes,
   * vtkDiscreteFlyingEdges3D), whose needle and cap triangles leave the front stuck: 10
   * makes them well shaped. Moves the surface (a fraction of a voxel), rounds sharp
   * edges.
   */
  vtkSetClampMacro(SmoothIterations, int, 0, VTK_INT_MAX);
  vtkGetMacro(SmoothIterations, int);
  ///@}

  ///@{
  /**
   * Worker threads of curvetet's parallel stages; 0 (default): all cores. The result does
   * not depend on it.
   */
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /**
   * Name of the input's integer cell array holding the triangles' tags. Default
   * "BoundaryTag"; absent array: all tags 0.
   */
  vtkSetStringMacro(BoundaryTagArrayName);
  vtkGetStringMacro(BoundaryTagArrayName);
  ///@}

  /**
   * curvetet's message of the last failed execution, "" after a success.
   */
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }

  /**
   * curvetet's JSON report of the last mesh (counts, quality histograms, timings), ""
   * when the last execution failed.
   */
  const char* GetReportJSON() const { return this->ReportJSON.c_str(); }

protected:
  vtkCurveTetFilter();
  ~vtkCurveTetFilter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double Alpha;
  double Size;
  vtkTypeBool UniformSize;
  vtkTypeBool Optimize;
  vtkTypeBool Thorough;
  double FeatureAngle;
  int SmoothIterations;
  int NumberOfThreads;
  char* BoundaryTagArrayName;

private:
  vtkCurveTetFilter(const vtkCurveTetFilter&) = delete;
  void operator=(const vtkCurveTetFilter&) = delete;

  static int ProgressCallback(void* self, double fraction, const char* stage);
  void Fail(const std::string& message);

  std::string LastErrorMessage;
  std::string ReportJSON;
  double LastProgress = 0.0;
};

#endif
