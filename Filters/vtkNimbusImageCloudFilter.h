/**
 * @class   vtkNimbusImageCloudFilter
 * @brief   3-D cloud density from a 2-D image, e.g. a satellite picture (002 §3).
 *
 * Input: a 2-D vtkImageData (one slice, nx x ny x 1), its active point scalars (or the
 * array chosen with SetInputArrayToProcess; without one, the first point array, else the
 * active or first cell array) read as intensity. A cell array of (nx - 1) x (ny - 1) values
 * (pixels as cells, as ParaView's default image reader, GDAL's, gives PNG, JPEG and TIFF
 * files) is averaged onto the points (each point the mean of the cells around it, as Cell
 * Data to Point Data does); the output then has nx x ny columns. RGB(A) images use the
 * luminance 0.2126 R + 0.7152 G + 0.0722 B. Intensities are normalised with IntensityRange
 * (default 0..255, for 8-bit images), then mapped to optical depth tau
 * (Filters/Core/ImageClouds.h, OpticalDepthMapping):
 *   u = clamp((I - ClearIntensity) / (WhiteIntensity - ClearIntensity), 0, 1)
 *   Linear (MappingType 0):    tau = MaximumOpticalDepth * u^Gamma
 *   TwoStream (MappingType 1): tau = min(MaximumOpticalDepth, 2 u / ((1 - g)(1 - u))),
 *     the inverse of a non-absorbing cloud's two-stream reflectance.
 * Columns of metaballs (Wyvill's degree-6 field, 004 §4) stand on a flat base at BaseHeight,
 * as tall as tau / (ExtinctionCoefficient * NominalDensity), with rough top balls; their
 * densities are fitted so that each column's optical depth
 * ExtinctionCoefficient * sum(density dz) matches tau (measured: within 5 % inside uniform
 * regions, see Testing/Cxx/TestImageClouds.cxx).
 *
 * Output port 0: vtkImageData, one point per pixel in x and y (PixelSize metres apart,
 * centred on x = y = 0), VerticalSpacing metres in z, float point array "density"
 * (dimensionless; a renderer's extinction is ExtinctionCoefficient * density, 1/m).
 * Output port 1: the 2-D map at z = BaseHeight with "optical_depth" (the image's target
 * tau) and "column_optical_depth" (the achieved tau of the density).
 *
 * Pieces (data parallel): both outputs are the requested extents (a piece with its ghost
 * layers under MPI), bit-identical to the same points of the serial outputs. The fit couples
 * neighbouring columns and normalises by the whole map, so every piece reads the whole input
 * image and builds the whole cloud, then crops: exact, but work and memory are not divided.
 *
 * NaN or infinite Gamma, MaximumOpticalDepth, AsymmetryParameter, BallRadiusFactor or
 * TopRoughness are refused by their setters at once (an error naming the property and the
 * value; the previous value is kept); finite values are clamped to their ranges. Other bad
 * input ends in an error message and empty outputs, never in an exception or an
 * allocation VTK cannot make: NaN or infinite parameters, values outside the documented
 * ranges (PixelSize and VerticalSpacing in [1e-3, 1e6] m, ExtinctionCoefficient in
 * (0, 1e3] 1/m, NominalDensity in (0, 1e6], |BaseHeight| and BaseTransitionThickness at
 * most 1e8 m), a cloud thicker than 4096 layers, an image whose grid would exceed 2e9
 * points or MemoryBudgetMiB, or work beyond about 2e11 grid-point updates (the messages
 * say which). NaN, infinite and (with IntensityRange[0] >= 0) negative intensities are
 * counted in a warning: NaN reads as clear sky, the others are clamped to the range's ends.
 * The build reports progress and stops soon after AbortExecute is set (outputs then empty).
 */
#ifndef vtkNimbusImageCloudFilter_h
#define vtkNimbusImageCloudFilter_h

#include "NimbusFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <vector> // for std::vector

class vtkImageData;
namespace nimbus
{
struct ImageCloud;
struct ImageCloudParameters;
}

