/**
 * @class   vtkNimbusSmokeSource
 * @brief   Rising smoke from a fluid simulation (002 §4): density, temperature and velocity
 *          over time.
 *
 * Runs nimbus::SmokeSolver (Filters/Core/SmokeSolver.h: a MAC grid, Boussinesq buoyancy,
 * an eddy viscosity for 002 §4's Reynolds equations, vorticity confinement, pressure
 * projection by conjugate gradients) on Dimensions cells of CellSizeMetres from Origin
 * (z up), with one emitter: a sphere at EmitterCentre of EmitterRadiusMetres adding
 * EmitterDensityPerSecond of density per second at EmitterTemperatureKelvin, blowing at
 * EmitterVelocity (m/s; 0 leaves the air alone). The top of the box is open and its
 * bottom a wall; its four sides are walls, or open so that the wind blows through the box
 * (SideBoundaries: by default open when there is wind, walls when there is none).
 *
 * Optional input (port 0), the obstacles the smoke flows around: either vtkImageData with
 * a point or cell array "obstacle" (non-zero: solid), one value per simulation cell
 * (Dimensions points, or Dimensions + 1 points with cell data); or vtkPolyData, a closed
 * surface in metres (polygons and strips; a cell is solid when its centre is inside:
 * nimbus::VoxelizeClosedSurface, Filters/Core/Voxelize.h). An open surface is an error.
 *
 * Output: vtkImageData with a point per cell centre (origin Origin + h/2, spacing h),
 * point data "density" (dimensionless, the active scalars: what the Cloud representation
 * multiplies by its extinction per density), "temperature" (K), "velocity" (m/s) and, with
 * obstacles, "obstacle" (1 in solid cells).
 *
 * Time: frame f is the state after f x FrameDurationSeconds of simulation; the source
 * advertises TIME_STEPS for frames 0..NumberOfFrames so ParaView's animation plays it. A
 * requested time shows the nearest frame at or before it. States are kept every
 * CheckpointInterval frames (and the last one), so playing forward costs one frame and
 * jumping back at most CheckpointInterval frames; the output for a time depends only on
 * the parameters, never on the order times were asked for. Progress is reported per frame
 * and AbortExecute stops between sub-steps (the output is then empty).
 *
 * With Puffs on, the output grid is PuffResolution times finer and its density is the
 * puffs' (see Puffs below).
 *
 * Pieces (data parallel): the output is the requested extent (a piece with its ghost layers
 * under MPI), bit-identical to the same points of the serial output. The pressure solve is
 * global and a distributed solver is out of scope, so every rank runs the whole simulation
 * redundantly (on the whole obstacle input) and outputs only its extent: memory and time
 * are NOT divided between ranks, only the data handed downstream is.
 *
 * Bad input (an error naming it, empty output): the solver's refusals
 * (CheckSmokeParameters: non-finite or out-of-range numbers, grid sizes, obstacles
 * covering every cell), an obstacle input of the wrong size, a frame that needs more than
 * the solver's MaxSubsteps.
 */
#ifndef vtkNimbusSmokeSource_h
#define vtkNimbusSmokeSource_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <memory> // for std::unique_ptr

class vtkPolyData;

