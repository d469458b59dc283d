/**
 * @class   vtkNimbusMetaballCloudSource
 * @brief   Metaball cloud density on a regular grid, grown fractally (004 §4).
 *
 * Builds a cumulus-like density field from metaballs with Wyvill's degree-6 falloff:
 * a basic shape of large balls (user-given with AddBall, or seeded-random), then
 * NumberOfLevels fractal growth steps. Each step extracts the isosurface of the
 * current field at IsoValue with VTK's flying edges, places smaller balls on its
 * triangles (area-weighted, none where the surface faces down so the base stays
 * flat), and repeats with radii scaled by RadiusScalePerLevel. With FlatBase on the
 * density is also faded to zero at BaseHeight (the condensation level).
 *
 * Output port 0: vtkImageData covering Bounds with Dimensions points and a float
 * point array "density" (dimensionless; 0 = clear air, BallDensity at an isolated
 * ball's centre).
 * Output port 1: vtkPolyData with one vertex per metaball at its centre and point
 * arrays "radius" (m), "density" and "level" (0 = basic shape).
 *
 * Pieces (data parallel): port 0 produces the requested extent (a piece with its ghost
 * layers under MPI), bit-identical to the same points of the serial output. The growth
 * levels extract the isosurface of the whole field, so every piece runs them on the whole
 * grid (redundant work); only the final sampling is restricted to the piece. Port 1 holds
 * the metaballs on piece 0 only (the other pieces' port 1 is empty).
 *
 * Units: Bounds, radii, heights in metres. The result depends only on the
 * parameters and Seed (same seed -> identical bytes).
 * Invalid parameters (non-positive dimensions, empty or non-finite bounds, no
 * balls, non-positive radii, NaN or infinity anywhere, values outside the ranges given
 * below) produce an error message and empty outputs; so do outputs that would need more
 * memory than MemoryBudgetMiB, or more work than about 2e11 grid-point and ball updates
 * (the message gives the estimate). Nothing is allocated before it has been checked
 * against the budget, and no exception leaves RequestData. Long runs report progress
 * and stop soon after AbortExecute is set (outputs then empty).
 *
 * Valid ranges (lengths in metres): Bounds within +-1e8 with min < max on every axis;
 * radii in (0, 1e8]; FootprintRadius, TowerHeight, BaseTransitionThickness in [0, 1e8];
 * BaseHeight within +-1e8; BallDensity and AddBall densities in [0, 1e6] (so that sums
 * of overlapping balls stay finite in float); IsoValue finite; NumberOfLevels in
 * [0, 100]; RadiusScalePerLevel in (0, 1]; BallCountFactor in (0, 1e3]; at most 1e7
 * balls in all.
 */
#ifndef vtkNimbusMetaballCloudSource_h
#define vtkNimbusMetaballCloudSource_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <functional> // for std::function
#include <memory>     // for std::unique_ptr
#include <vector>     // for std::vector

class vtkImageData;
class vtkPolyData;
namespace nimbus
{
struct GridGeometry;
struct Metaball;
class Random;
}

