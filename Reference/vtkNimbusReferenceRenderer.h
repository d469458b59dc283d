/**
 * @class   vtkNimbusReferenceRenderer
 * @brief   Ground-truth renderer of a Nimbus scene: float linear-sRGB image.
 *
 * Thin VTK glue around the plain-C++ reference renderers in Reference/:
 * - SingleScattering (deterministic): integrates 000 Eq. 1 per pixel (cloud +
 *   atmosphere + ground + background), halving the step until the estimated
 *   relative error is below RelativeTolerance.
 * - PathTracing (Monte Carlo, full multiple scattering): progressive, per-pixel
 *   standard error, stops at TargetRelativeError or MaxSamplesPerPixel;
 *   deterministic for a Seed.
 *
 * The scene comes from SceneFileName (JSON, docs/scene-format.md). Its density
 * is the scene's own (a .vti file or the metaball source) unless a vtkImageData
 * is connected to input port 0 (optional), whose array DensityArrayName (point
 * data, any numeric type) is used instead, placed by its origin and spacing.
 * NaN, infinite or negative densities are an error naming the array and how
 * many there are; so is a direction matrix other than the identity (the grid is
 * placed by origin and spacing only). The image, the density's float copy and
 * the renderers' buffers are checked against MemoryBudgetMiB before they are
 * allocated; a render with a NaN or infinite pixel is an error (no output). No
 * exception leaves the algorithm: errors are reported with vtkErrorMacro and the
 * output is empty. Progress is reported during the render, and AbortExecute
 * stops it within one chunk of pixels (the output is then empty).
 *
 * Output: vtkImageData of Width x Height points with the 3-component float
 * point array "radiance" (linear sRGB, relative units: the sun's illuminance is
 * the scene's sun.illuminance) and, for path tracing, "standard_error"; field
 * data "EstimatedRelativeError", "RenderSeconds", "SamplesPerPixel" (and, for path
 * tracing, "StoppedAtTimeLimit", "ReachedImageTarget").
 */
#ifndef vtkNimbusReferenceRenderer_h
#define vtkNimbusReferenceRenderer_h

#include "NimbusReferenceModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <memory> // for std::unique_ptr
#include <string> // for std::string

class vtkImageData;

