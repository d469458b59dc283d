/**
 * @class   vtkNimbusCloudAutomatonSource
 * @brief   Animated cloud density from the cloud cellular automaton (002 §3).
 *
 * Runs the three-field (hum/act/cld) cellular automaton of Dobashi et al. (see
 * Filters/Core/CloudAutomaton.h and shared/papers/README.md for the rules) on a grid of
 * Dimensions cells covering Bounds, and outputs vtkImageData with a float point array
 * "density" in [0, 1]: the cld field smoothed by a degree-6 kernel of SmoothingRadius cells
 * and interpolated linearly in time between automaton steps.
 *
 * Time: one automaton step lasts StepDuration seconds. The source advertises TIME_STEPS
 * 0, dt, ..., NumberOfTimeSteps dt and TIME_RANGE, so ParaView's animation steps through
 * it. A requested time t is computed from the nearest cached state at or before step
 * floor(t / dt): the source keeps checkpoints every CheckpointInterval steps (at most
 * MaximumNumberOfCheckpoints) and the last smoothed densities, so stepping forward costs
 * one automaton step and jumping back costs at most CheckpointInterval steps. The output
 * for a given time depends only on the parameters, the input and Seed -- never on the
 * order times were requested.
 *
 * Formation regions (on by default): vapour and activation are supplied in
 * NumberOfFormationRegions Gaussian ellipsoids, as Dobashi et al. (2000) shape their supply
 * probabilities so that separate clouds form (Filters/Core/CloudAutomaton.h,
 * RandomFormationRegions): p_hum = HumidityProbability w and p_act = ActivationProbability w,
 * w = exp(-r^2/2) in [0, 1] (0 beyond r = 3), r the distance from the nearest region's centre
 * in semi-axes. The regions are drawn from Seed: centres uniform over x and y at 30 % of the
 * grid's height, horizontal semi-axes in FormationRegionRadiusRange (metres), vertical ones
 * half as long. NumberOfFormationRegions 0 gives the uniform probabilities everywhere.
 * Extinction stays uniform, so clouds that the wind carries out of a region decay.
 *
 * Spin-up: time 0 shows automaton step SpinUpSteps (default 40), so that the first frame
 * already has grown clouds; time t shows step SpinUpSteps + t / StepDuration.
 *
 * Pieces (data parallel): the output is the requested extent (a piece with its ghost layers
 * under MPI), bit-identical to the same points of the serial output. When every rank of the
 * global vtkMultiProcessController asks for its own piece (piece = rank, pieces = ranks, as
 * pvbatch and pvserver do) and the grid has at least 2 layers per rank, the ranks share the
 * automaton: rank r steps only its slab of layers (nimbus::DistributedLayers: nz / ranks
 * layers, plus 2 below and 1 above, the reach of the rules in z; the wind moves only along x
 * and y, and x and y stay whole, so the periodic sides wrap within the slab), and after each
 * step sends its 2 top layers up and its bottom layer down (3 fields, ny rows of
 * ceil(nx / 64) words each). Every random number is keyed by the global cell, so the slabs
 * step exactly as the whole grid. The density of the rank's piece is then smoothed from the
 * cld rows around it (nimbus::SmoothCloudBox), which the ranks that own them scatter to it.
 * Otherwise (one process, or a request that is not one piece per rank) the whole grid is run
 * and cropped, as before. GetHaloBytesPerStep() and GetPieceGatherBytes() say what a rank
 * sent per step and received for its last piece.
 *
 * Optional input (port 0): vtkImageData whose point arrays "p_ext", "p_hum", "p_act"
 * (one component, values in [0, 1]) replace the scalar ExtinctionProbability,
 * HumidityProbability, ActivationProbability per cell (arrays given replace the formation
 * regions' fields too). The input must have the source's
 * Dimensions (a 3-D field) or Dimensions[0] x Dimensions[1] x 1 (a 2-D map used at every
 * height). Its geometry is ignored; cell (i, j, k) of the automaton is point (i, j, k).
 *
 * Units: Bounds in metres; Wind in m/s (x, y) at the bottom of the grid, Shear in
 * (m/s) per metre of height; StepDuration in seconds; probabilities per cell per step.
 * The field data holds "AutomatonStep" (the fractional step shown).
 *
 * NaN or infinite probabilities or smoothing radius are refused by their setters at once
 * (an error naming the property and the value; the previous value is kept); finite values
 * are clamped to their ranges. Other bad input ends in an error message and an empty
 * output, never in an exception or an allocation VTK cannot make: StepDuration outside [1e-6, 1e9]
 * s, Bounds not finite, not min < max or beyond +-1e8 m, a wind or shear that moves a layer more
 * than 1e6 cells per step, input arrays with values outside [0, 1] (counted in the message), a
 * grid, cache and checkpoints that would need more than MemoryBudgetMiB, or a requested time that
 * would need more than about 1e11 cell updates from the nearest cached state (the message gives the
 * estimate). Stepping reports progress and stops soon after AbortExecute is set (the output is then
 * empty; the states computed so far stay cached).
 */