class NIMBUSFILTERS_EXPORT vtkNimbusSmokeSource : public vtkImageAlgorithm
{
public:
  static vtkNimbusSmokeSource* New();
  vtkTypeMacro(vtkNimbusSmokeSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The grid: cells per axis (default 32 x 32 x 48), their size (m, 0.25) and the
  /// corner (m, default (-4, -4, 0)).
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  vtkSetMacro(CellSizeMetres, double);
  vtkGetMacro(CellSizeMetres, double);
  vtkSetVector3Macro(Origin, double);
  vtkGetVector3Macro(Origin, double);
  ///@}

  ///@{
  /// The emitter (defaults: at (0, 0, 0.75) m, radius 0.75 m, 2 density units per
  /// second, 600 K, no velocity of its own).
  vtkSetVector3Macro(EmitterCentre, double);
  vtkGetVector3Macro(EmitterCentre, double);
  vtkSetMacro(EmitterRadiusMetres, double);
  vtkGetMacro(EmitterRadiusMetres, double);
  vtkSetMacro(EmitterDensityPerSecond, double);
  vtkGetMacro(EmitterDensityPerSecond, double);
  vtkSetMacro(EmitterTemperatureKelvin, double);
  vtkGetMacro(EmitterTemperatureKelvin, double);
  vtkSetVector3Macro(EmitterVelocity, double);
  vtkGetVector3Macro(EmitterVelocity, double);
  ///@}

  ///@{
  /// The air: ambient temperature (K, 293.15), wind (m/s, 0) and how fast the air takes
  /// its speed (1/s, 0.5), cooling of the smoke (1/s, 0.2), fading of its density (1/s,
  /// 0), vorticity confinement (0.3), the Smagorinsky constant of the eddy viscosity
  /// (0.15), the advection scheme (0 semi-Lagrangian, 1 MacCormack: default), the box's
  /// sides (SideBoundaries: 0 automatic, the default: open when the wind and its coupling
  /// are not 0, walls otherwise; 1 walls; 2 open: air and smoke pass through them, what
  /// flows in is the wind, without smoke, at the ambient temperature, so the wind blows
  /// through the box; with walls a steady wind hardly moves the air inside).
  vtkSetMacro(AmbientTemperatureKelvin, double);
  vtkGetMacro(AmbientTemperatureKelvin, double);
  vtkSetVector3Macro(Wind, double);
  vtkGetVector3Macro(Wind, double);
  vtkSetMacro(WindCoupling, double);
  vtkGetMacro(WindCoupling, double);
  vtkSetMacro(CoolingPerSecond, double);
  vtkGetMacro(CoolingPerSecond, double);
  vtkSetMacro(DissipationPerSecond, double);
  vtkGetMacro(DissipationPerSecond, double);
  vtkSetMacro(VorticityConfinement, double);
  vtkGetMacro(VorticityConfinement, double);
  vtkSetMacro(SmagorinskyConstant, double);
  vtkGetMacro(SmagorinskyConstant, double);
  vtkSetClampMacro(Advection, int, 0, 1);
  vtkGetMacro(Advection, int);
  vtkSetClampMacro(SideBoundaries, int, 0, 2);
  vtkGetMacro(SideBoundaries, int);
  ///@}

  ///@{
  /// Puffs (002 §4; Filters/Core/SmokePuffs.h), off by default: metaball particles born
  /// in the emitter (PuffsPerSecond, radius PuffRadiusMetres, growing by
  /// PuffGrowthPerSecond of it per second, removed after PuffLifetimeSeconds), carried by
  /// the simulated air. When on, the output's "density" is the puffs splatted on a grid
  /// PuffResolution times finer per axis than the simulation's (1 to 4), so detail
  /// finer than the simulation's cells survives; each puff carries the smoke of
  /// EmitterDensityPerSecond / PuffsPerSecond seconds of emission (the same amount as the
  /// grid's smoke), and "temperature" and "velocity" are the simulation's, interpolated
  /// (trilinear) to the finer points. "grid_density" is then the simulation's own density
  /// at those points.
  vtkSetMacro(Puffs, bool);
  vtkGetMacro(Puffs, bool);
  vtkBooleanMacro(Puffs, bool);
  vtkSetMacro(PuffsPerSecond, double);
  vtkGetMacro(PuffsPerSecond, double);
  vtkSetMacro(PuffRadiusMetres, double);
  vtkGetMacro(PuffRadiusMetres, double);
  vtkSetMacro(PuffGrowthPerSecond, double);
  vtkGetMacro(PuffGrowthPerSecond, double);
  vtkSetMacro(PuffLifetimeSeconds, double);
  vtkGetMacro(PuffLifetimeSeconds, double);
  vtkSetClampMacro(PuffResolution, int, 1, 4);
  vtkGetMacro(PuffResolution, int);
  ///@}

  ///@{
  /// Time: seconds per frame (1/24), frames (96), checkpoints every this many frames
  /// (8), threads (0: all cores; results do not depend on it).
  vtkSetMacro(FrameDurationSeconds, double);
  vtkGetMacro(FrameDurationSeconds, double);
  vtkSetClampMacro(NumberOfFrames, int, 1, 100000);
  vtkGetMacro(NumberOfFrames, int);
  vtkSetClampMacro(CheckpointInterval, int, 1, 100000);
  vtkGetMacro(CheckpointInterval, int);
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /// The frame the last output shows, and the solver's sub-steps it took to get there.
  int GetLastFrame() const;
  int GetLastSubsteps() const;

protected:
  vtkNimbusSmokeSource();
  ~vtkNimbusSmokeSource() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Dimensions[3] = { 32, 32, 48 };
  double CellSizeMetres = 0.25;
  double Origin[3] = { -4.0, -4.0, 0.0 };
  double EmitterCentre[3] = { 0.0, 0.0, 0.75 };
  double EmitterRadiusMetres = 0.75;
  double EmitterDensityPerSecond = 2.0;
  double EmitterTemperatureKelvin = 600.0;
  double EmitterVelocity[3] = { 0.0, 0.0, 0.0 };
  double AmbientTemperatureKelvin = 293.15;
  double Wind[3] = { 0.0, 0.0, 0.0 };
  double WindCoupling = 0.5;
  double CoolingPerSecond = 0.2;
  double DissipationPerSecond = 0.0;
  double VorticityConfinement = 0.3;
  double SmagorinskyConstant = 0.15;
  int Advection = 1;
  int SideBoundaries = 0;
  double FrameDurationSeconds = 1.0 / 24.0;
  int NumberOfFrames = 96;
  int CheckpointInterval = 8;
  int NumberOfThreads = 0;
  bool Puffs = false;
  double PuffsPerSecond = 400.0;
  double PuffRadiusMetres = 0.4;
  double PuffGrowthPerSecond = 0.3;
  double PuffLifetimeSeconds = 20.0;
  int PuffResolution = 2;

private:
  vtkNimbusSmokeSource(const vtkNimbusSmokeSource&) = delete;
  void operator=(const vtkNimbusSmokeSource&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;

  // RequestData's steps; false: an error was reported, no output.
  struct SmokeSetup;
  void WarnOnceAboutPieces(vtkInformationVector* outputVector);
  void FillSmokeParameters(SmokeSetup& setup) const;
  bool ReadObstacles(vtkInformationVector* inputVector, SmokeSetup& setup);
  bool ReadObstacleImage(vtkImageData* obstacleImage, SmokeSetup& setup);
  bool VoxelizeObstacleSurface(vtkPolyData* obstacleSurface, SmokeSetup& setup);
  bool FillPuffParameters(SmokeSetup& setup);
  void ForgetStatesIfChanged(const SmokeSetup& setup);
  void MoveSolverToCheckpoint(const SmokeSetup& setup, int frame);
  bool StepSolverTo(const SmokeSetup& setup, int frame); // false: aborted
  void FillOutput(const SmokeSetup& setup, vtkImageData* output);
};

#endif