class NIMBUSREFERENCE_EXPORT vtkNimbusReferenceRenderer : public vtkImageAlgorithm
{
public:
  static vtkNimbusReferenceRenderer* New();
  vtkTypeMacro(vtkNimbusReferenceRenderer, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Modes
  {
    SINGLE_SCATTERING = 0,
    PATH_TRACING = 1
  };

  ///@{
  /// The scene file (JSON). Required.
  vtkSetStdStringFromCharMacro(SceneFileName);
  vtkGetCharFromStdStringMacro(SceneFileName);
  ///@}

  /// The scene file read and validated, as canonical JSON of the current format
  /// version (every field, defaults filled in, a relative density path made
  /// absolute; docs/scene-format.md): what scripts should read instead of the file,
  /// so that they see one version whatever version the file has. Empty, with an
  /// error, when the file cannot be read or is not a valid scene.
  std::string GetCanonicalSceneJson();

  ///@{
  /// Point-data array of the optional input image used as density. Default "density".
  vtkSetStdStringFromCharMacro(DensityArrayName);
  vtkGetCharFromStdStringMacro(DensityArrayName);
  ///@}

  ///@{
  /// SINGLE_SCATTERING (default) or PATH_TRACING.
  vtkSetClampMacro(Mode, int, SINGLE_SCATTERING, PATH_TRACING);
  vtkGetMacro(Mode, int);
  void SetModeToSingleScattering() { this->SetMode(SINGLE_SCATTERING); }
  void SetModeToPathTracing() { this->SetMode(PATH_TRACING); }
  ///@}

  ///@{
  /// Single scattering: initial step as a fraction of the grid's smallest
  /// spacing, the relative error to converge to, and the most step halvings.
  /// Defaults 0.5, 1e-3, 6.
  vtkSetMacro(StepScale, double);
  vtkGetMacro(StepScale, double);
  vtkSetMacro(RelativeTolerance, double);
  vtkGetMacro(RelativeTolerance, double);
  vtkSetMacro(MaxRefinements, int);
  vtkGetMacro(MaxRefinements, int);
  ///@}

  ///@{
  /// Path tracing: samples per pixel (min, max), the per-pixel relative standard
  /// error to stop at (0: run to the max), the highest scattering order (0:
  /// unlimited, 1: single scattering) and the seed. Defaults 16, 256, 0, 0, 1.
  vtkSetMacro(MinSamplesPerPixel, int);
  vtkGetMacro(MinSamplesPerPixel, int);
  vtkSetMacro(MaxSamplesPerPixel, int);
  vtkGetMacro(MaxSamplesPerPixel, int);
  vtkSetMacro(TargetRelativeError, double);
  vtkGetMacro(TargetRelativeError, double);
  vtkSetMacro(MaxScatteringOrder, int);
  vtkGetMacro(MaxScatteringOrder, int);
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Path tracing by light tracing (nimbus::PathTracingSettings::LightTracing): paths from
  /// the lights connected to the camera at every scattering vertex, in batches whose spread
  /// gives the standard error; Min/MaxSamplesPerPixel then count light paths per pixel
  /// (LightPathsPerBatch a batch, 0: max(1024, pixels)). For scenes lit only by point, spot
  /// and polyline lights in the cloud's media (no sun, background radiance, atmosphere,
  /// ground, occluders or emission; others are an error that says so). Default off.
  vtkSetMacro(LightTracing, bool);
  vtkGetMacro(LightTracing, bool);
  vtkBooleanMacro(LightTracing, bool);
  vtkSetClampMacro(LightPathsPerBatch, int, 0, 1 << 30);
  vtkGetMacro(LightPathsPerBatch, int);
  ///@}

  ///@{
  /// Path tracing: stop after the first round of samples that ends past
  /// TimeLimitSeconds (s), or whose image-wide relative error (RMS standard error
  /// over RMS radiance) is at or below TargetImageRelativeError; 0 = no such stop.
  /// Field data "StoppedAtTimeLimit" and "ReachedImageTarget" say which ended it.
  /// Defaults 0, 0.
  virtual void SetTimeLimitSeconds(double value);
  virtual double GetTimeLimitSecondsMinValue() { return 0.0; }
  virtual double GetTimeLimitSecondsMaxValue() { return 1.0e9; }
  vtkGetMacro(TimeLimitSeconds, double);
  virtual void SetTargetImageRelativeError(double value);
  virtual double GetTargetImageRelativeErrorMinValue() { return 0.0; }
  virtual double GetTargetImageRelativeErrorMaxValue() { return 1.0; }
  vtkGetMacro(TargetImageRelativeError, double);
  ///@}

  ///@{
  /// Path tracing, during a render (for a progress display from a ProgressEvent
  /// observer): the image-wide relative error and the mean samples per pixel after
  /// the last finished round; 0 before the first.
  vtkGetMacro(CurrentImageRelativeError, double);
  vtkGetMacro(CurrentSamplesPerPixel, double);
  ///@}

  /// Path tracing with a TargetImageRelativeError: before the render a pilot
  /// (nimbus::EstimatePathTracingTime: 1/16 of the pixels at 32 samples) forecasts the
  /// time to the target (s; also field data "EstimatedSecondsToTarget"), and a warning
  /// says so when that is over TimeLimitSeconds (or over an hour without a limit).
  /// 0 before a render or without a target.
  vtkGetMacro(EstimatedSecondsToTarget, double);

  ///@{
  /// Worker threads (0: all cores). Default 0.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /// Memory the render may allocate, MiB (image, density copy, renderer buffers;
  /// also passed to the scene's density source). Default
  /// nimbus::DefaultMemoryBudgetMiB() (Physics/MemoryBudget.h); <= 0: that default.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  ///@}

protected:
  vtkNimbusReferenceRenderer();
  ~vtkNimbusReferenceRenderer() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  std::string SceneFileName;
  std::string DensityArrayName = "density";
  int Mode = SINGLE_SCATTERING;
  double StepScale = 0.5;
  double RelativeTolerance = 1e-3;
  int MaxRefinements = 6;
  int MinSamplesPerPixel = 16;
  int MaxSamplesPerPixel = 256;
  double TargetRelativeError = 0.0;
  int MaxScatteringOrder = 0;
  int Seed = 1;
  double TimeLimitSeconds = 0.0;
  bool LightTracing = false;
  int LightPathsPerBatch = 0;
  double TargetImageRelativeError = 0.0;
  double EstimatedSecondsToTarget = 0.0;
  double CurrentImageRelativeError = 0.0;
  double CurrentSamplesPerPixel = 0.0;
  int NumberOfThreads = 0;
  double MemoryBudgetMiB;

private:
  // RequestData's work; throws on failure (RequestData reports it).
  int Render(vtkInformationVector** inputVector, vtkImageData* output);

  // The scene parsed by RequestInformation, rendered by RequestData.
  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;

  vtkNimbusReferenceRenderer(const vtkNimbusReferenceRenderer&) = delete;
  void operator=(const vtkNimbusReferenceRenderer&) = delete;
};

#endif
