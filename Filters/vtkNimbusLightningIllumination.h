/**
 * @class   vtkNimbusLightningIllumination
 * @brief   A cloud lit from inside by lightning (003 §4-§7): precomputed basis, relit per time.
 *
 * Input port 0: the cloud, vtkImageData with a density array (the array to process,
 * SetInputArrayToProcess(0, ...); when it is not there, the active point scalars, else
 * the active cell scalars). Input port 1: the lightning,
 * vtkPolyData: the point sources of vtkNimbusLightningSource's port 1 (vertices with
 * point data "intensity") or its strokes (port 0: lines with cell data "intensity",
 * radiant intensity per metre, split here into sources PointSourceSpacing metres apart,
 * 003 Eq. 3).
 *
 * Output: the cloud (shallow copy) with the in-scattered radiance of the lightning, J(x,
 * w), in its field data, for vtkNimbusCloudVolumeMapper to draw:
 *   - "nimbus_lightning_in_scattering": float, 12 components per grid point (x fastest):
 *     the degree-1 SH coefficients c_00, c_1-1, c_10, c_11 of J for R, G, B, the layout
 *     of Physics/MultipleScattering.h, in units where the sun's irradiance is 1 per
 *     unit scattering coefficient (the same radiometry as the mapper's sun);
 *   - "nimbus_lightning_grid": int, 7 values: the grid's points per axis, its blocks of
 *     input samples per axis (point (i, j, k) is the mean of the block starting at input
 *     sample D i), and 1 when the density is cell data;
 *   - "nimbus_lightning_optics": double, 4 values: ExtinctionPerDensity, Albedo, CloudG,
 *     MetresPerUnit (the mapper warns when its own differ).
 *
 * How (Physics/LightningBasis.h): the density is averaged in blocks of Downsampling
 * samples (0: the smallest factor leaving at most 16 points along the longest side),
 * sigma_t = ExtinctionPerDensity x density. The virtual lights (003 §5 Eq. 4) fill the
 * cloud's box horizontally, LightSpacingMetres apart (0: a twelfth of the box's longest
 * horizontal side, 237 m for the default cumulus, where the relit picture is within
 * 0.97 % of the direct solve's brightest pixel, 333 times faster; docs/lightning.md),
 * from the cloud bottom (the lowest layer holding density) to its top, and below it
 * down to SimulationBottomMetres with Eq. 4's widening steps. One multiple-scattering
 * solve per three virtual lights (NumberOfDirections discrete directions, the first
 * scattering included) gives the basis, Haar-compressed at Threshold (xi, relative to
 * the basis's largest coefficient). That precompute runs once per cloud and
 * setting (progress reported, abortable) and is kept in memory and, when UseDiskCache,
 * on disk under CacheDirectory (default $NIMBUS_CACHE_DIR, else $XDG_CACHE_HOME/nimbus,
 * else ~/.cache/nimbus), named by a fingerprint of everything it depends on, so a new
 * session with the same cloud reads it instead. Every time step then only relights:
 * the sources to the virtual lights with trilinear weights (Eq. 6), weighted sums in the
 * wavelet domain and one inverse transform (Eqs. 8-10), milliseconds.
 *
 * Sources outside the virtual lights' box (a stroke beside the cloud, branches far out)
 * are moved onto the box, as Eq. 6 needs, and dimmed by (d_landed / d)^2, the distances
 * from the cloud's centre to where they land and where they are: their light reaches the
 * cloud from about the right distance rather than from the box's face.
 *
 * Time: the output has the lightning input's time steps; the cloud is taken as steady.
 *
 * Refusals (an error naming the problem; the cloud passes through without lightning):
 * no density array, negative, NaN or infinite density, a basis over MemoryBudgetMiB,
 * lightning sources that are not finite, bad settings. A cache file that cannot be read
 * is ignored (and replaced); one that cannot be written is reported as a warning.
 */
#ifndef vtkNimbusLightningIllumination_h
#define vtkNimbusLightningIllumination_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <array>  // for std::array
#include <memory> // for std::unique_ptr
#include <string> // for std::string
#include <vector> // for std::vector

class vtkDataArray;
class vtkFieldData;
class vtkImageData;
class vtkPolyData;
namespace nimbus
{
struct MultipleScatteringField;
struct FirstScatteringForwardPeak;
struct ExtinctionGrid;
struct PointLight;
struct VirtualLightGrid;
struct CloudOptics;
struct LightningBasisOptions;
}

