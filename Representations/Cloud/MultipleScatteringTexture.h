// nimbus::MultipleScatteringTexture — the multiple-scattering term of
// vtkNimbusCloudVolumeMapper (003, 004): the solver's in-scattered radiance
// J(x, w) (Physics/MultipleScattering.h) on a grid downsampled from the density, as
// three RGBA float 3-D textures (the SH coefficients c_00, c_1-1, c_10, c_11 of R, of
// G, of B), re-solved only when what it depends on changes (the key).
//
// The grid: the density's input samples in blocks of D = downsampling x the density
// texture's own block factor per axis, each block's mean (DensityResample), so the
// grid's point i' sits at input-sample position D i' + (D - 1)/2; the texture is read
// with the density texture's coordinates times TextureScale.
#ifndef nimbus_MultipleScatteringTexture_h
#define nimbus_MultipleScatteringTexture_h

#include "DensityResample.h"
#include "MultipleScattering.h"
#include "NimbusRepresentationsModule.h"
#include "vtkNew.h" // for vtkNew

#include <array>
#include <functional>
#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
/// Uploads `components` floats per texel (x fastest) as a float 3-D texture, linear
/// filtering, clamped at the edges. False (the texture released) when GL refuses it or
/// runs out of memory.
NIMBUSREPRESENTATIONS_EXPORT bool UploadFloatTexture3D(vtkOpenGLRenderWindow* window,
  vtkTextureObject* texture, const std::array<int, 3>& dimensions, int components,
  const float* texels);

/// Uploads 12 floats per point (SH c_00, c_1-1, c_10, c_11 of R, G, B; x fastest) as
/// three RGBA float 3-D textures, linear filtering, clamped at the edges. False (the
/// textures released) when GL refuses them.
NIMBUSREPRESENTATIONS_EXPORT bool UploadShCoefficients(vtkOpenGLRenderWindow* window,
  vtkTextureObject* const textures[3], const std::array<int, 3>& dimensions,
  const float* coefficients);

class NIMBUSREPRESENTATIONS_EXPORT MultipleScatteringTexture
{
public:
  MultipleScatteringTexture();
  ~MultipleScatteringTexture();
  MultipleScatteringTexture(const MultipleScatteringTexture&) = delete;
  MultipleScatteringTexture& operator=(const MultipleScatteringTexture&) = delete;

  /// What one solve needs besides the density.
  struct Request
  {
    MultipleScatteringOptions Options;
    CloudOptics Optics;
    double ExtinctionPerDensity = 0.02;               // k_cl [1/m per density unit]
    int Downsampling = 4;                             // >= 1, relative to the density texture
    std::array<int, 3> TextureFactors{ { 1, 1, 1 } }; // the density texture's blocks
    std::array<int, 3> TextureDimensions{ { 1, 1, 1 } };
    double MetresPerUnit = 1.0;
    double BudgetBytes = 0.0;
    CloudLighting Lighting;
    /// The medium's glow (Physics/BlackbodyEmission.h), a source of the solve
    /// (CloudLighting::Emission, DiscreteDirections only): the temperatures [K] of the
    /// density's samples (one component, as many tuples as the density; null: no glow),
    /// E [radiance per metre per unit density at T_ref] and T_ref [K]. On the solver's
    /// grid eta = E times the block's mean of rho B(T) / Y[B(T_ref)] (linear sRGB),
    /// the blocks of the extinction's (ComputeEmissionTexels): the same emission as the
    /// mapper's EmissionTexture, which the shader adds as E times its texel.
    vtkDataArray* EmissionTemperature = nullptr;
    double EmissionRadiancePerMetre = 0.0;
    double EmissionReferenceKelvin = 1500.0;
    /// The glow's first scattering on a finer grid, downsampled this much from the
    /// density texture (1 ... Downsampling - 1; 0 or >= Downsampling: on the solve's
    /// grid): next to a hot core a few density cells across, the coarse grid's first
    /// scattering loses light (docs/smoke.md). Then the solve leaves it out
    /// (EmissionFirstScatteringApart), EmissionFirstScattering computes it on the finer
    /// grid, and the texture is uploaded at that grid's resolution: the solve's J
    /// interpolated trilinearly onto it plus the first scattering.
    int EmissionFirstScatteringDownsampling = 0;
    /// Everything the answer depends on but the density values (compared with the
    /// last solve's); the density's identity is `densityVersion`.
    std::vector<double> Key;
  };