#ifndef vtkNimbusCloudAutomatonSource_h
#define vtkNimbusCloudAutomatonSource_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <memory> // for std::unique_ptr

class NIMBUSFILTERS_EXPORT vtkNimbusCloudAutomatonSource : public vtkImageAlgorithm
{
public:
  static vtkNimbusCloudAutomatonSource* New();
  vtkTypeMacro(vtkNimbusCloudAutomatonSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Number of cells (= output points) along x, y, z, each >= 1. Default 128 x 128 x 32.
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /// Region covered by the grid (xmin, xmax, ymin, ymax, zmin, zmax), metres, z up.
  /// Default (-6400, 6400, -6400, 6400, 1000, 2600).
  vtkSetVector6Macro(Bounds, double);
  vtkGetVector6Macro(Bounds, double);
  ///@}

  ///@{
  /// Seed of every random draw. Default 1.
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Per-step probabilities used where the input has no array: cloud extinction p_ext,
  /// vapour supply p_hum, activation supply p_act (002 §3); with formation regions, p_hum and
  /// p_act at a region's centre (scaled by the region's weight elsewhere). Defaults 0.06,
  /// 0.1, 0.005.
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetExtinctionProbability(double value);
  double GetExtinctionProbabilityMinValue() { return 0.0; }
  double GetExtinctionProbabilityMaxValue() { return 1.0; }
  vtkGetMacro(ExtinctionProbability, double);
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetHumidityProbability(double value);
  double GetHumidityProbabilityMinValue() { return 0.0; }
  double GetHumidityProbabilityMaxValue() { return 1.0; }
  vtkGetMacro(HumidityProbability, double);
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetActivationProbability(double value);
  double GetActivationProbabilityMinValue() { return 0.0; }
  double GetActivationProbabilityMaxValue() { return 1.0; }
  vtkGetMacro(ActivationProbability, double);
  ///@}

  ///@{
  /// Probabilities of hum and act in each cell at step 0 (cld starts empty).
  /// Defaults 0 and 0 (the formation regions supply both).
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetInitialHumidity(double value);
  double GetInitialHumidityMinValue() { return 0.0; }
  double GetInitialHumidityMaxValue() { return 1.0; }
  vtkGetMacro(InitialHumidity, double);
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetInitialActivation(double value);
  double GetInitialActivationMinValue() { return 0.0; }
  double GetInitialActivationMaxValue() { return 1.0; }
  vtkGetMacro(InitialActivation, double);
  ///@}

  ///@{
  /// Wind (m/s, x and y) at the bottom of the grid, and its increase per metre of height
  /// ((m/s)/m). The fields move by whole cells; fractional motion accumulates exactly.
  /// Defaults (4, 0) and (0.002, 0): a light breeze along +x, 7 m/s at the default top.
  vtkSetVector2Macro(Wind, double);
  vtkGetVector2Macro(Wind, double);
  vtkSetVector2Macro(Shear, double);
  vtkGetVector2Macro(Shear, double);
  ///@}

  ///@{
  /// Formation regions (see the class description): how many (0: uniform probabilities;
  /// clamped to [0, 10000]; default 10) and the range of their horizontal semi-axes, metres
  /// (both > 0 and finite, else RequestData refuses them; default (400, 700)). With open
  /// boundaries the centres keep three semi-axes from the x and y faces.
  vtkSetClampMacro(NumberOfFormationRegions, int, 0, 10000);
  vtkGetMacro(NumberOfFormationRegions, int);
  vtkSetVector2Macro(FormationRegionRadiusRange, double);
  vtkGetVector2Macro(FormationRegionRadiusRange, double);
  ///@}

  ///@{
  /// Automaton steps run before time 0 (clamped to [0, 1e6]; default 40), so that the first
  /// frame shows grown clouds.
  vtkSetClampMacro(SpinUpSteps, int, 0, 1000000);
  vtkGetMacro(SpinUpSteps, int);
  ///@}

  ///@{
  /// On: the grid wraps around in x and y (clouds blown out come back in). Off: open
  /// faces, clear air blows in. z is always open. Default off (open: clouds leave downwind
  /// instead of coming back cut by the faces).
  vtkSetMacro(PeriodicBoundary, bool);
  vtkGetMacro(PeriodicBoundary, bool);
  vtkBooleanMacro(PeriodicBoundary, bool);
  ///@}

  ///@{
  /// Seconds per automaton step (in [1e-6, 1e9]) and number of steps advertised as
  /// TIME_STEPS (clamped to [0, 1e6]). Defaults 10 and 100.
  vtkSetMacro(StepDuration, double);
  vtkGetMacro(StepDuration, double);
  vtkSetClampMacro(NumberOfTimeSteps, int, 0, 1000000);
  vtkGetMacro(NumberOfTimeSteps, int);
  ///@}

  ///@{
  /// Radius (cells) of the smoothing kernel; <= 1 gives the raw 0/1 cld field. Default 2.5.
  /// Clamped to [0.0, 16.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetSmoothingRadius(double value);
  double GetSmoothingRadiusMinValue() { return 0.0; }
  double GetSmoothingRadiusMaxValue() { return 16.0; }
  vtkGetMacro(SmoothingRadius, double);
  ///@}

  ///@{
  /// Interpolate linearly between the two steps around the requested time (on), or show
  /// the step at or before it (off). Default on.
  vtkSetMacro(InterpolateInTime, bool);
  vtkGetMacro(InterpolateInTime, bool);
  vtkBooleanMacro(InterpolateInTime, bool);
  ///@}

  ///@{
  /// Worker threads of the automaton and smoothing (0: one per hardware thread). The
  /// result does not depend on it. Default 0.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /// Checkpoints: a copy of the state every CheckpointInterval steps, at most
  /// MaximumNumberOfCheckpoints kept (step 0 is always recomputable). Defaults 10 and 16.
  vtkSetClampMacro(CheckpointInterval, int, 1, 1000000);
  vtkGetMacro(CheckpointInterval, int);
  vtkSetClampMacro(MaximumNumberOfCheckpoints, int, 0, 100000);
  vtkGetMacro(MaximumNumberOfCheckpoints, int);
  ///@}

  ///@{
  /// Memory the source may use (grid states, checkpoints, cached densities, output), MiB
  /// (> 0, finite). Settings that would need more are refused with a message. Default
  /// nimbus::DefaultMemoryBudgetMiB(): half the physical memory, at most three quarters of
  /// the process's address-space limit.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  /// (1, nimbus::DefaultMemoryBudgetMiB()) MiB: ParaView's range for MemoryBudgetMiB, whose
  /// default there is the upper end (the machine's default, not a number in the XML).
  vtkGetVector2Macro(MemoryBudgetRangeMiB, double);
  ///@}

  /// Automaton steps run since the cache was last reset (for tests and timings).
  vtkGetMacro(NumberOfStepsComputed, vtkIdType);

  ///@{
  /// Distributed runs (see Pieces above): bytes this rank sends to its neighbours per automaton
  /// step, and bytes of cld rows it received for the density of its last piece; 0 when the
  /// whole grid runs here. The layers this rank owns, [first, end) (the whole grid when not
  /// distributed).
  vtkGetMacro(HaloBytesPerStep, vtkIdType);
  vtkGetMacro(PieceGatherBytes, vtkIdType);
  vtkGetVector2Macro(OwnedLayers, int);
  ///@}

protected:
  vtkNimbusCloudAutomatonSource();
  ~vtkNimbusCloudAutomatonSource() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /// RequestData's work; may throw (RequestData catches and clears the cache).
  int Generate(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
  /// False (after vtkErrorMacro) when a parameter is unusable.
  bool CheckParameters();

  int Dimensions[3];
  double Bounds[6];
  int Seed;
  double ExtinctionProbability;
  double HumidityProbability;
  double ActivationProbability;
  double InitialHumidity;
  double InitialActivation;
  double Wind[2];
  double Shear[2];
  int NumberOfFormationRegions;
  double FormationRegionRadiusRange[2];
  int SpinUpSteps;
  bool PeriodicBoundary;
  double StepDuration;
  int NumberOfTimeSteps;
  double SmoothingRadius;
  bool InterpolateInTime;
  int NumberOfThreads;
  int CheckpointInterval;
  int MaximumNumberOfCheckpoints;
  vtkIdType NumberOfStepsComputed;
  vtkIdType HaloBytesPerStep = 0;
  vtkIdType PieceGatherBytes = 0;
  int OwnedLayers[2] = { 0, 0 };
  double MemoryBudgetMiB;
  double MemoryBudgetRangeMiB[2];

private:
  vtkNimbusCloudAutomatonSource(const vtkNimbusCloudAutomatonSource&) = delete;
  void operator=(const vtkNimbusCloudAutomatonSource&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
  /// Sets up Internals' automaton for the held layers [held[0], held[1]) (input maps and
  /// formation regions included); false (after vtkErrorMacro) when the input is unusable.
  bool SetUpAutomaton(vtkImageData* input, const int held[2]);
};

#endif