class NIMBUSFILTERS_EXPORT vtkNimbusLightningIllumination : public vtkImageAlgorithm
{
public:
  static vtkNimbusLightningIllumination* New();
  vtkTypeMacro(vtkNimbusLightningIllumination, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// How the field is made. Basis (default): 003's precompute and relight (the sources
  /// spread to virtual lights: fast per time step, approximate near the sources).
  /// DirectSolve: the multiple-scattering solve with the actual point sources at every
  /// time step (no precompute; the reference the basis is measured against; about a
  /// second per step on the default grid).
  enum Methods
  {
    Basis = 0,
    DirectSolve = 1
  };
  vtkSetClampMacro(Method, int, 0, 1);
  vtkGetMacro(Method, int);
  void SetMethodToBasis() { this->SetMethod(Basis); }
  void SetMethodToDirectSolve() { this->SetMethod(DirectSolve); }

  /// The lightning (input port 1).
  void SetLightningConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }

  ///@{
  /// Cloud optics, as on vtkNimbusCloudVolumeMapper (same defaults: 0.02 /m per density
  /// unit, 0.99, 0.85) and metres per world unit (1).
  virtual void SetExtinctionPerDensity(double value);
  virtual double GetExtinctionPerDensityMinValue() { return 0.0; }
  virtual double GetExtinctionPerDensityMaxValue() { return 1e6; }
  vtkGetMacro(ExtinctionPerDensity, double);
  virtual void SetAlbedo(double value);
  virtual double GetAlbedoMinValue() { return 0.0; }
  virtual double GetAlbedoMaxValue() { return 1.0; }
  vtkGetMacro(Albedo, double);
  virtual void SetCloudG(double value);
  virtual double GetCloudGMinValue() { return -0.99; }
  virtual double GetCloudGMaxValue() { return 0.99; }
  vtkGetMacro(CloudG, double);
  virtual void SetMetresPerUnit(double value);
  virtual double GetMetresPerUnitMinValue() { return 1e-9; }
  virtual double GetMetresPerUnitMaxValue() { return 1e9; }
  vtkGetMacro(MetresPerUnit, double);
  ///@}

  ///@{
  /// The grid of the basis: blocks of input samples per axis (0: automatic, see above).
  vtkSetClampMacro(Downsampling, int, 0, 4096);
  vtkGetMacro(Downsampling, int);
  ///@}

  ///@{
  /// The virtual lights: h_usr of 003 Eq. 4 in metres (0: automatic) and the lowest
  /// height they reach (metres; the ground, 0, by default).
  virtual void SetLightSpacingMetres(double value);
  virtual double GetLightSpacingMetresMinValue() { return 0.0; }
  virtual double GetLightSpacingMetresMaxValue() { return 1e9; }
  vtkGetMacro(LightSpacingMetres, double);
  vtkSetMacro(SimulationBottomMetres, double);
  vtkGetMacro(SimulationBottomMetres, double);
  ///@}

  ///@{
  /// The solve and the compression: n_dir (26), scattering orders (16, then a geometric tail), xi
  /// (1e-3), threads (0: all cores; the result does not depend on it).
  vtkSetClampMacro(NumberOfDirections, int, 6, 1024);
  vtkGetMacro(NumberOfDirections, int);
  vtkSetClampMacro(Orders, int, 1, 1000);
  vtkGetMacro(Orders, int);
  virtual void SetThreshold(double value);
  virtual double GetThresholdMinValue() { return 0.0; }
  virtual double GetThresholdMaxValue() { return 1.0; }
  vtkGetMacro(Threshold, double);
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /// The most memory the precompute may take (MiB; default 2048; 0: no limit).
  virtual void SetMemoryBudgetMiB(double value);
  virtual double GetMemoryBudgetMiBMinValue() { return 0.0; }
  virtual double GetMemoryBudgetMiBMaxValue() { return 1e9; }
  vtkGetMacro(MemoryBudgetMiB, double);
  ///@}

  ///@{
  /// The disk cache (default on; directory "" = the default above).
  vtkSetMacro(UseDiskCache, bool);
  vtkGetMacro(UseDiskCache, bool);
  vtkBooleanMacro(UseDiskCache, bool);
  vtkSetStdStringFromCharMacro(CacheDirectory);
  vtkGetCharFromStdStringMacro(CacheDirectory);
  ///@}

  ///@{
  /// The colour of the lightning's light (multiplies the sources' intensities; default
  /// 0.85, 0.9, 1: the blue-white of a return stroke) and the spacing of the sources
  /// made from strokes (metres, 10).
  vtkSetVector3Macro(LightningColor, double);
  vtkGetVector3Macro(LightningColor, double);
  virtual void SetPointSourceSpacing(double value);
  virtual double GetPointSourceSpacingMinValue() { return 1e-3; }
  virtual double GetPointSourceSpacingMaxValue() { return 1e9; }
  vtkGetMacro(PointSourceSpacing, double);