class NIMBUSFILTERS_EXPORT vtkNimbusMetaballCloudSource : public vtkImageAlgorithm
{
public:
  static vtkNimbusMetaballCloudSource* New();
  vtkTypeMacro(vtkNimbusMetaballCloudSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Number of grid points along x, y, z (each >= 1). Default 96 x 96 x 64.
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /// Region covered by the grid (xmin, xmax, ymin, ymax, zmin, zmax), metres.
  /// Default (-1500, 1500, -1500, 1500, 800, 2800). z is up.
  vtkSetVector6Macro(Bounds, double);
  vtkGetVector6Macro(Bounds, double);
  ///@}

  ///@{
  /// Seed of the random basic shape and growth. Default 1.
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Number of fractal growth levels (>= 0). Default 3.
  vtkSetMacro(NumberOfLevels, int);
  vtkGetMacro(NumberOfLevels, int);
  ///@}

  ///@{
  /// Random basic shape (used when no ball was added with AddBall): number of
  /// balls, their radius range (m), the radius of the disc their centres lie in
  /// (m, around the centre of Bounds), and how far above the base the centres
  /// may rise (m). Defaults 10, (350, 600), 700, 600.
  vtkSetMacro(NumberOfBaseBalls, int);
  vtkGetMacro(NumberOfBaseBalls, int);
  vtkSetVector2Macro(BaseBallRadiusRange, double);
  vtkGetVector2Macro(BaseBallRadiusRange, double);
  vtkSetMacro(FootprintRadius, double);
  vtkGetMacro(FootprintRadius, double);
  vtkSetMacro(TowerHeight, double);
  vtkGetMacro(TowerHeight, double);
  ///@}

  ///@{
  /// Growth: number of balls placed at the first level, multiplied by
  /// BallCountFactor at each further level; radii of level k are the basic
  /// shape's range times RadiusScalePerLevel^k. Defaults 60, 2, 0.5.
  vtkSetMacro(BallsPerLevel, int);
  vtkGetMacro(BallsPerLevel, int);
  vtkSetMacro(BallCountFactor, double);
  vtkGetMacro(BallCountFactor, double);
  vtkSetMacro(RadiusScalePerLevel, double);
  vtkGetMacro(RadiusScalePerLevel, double);
  ///@}

  ///@{
  /// Density at the centre of every generated ball. Default 1.
  vtkSetMacro(BallDensity, double);
  vtkGetMacro(BallDensity, double);
  ///@}

  ///@{
  /// Density level of the isosurface the growth step seeds balls on. Default 0.5.
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /// Cloud base: the random basic shape sits on BaseHeight (m). With FlatBase on
  /// the density is also 0 at and below BaseHeight and fades in over
  /// BaseTransitionThickness (m) above it. Defaults on, 1000, 100.
  vtkSetMacro(FlatBase, bool);
  vtkGetMacro(FlatBase, bool);
  vtkBooleanMacro(FlatBase, bool);
  vtkSetMacro(BaseHeight, double);
  vtkGetMacro(BaseHeight, double);
  vtkSetMacro(BaseTransitionThickness, double);
  vtkGetMacro(BaseTransitionThickness, double);
  ///@}

  ///@{
  /// User-given basic shape: balls added here replace the random one.
  /// Centre and radius in metres; density at the centre.
  void AddBall(double x, double y, double z, double radius, double density);
  void RemoveAllBalls();
  int GetNumberOfUserBalls() const;
  ///@}

  ///@{
  /// Memory the source may use for one update, MiB (> 0, finite). Outputs that would need
  /// more are refused with a message instead of being allocated. Default
  /// nimbus::DefaultMemoryBudgetMiB(): half the physical memory, at most three quarters of
  /// the process's address-space limit.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  /// (1, nimbus::DefaultMemoryBudgetMiB()) MiB: ParaView's range for MemoryBudgetMiB, whose
  /// default there is the upper end (the machine's default, not a number in the XML).
  vtkGetVector2Macro(MemoryBudgetRangeMiB, double);
  ///@}

  /// The metaballs of the last update (port 1's data).
  vtkPolyData* GetMetaballs();

protected:
  vtkNimbusMetaballCloudSource();
  ~vtkNimbusMetaballCloudSource() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /// Returns false (after vtkErrorMacro) when a parameter is unusable, or the output
  /// would need more memory than MemoryBudgetMiB or more work than the limit.
  bool CheckParameters();

  /// RequestData's work; may throw (RequestData catches).
  int Generate(vtkImageData* image, vtkPolyData* metaballs);

  int Dimensions[3];
  double Bounds[6];
  int Seed;
  int NumberOfLevels;
  int NumberOfBaseBalls;
  double BaseBallRadiusRange[2];
  double FootprintRadius;
  double TowerHeight;
  int BallsPerLevel;
  double BallCountFactor;
  double RadiusScalePerLevel;
  double BallDensity;
  double IsoValue;
  bool FlatBase;
  double BaseHeight;
  double BaseTransitionThickness;
  double MemoryBudgetMiB;
  double MemoryBudgetRangeMiB[2];

private:
  vtkNimbusMetaballCloudSource(const vtkNimbusMetaballCloudSource&) = delete;
  void operator=(const vtkNimbusMetaballCloudSource&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;

  // CheckParameters's steps, in order; false after vtkErrorMacro.
  bool CheckGridParameters();  // MemoryBudgetMiB, Dimensions, Bounds
  bool CheckBallParameters();  // finite values, levels, the basic shape's balls
  bool CheckShapeParameters(); // densities, lengths, growth factors
  bool CheckMemoryAndWork();   // the estimates against MemoryBudgetMiB and the work limit

  // Generate's steps; false: aborted (or, for FillDensityOutput, an error was reported).
  std::vector<nimbus::Metaball> MakeBasicShape(nimbus::Random& random);
  bool GrowBalls(const nimbus::GridGeometry& grid, nimbus::Random& random, double& stepStart,
    const std::function<bool(double)>& progress, std::vector<nimbus::Metaball>& balls,
    std::vector<float>& density);
  bool FillDensityOutput(
    const nimbus::GridGeometry& grid, const std::vector<float>& density, vtkImageData* image);
};

#endif
