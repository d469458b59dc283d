/**
 * @class   vtkNimbusDunesSource
 * @brief   Sand dunes and wind ripples grown by a cellular automaton (002 §5).
 *
 * Two height fields, simulated separately at their own scales (002 §5.1) by the
 * saltation-and-creep automaton of Nishimori and Ouchi (1993) in
 * Filters/Core/DuneAutomaton.h:
 *  - the dunes: Dimensions cells of CellSizeMetres on a rock floor, a random sand bed
 *    (SandDepthMetres +- SandDepthVariationMetres / 2, from Seed) grown for SpinUpSteps
 *    steps, then StepsPerTimeStep steps per time step, with wind shadows and avalanches;
 *  - the ripples: a periodic RippleResolution^2 tile of RippleCellSizeMetres cells, grown
 *    for RippleSteps steps from a flat bed with a millimetre of noise (static in time).
 * The wind blows along +x; both fields are periodic in x and y, so the outputs tile.
 *
 * Output 0 (vtkPolyData): the dune surface, (nx + 1) x (ny + 1) points (the first row and
 * column repeated at the far side, so copies shifted by the field's size meet exactly)
 * centred on the origin, z up, quads; point arrays "Height" (m of sand; under 1 micrometre
 * shown as 0, bare rock), "Normals",
 * "TextureCoordinates" (x and y divided by the ripple tile's size: one repeat per tile)
 * and "Tangents" (the surface's x direction, for normal mapping).
 * Output 1 (vtkImageData): the ripple tile, RippleResolution^2 points of RippleCellSizeMetres;
 * point arrays "RippleHeight" (m, relative to the bed's mean), "RippleNormal" (unit
 * vectors, tangent space: z along the surface normal, x downwind) and "RippleNormalMap"
 * (unsigned char RGB = 255 (n + 1) / 2, a normal-map texture). RippleNormalLevel() makes
 * the coarser levels of detail of 002 §5.2 (256^2, 128^2, 64^2, 32^2).
 *
 * Time: time t shows dune step SpinUpSteps + floor(t); TIME_STEPS are 0, s, 2s, ...,
 * NumberOfTimeSteps s with s = StepsPerTimeStep (one time unit per automaton step). The
 * source keeps its last state and the spin-up state, so stepping forward costs
 * StepsPerTimeStep steps and stepping back at most the steps since the spin-up. The result
 * for a time depends only on the parameters and Seed, not on the thread count or the order
 * of requests. Field data: "DuneAutomatonStep".
 *
 * Bad parameters (NaN, infinities, negative or zero sizes, angles outside [0, 90), rates
 * outside their ranges, grids beyond 8192 cells a side, a ripple resolution that is not a
 * multiple of 8, more than 1e11 cell steps in one request) end in vtkErrorMacro and empty
 * outputs. Progress is reported and AbortExecute stops the steps (empty outputs).
 */
#ifndef vtkNimbusDunesSource_h
#define vtkNimbusDunesSource_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

#include <memory> // for std::unique_ptr

class vtkImageData;