class NIMBUSFILTERS_EXPORT vtkNimbusImageCloudFilter : public vtkImageAlgorithm
{
public:
  static vtkNimbusImageCloudFilter* New();
  vtkTypeMacro(vtkNimbusImageCloudFilter, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum MappingTypes
  {
    LINEAR = 0,
    TWO_STREAM = 1
  };

  ///@{
  /// Raw intensities mapped to 0 and 1 before the mapping. Default (0, 255).
  vtkSetVector2Macro(IntensityRange, double);
  vtkGetVector2Macro(IntensityRange, double);
  ///@}

  ///@{
  /// Intensity -> optical depth mapping (see the class description). Defaults: TwoStream,
  /// ClearIntensity 0.25 (dark sea and land stay clear), WhiteIntensity 1, Gamma 1,
  /// MaximumOpticalDepth 30, AsymmetryParameter 0.85.
  vtkSetClampMacro(MappingType, int, LINEAR, TWO_STREAM);
  vtkGetMacro(MappingType, int);
  void SetMappingTypeToLinear() { this->SetMappingType(LINEAR); }
  void SetMappingTypeToTwoStream() { this->SetMappingType(TWO_STREAM); }
  vtkSetMacro(ClearIntensity, double);
  vtkGetMacro(ClearIntensity, double);
  vtkSetMacro(WhiteIntensity, double);
  vtkGetMacro(WhiteIntensity, double);
  /// Clamped to [0.01, 100.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetGamma(double value);
  double GetGammaMinValue() { return 0.01; }
  double GetGammaMaxValue() { return 100.0; }
  vtkGetMacro(Gamma, double);
  /// Clamped to [0.0, 1000.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetMaximumOpticalDepth(double value);
  double GetMaximumOpticalDepthMinValue() { return 0.0; }
  double GetMaximumOpticalDepthMaxValue() { return 1000.0; }
  vtkGetMacro(MaximumOpticalDepth, double);
  /// Clamped to [0.0, 0.99]; NaN and infinities refused at once (error, value kept).
  virtual void SetAsymmetryParameter(double value);
  double GetAsymmetryParameterMinValue() { return 0.0; }
  double GetAsymmetryParameterMaxValue() { return 0.99; }
  vtkGetMacro(AsymmetryParameter, double);
  ///@}

  ///@{
  /// Grid: metres per pixel (x, y) and between layers (z). Defaults 100 and 50.
  vtkSetMacro(PixelSize, double);
  vtkGetMacro(PixelSize, double);
  vtkSetMacro(VerticalSpacing, double);
  vtkGetMacro(VerticalSpacing, double);
  ///@}

  ///@{
  /// Extinction coefficient per unit density (1/m) and the density of the cloud body:
  /// a column of optical depth tau is about tau / (ExtinctionCoefficient * NominalDensity)
  /// metres thick. Defaults 0.02 and 1.
  vtkSetMacro(ExtinctionCoefficient, double);
  vtkGetMacro(ExtinctionCoefficient, double);
  vtkSetMacro(NominalDensity, double);
  vtkGetMacro(NominalDensity, double);
  ///@}

  ///@{
  /// Flat base: height (m) and the thickness (m) the density fades in over. Defaults 1000, 50.
  vtkSetMacro(BaseHeight, double);
  vtkGetMacro(BaseHeight, double);
  vtkSetMacro(BaseTransitionThickness, double);
  vtkGetMacro(BaseTransitionThickness, double);
  ///@}

  ///@{
  /// Metaballs: one column every BallSpacing pixels, radius BallRadiusFactor * BallSpacing
  /// * PixelSize, top balls varied by TopRoughness (0..1), Iterations of density fitting,
  /// Seed of the jitter. Defaults 2, 3, 0.6, 10, 1.
  vtkSetClampMacro(BallSpacing, int, 1, 64);
  vtkGetMacro(BallSpacing, int);
  /// Clamped to [0.1, 20.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetBallRadiusFactor(double value);
  double GetBallRadiusFactorMinValue() { return 0.1; }
  double GetBallRadiusFactorMaxValue() { return 20.0; }
  vtkGetMacro(BallRadiusFactor, double);
  /// Clamped to [0.0, 1.0]; NaN and infinities refused at once (error, value kept).
  virtual void SetTopRoughness(double value);
  double GetTopRoughnessMinValue() { return 0.0; }
  double GetTopRoughnessMaxValue() { return 1.0; }
  vtkGetMacro(TopRoughness, double);
  vtkSetClampMacro(Iterations, int, 0, 100);
  vtkGetMacro(Iterations, int);
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Memory the filter may use for one update, MiB (> 0, finite). Images whose cloud would
  /// need more are refused with a message. Default nimbus::DefaultMemoryBudgetMiB(): half
  /// the physical memory, at most three quarters of the process's address-space limit.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  /// (1, nimbus::DefaultMemoryBudgetMiB()) MiB: ParaView's range for MemoryBudgetMiB, whose
  /// default there is the upper end (the machine's default, not a number in the XML).
  vtkGetVector2Macro(MemoryBudgetRangeMiB, double);
  ///@}

  /// Port 1's data: target and achieved optical depth maps.
  vtkImageData* GetOpticalDepthMap();

protected:
  vtkNimbusImageCloudFilter();
  ~vtkNimbusImageCloudFilter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /// RequestData's work; may throw (RequestData catches).
  int Generate(vtkInformationVector** inputVector, vtkInformationVector* outputVector);

  double IntensityRange[2];
  int MappingType;
  double ClearIntensity;
  double WhiteIntensity;
  double Gamma;
  double MaximumOpticalDepth;
  double AsymmetryParameter;
  double PixelSize;
  double VerticalSpacing;
  double ExtinctionCoefficient;
  double NominalDensity;
  double BaseHeight;
  double BaseTransitionThickness;
  int BallSpacing;
  double BallRadiusFactor;
  double TopRoughness;
  int Iterations;
  int Seed;
  double MemoryBudgetMiB;
  double MemoryBudgetRangeMiB[2];

private:
  vtkNimbusImageCloudFilter(const vtkNimbusImageCloudFilter&) = delete;
  void operator=(const vtkNimbusImageCloudFilter&) = delete;

  // Generate's steps; false: an error was reported (or, for ComputeOpticalDepths, aborted).
  struct IntensityInput;
  bool FindIntensityArray(vtkInformationVector** inputVector, vtkImageData* input,
    const int dims[3], IntensityInput& found);
  bool CheckMappingParameters();
  bool CheckCloudSize(const int dims[3], const nimbus::ImageCloudParameters& parameters);
  bool ComputeOpticalDepths(
    const IntensityInput& input, const int dims[3], std::vector<double>& tau);
  void FillOutputs(const nimbus::ImageCloud& cloud, const std::vector<double>& tau,
    vtkImageData* output, vtkImageData* map);
};

#endif