  /// The sources' first scattering computed on the density's own grid (exact
  /// transmittance and the cell averages next to the channel; Physics/FirstScattering.h)
  /// and handed to the mapper as "nimbus_lightning_first_scattering"; the basis and the
  /// direct solve then hold the orders >= 2. Off: the first scattering on the illumination
  /// grid with the rest, as 003 does (it loses light next to the channel: docs/lightning.md).
  /// Default on.
  vtkSetMacro(FirstScatteringOnDensityGrid, bool);
  vtkGetMacro(FirstScatteringOnDensityGrid, bool);
  vtkBooleanMacro(FirstScatteringOnDensityGrid, bool);
  /// Blocks of density samples per first-scattering point (0, the default: 1, or the
  /// fewest that keep the grid under 64^3 points).
  vtkSetClampMacro(FirstScatteringDownsampling, int, 0, 4096);
  vtkGetMacro(FirstScatteringDownsampling, int);
  /// Seconds the last update spent on the first scattering (about 0 when its groups of
  /// sources were kept from an earlier time step), and the groups kept and computed; of
  /// the computed, those that extended a kept group (the leader's reached set: only its
  /// new sources computed).
  double GetLastFirstScatteringSeconds() const;
  int GetFirstScatteringGroupsKept() const;
  int GetFirstScatteringGroupsComputed() const;
  int GetFirstScatteringGroupsExtended() const;
  ///@}

  ///@{
  /// What the last update did: seconds of the precompute (0 when it came from memory or
  /// disk), whether it was read from the disk cache, the basis's virtual lights, grid
  /// and bytes (compressed, uncompressed), and the seconds of the last relight (or of
  /// the last direct solve).
  double GetLastPrecomputeSeconds() const;
  bool GetLastBasisFromDisk() const;
  int GetNumberOfVirtualLights() const;
  void GetGridDimensions(int dims[3]) const;
  double GetBasisBytes() const;
  double GetUncompressedBasisBytes() const;
  double GetLastRelightSeconds() const;
  /// Point sources of the last relight outside the virtual lights' box (moved onto it and
  /// dimmed, see the class comment).
  int GetNumberOfSourcesOutside() const;
  /// The file of the basis in the disk cache ("" before the first precompute).
  std::string GetCacheFile() const;
  ///@}

  /// The cache directory used when CacheDirectory is "".
  static std::string DefaultCacheDirectory();

protected:
  vtkNimbusLightningIllumination();
  ~vtkNimbusLightningIllumination() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Method = Basis;
  double ExtinctionPerDensity = 0.02;
  double Albedo = 0.99;
  double CloudG = 0.85;
  double MetresPerUnit = 1.0;
  int Downsampling = 0;
  double LightSpacingMetres = 0.0;
  double SimulationBottomMetres = 0.0;
  int NumberOfDirections = 26;
  int Orders = 16;
  double Threshold = 1e-3;
  int NumberOfThreads = 0;
  double MemoryBudgetMiB = 2048.0;
  bool UseDiskCache = true;
  std::string CacheDirectory;
  double LightningColor[3] = { 0.85, 0.9, 1.0 };
  double PointSourceSpacing = 10.0;
  bool FirstScatteringOnDensityGrid = true;
  int FirstScatteringDownsampling = 0;

private:
  vtkNimbusLightningIllumination(const vtkNimbusLightningIllumination&) = delete;
  void operator=(const vtkNimbusLightningIllumination&) = delete;

  void AddLightningArrays(
    vtkFieldData* fieldData, const nimbus::MultipleScatteringField& field, bool cellData);
  void AddFirstScattering(
    vtkFieldData* fieldData, vtkImageData* cloud, vtkDataArray* scalars, bool cellData);
  nimbus::FirstScatteringForwardPeak ForwardPeak() const;
  bool ReadLightningSources(
    vtkPolyData* lightning, const double colour[3], std::vector<nimbus::PointLight>& sources);
  bool BuildIlluminationGrids(vtkImageData* cloud, vtkDataArray* scalars, bool cellData,
    nimbus::ExtinctionGrid& grid, std::array<int, 3>& factors, nimbus::VirtualLightGrid& lights,
    double low[3], double high[3]);
  int SolveDirectly(vtkFieldData* fieldData, vtkImageData* cloud, vtkDataArray* scalars,
    bool cellData, const nimbus::ExtinctionGrid& grid, const nimbus::CloudOptics& optics,
    const std::vector<nimbus::PointLight>& sources, const std::array<int, 3>& factors);
  bool EnsureBasis(const nimbus::ExtinctionGrid& grid, const nimbus::CloudOptics& optics,
    const nimbus::VirtualLightGrid& lights, const nimbus::LightningBasisOptions& options,
    const std::string& fingerprint, const std::array<int, 3>& factors);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