class NIMBUSFILTERS_EXPORT vtkNimbusDunesSource : public vtkPolyDataAlgorithm
{
public:
  static vtkNimbusDunesSource* New();
  vtkTypeMacro(vtkNimbusDunesSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Dune cells along x (downwind) and y, each in [4, 8192]. Default 128 x 128.
  vtkSetVector2Macro(Dimensions, int);
  vtkGetVector2Macro(Dimensions, int);
  ///@}

  ///@{
  /// Side of a dune cell, metres (> 0). Default 2.
  vtkSetMacro(CellSizeMetres, double);
  vtkGetMacro(CellSizeMetres, double);
  ///@}

  ///@{
  /// The initial sand bed: mean depth and the spread of its random variation, metres
  /// (>= 0; depth > 0). Defaults 3 and 3.
  vtkSetMacro(SandDepthMetres, double);
  vtkGetMacro(SandDepthMetres, double);
  vtkSetMacro(SandDepthVariationMetres, double);
  vtkGetMacro(SandDepthVariationMetres, double);
  ///@}

  ///@{
  /// Dune saltation (N&O Eq. 1): the jump L0 of a grain from the floor, metres (>= 0;
  /// default 8), its growth with height b (metres per metre, >= 0; default 0.02) and the
  /// sand lifted per cell and step q, metres (>= 0; default 0.2).
  vtkSetMacro(SaltationLengthMetres, double);
  vtkGetMacro(SaltationLengthMetres, double);
  vtkSetMacro(SaltationHeightGain, double);
  vtkGetMacro(SaltationHeightGain, double);
  vtkSetMacro(SaltationDepthMetres, double);
  vtkGetMacro(SaltationDepthMetres, double);
  ///@}

  ///@{
  /// Dune creep rate D (N&O Eq. 2), in [0, 1]. Default 0.2.
  vtkSetMacro(CreepRate, double);
  vtkGetMacro(CreepRate, double);
  ///@}

  ///@{
  /// Wind-shadow angle and angle of repose, degrees in [0, 90) (0: off). Defaults 15, 34.
  vtkSetMacro(ShadowAngleDegrees, double);
  vtkGetMacro(ShadowAngleDegrees, double);
  vtkSetMacro(ReposeAngleDegrees, double);
  vtkGetMacro(ReposeAngleDegrees, double);
  ///@}

  ///@{
  /// Dune steps before time 0 (default 2000), steps per time step (>= 1, default 10) and
  /// the number of time steps advertised (default 100). Clamped to [0, 1e7], [1, 1e6],
  /// [0, 1e6].
  vtkSetClampMacro(SpinUpSteps, int, 0, 10000000);
  vtkGetMacro(SpinUpSteps, int);
  vtkSetClampMacro(StepsPerTimeStep, int, 1, 1000000);
  vtkGetMacro(StepsPerTimeStep, int);
  vtkSetClampMacro(NumberOfTimeSteps, int, 0, 1000000);
  vtkGetMacro(NumberOfTimeSteps, int);
  ///@}

  ///@{
  /// The ripple tile: texels a side (a multiple of 8 in [8, 4096]; default 256, 002 §5.2's
  /// finest level), cell size, metres (> 0; default 0.01) and steps (clamped to [0, 1e6];
  /// default 400).
  vtkSetMacro(RippleResolution, int);
  vtkGetMacro(RippleResolution, int);
  vtkSetMacro(RippleCellSizeMetres, double);
  vtkGetMacro(RippleCellSizeMetres, double);
  vtkSetClampMacro(RippleSteps, int, 0, 1000000);
  vtkGetMacro(RippleSteps, int);
  ///@}

  ///@{
  /// Ripple saltation: L0, metres (default 0.06); b (default 1); q, metres (default 0.003);
  /// creep rate D (default 0.2). Ripples make crests about 1.4 L0 apart.
  vtkSetMacro(RippleSaltationLengthMetres, double);
  vtkGetMacro(RippleSaltationLengthMetres, double);
  vtkSetMacro(RippleSaltationHeightGain, double);
  vtkGetMacro(RippleSaltationHeightGain, double);
  vtkSetMacro(RippleSaltationDepthMetres, double);
  vtkGetMacro(RippleSaltationDepthMetres, double);
  vtkSetMacro(RippleCreepRate, double);
  vtkGetMacro(RippleCreepRate, double);
  ///@}

  ///@{
  /// Seed of the random beds. Default 1.
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Worker threads (0: one per hardware thread); the result does not depend on it.
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /// Dune steps run since the cache was last reset (for tests and timings).
  vtkGetMacro(NumberOfStepsComputed, vtkIdType);

  /// The ripple tile's level of detail `level` (0: the tile itself; each level halves the
  /// resolution: box-averaged heights, normals recomputed from them, 002 §5.2) from
  /// output 1, into `output` (arrays as output 1's). False, with nothing written, when
  /// `ripples` has no RippleHeight or the resolution does not halve `level` times.
  static bool RippleNormalLevel(vtkImageData* ripples, int level, vtkImageData* output);

  vtkImageData* GetRippleOutput();

protected:
  vtkNimbusDunesSource();
  ~vtkNimbusDunesSource() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// False (after vtkErrorMacro) when a parameter is unusable.
  bool CheckParameters();
  /// RequestData's work; may throw.
  int Generate(vtkInformationVector* outputVector);

  int Dimensions[2];
  double CellSizeMetres;
  double SandDepthMetres;
  double SandDepthVariationMetres;
  double SaltationLengthMetres;
  double SaltationHeightGain;
  double SaltationDepthMetres;
  double CreepRate;
  double ShadowAngleDegrees;
  double ReposeAngleDegrees;
  int SpinUpSteps;
  int StepsPerTimeStep;
  int NumberOfTimeSteps;
  int RippleResolution;
  double RippleCellSizeMetres;
  int RippleSteps;
  double RippleSaltationLengthMetres;
  double RippleSaltationHeightGain;
  double RippleSaltationDepthMetres;
  double RippleCreepRate;
  int Seed;
  int NumberOfThreads;
  vtkIdType NumberOfStepsComputed;

private:
  vtkNimbusDunesSource(const vtkNimbusDunesSource&) = delete;
  void operator=(const vtkNimbusDunesSource&) = delete;

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