  /// The blocks of the grid: input samples (cells for cell data), block factors,
  /// grid points per axis.
  static DensityResamplePlan PlanGrid(vtkImageData* image, bool cellData, const Request& request);

  /// The grid the solver will work on: the image's scalars (cell data when
  /// `cellData`) in blocks (see the file comment), placed in world metres through
  /// `dataToWorld`. False, with the reason in `error`, when the grid is sheared.
  static bool BuildGrid(vtkImageData* image, vtkDataArray* scalars, bool cellData,
    vtkMatrix4x4* dataToWorld, const Request& request, ExtinctionGrid& grid,
    std::array<int, 3>& factors, std::string& error);

  /// Solves and uploads when `request.Key` or `densityVersion` changed since the last
  /// solve. `progress(fraction)` during the solve. False, with the reason in
  /// `error`, when the grid is over the budget, the input is refused, the solve threw
  /// or the upload failed (the term is then off).
  bool Update(vtkOpenGLRenderWindow* window, vtkImageData* image, vtkDataArray* scalars,
    bool cellData, vtkMatrix4x4* dataToWorld, double densityVersion, const Request& request,
    const std::function<void(double)>& progress, std::string& error);

  /// Whether the textures hold a term (false for Octaves without sky light).
  bool HasTexture() const { return this->Textured; }
  vtkTextureObject* GetTexture(int channel) const;
  /// Density texture coordinates -> this texture's.
  const std::array<double, 3>& GetTextureScale() const { return this->TextureScale; }
  /// The last solve's delta-M forward fraction (MultipleScatteringField).
  double GetForwardPeakFraction() const { return this->Field.ForwardPeakFraction; }
  const MultipleScatteringField& GetField() const { return this->Field; }
  const std::array<int, 3>& GetGridDimensions() const { return this->Field.Dimensions; }
  int GetNumberOfSolves() const { return this->Solves; }
  /// Seconds of the last solve (grid building, solver, upload).
  double GetLastSolveSeconds() const { return this->LastSeconds; }
  /// Bytes the last solve estimated it needed (EstimateMultipleScatteringBytes).
  double GetLastEstimatedBytes() const { return this->LastEstimatedBytes; }

  /// Frees the textures; the next Update solves again.
  void Release(vtkWindow* window);

private:
  static bool BuildEmission(vtkDataArray* scalars, const DensityResamplePlan& plan,
    const Request& request, std::vector<float>& emission, std::string& error);
  static bool FinerFirstScattering(const Request& request);
  bool AddFinerFirstScattering(vtkImageData* image, vtkDataArray* scalars, bool cellData,
    vtkMatrix4x4* dataToWorld, const Request& request, const std::array<int, 3>& coarseFactors,
    ExtinctionGrid& grid, std::array<int, 3>& factors, std::string& error);
  bool Solve(vtkOpenGLRenderWindow* window, vtkImageData* image, vtkDataArray* scalars,
    bool cellData, vtkMatrix4x4* dataToWorld, const Request& request,
    const std::vector<double>& key, const std::function<void(double)>& progress,
    std::string& error);

  vtkNew<vtkTextureObject> Textures[3];
  std::vector<double> SolvedKey;
  std::vector<double> FailedKey; // the key of a solve that failed, and why
  std::string FailedError;
  MultipleScatteringField Field;
  std::array<double, 3> TextureScale{ { 1, 1, 1 } };
  bool Textured = false;
  bool Valid = false;
  int Solves = 0;
  double LastSeconds = 0.0;
  double LastEstimatedBytes = 0.0;
};
} // namespace nimbus

#endif
