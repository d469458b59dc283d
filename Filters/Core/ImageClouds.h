// Clouds from a 2-D image (002 §3, "an image-based approach for modeling clouds viewed from
// space"; shared/papers/README.md): pixel intensity gives the cloud's optical depth, and
// metaballs (004 §4's degree-6 field, Metaballs.h) are placed and weighted so that the
// column optical depth of the resulting density matches it, over a flat base with a bumpy top.
//
// Plain C++ (no VTK); vtkNimbusImageCloudFilter is the pipeline glue.
//
// Units: lengths in metres; optical depth dimensionless; the extinction coefficient sigma
// in 1/m per unit density, so a column's optical depth is tau = sigma * integral(density dz).
#ifndef NimbusImageClouds_h
#define NimbusImageClouds_h

#include "Metaballs.h"
#include "NimbusFiltersModule.h"

#include <cstdint>
#include <vector>

namespace nimbus
{

/// Intensity -> optical depth. The intensity u is first normalised so that
/// ClearIntensity -> 0 and WhiteIntensity -> 1 (clamped to [0, 1]); then
///   Linear:    tau = MaximumOpticalDepth * u^Gamma
///   TwoStream: tau = min(MaximumOpticalDepth, 2 u / ((1 - g)(1 - u)))
/// TwoStream inverts the reflectance of a non-absorbing plane-parallel cloud in the
/// two-stream approximation, R = (1 - g) tau / (2 + (1 - g) tau) (the two-stream result, e.g.
/// Bohren 1987, Am. J. Phys. 55, "Multiple scattering of light and some of its observable
/// consequences"), reading the normalised intensity as the cloud's reflectance: bright pixels
/// become optically much thicker than a linear map would make them, as in satellite retrievals.
struct OpticalDepthMapping
{
  enum class Kind
  {
    Linear,
    TwoStream
  };
  Kind Type = Kind::Linear;
  double ClearIntensity = 0.1; // normalised intensity of clear sky (ground, sea)
  double WhiteIntensity = 1.0; // normalised intensity of the thickest cloud
  double Gamma = 1.0;          // Linear: exponent
  double MaximumOpticalDepth = 30.0;
  double AsymmetryParameter = 0.85; // TwoStream: g of the cloud's phase function
};

/// The mapping above for one normalised intensity in [0, 1] (values outside are clamped).
NIMBUSFILTERS_EXPORT double IntensityToOpticalDepth(
  double intensity, const OpticalDepthMapping& mapping);

struct ImageCloudParameters
{
  double PixelSize = 100.0;              // m, horizontal size of a pixel (= grid spacing)
  double VerticalSpacing = 50.0;         // m, grid spacing along z
  double ExtinctionCoefficient = 0.02;   // sigma, 1/m per unit density
  double NominalDensity = 1.0;           // the cloud body's density: thickness = tau / (sigma rho)
  double BaseHeight = 1000.0;            // m, flat cloud base
  double BaseTransitionThickness = 50.0; // m, density fades in over this above the base
  int BallSpacing = 2;                   // pixels between columns of metaballs (>= 1)
  double BallRadiusFactor = 3.0;         // ball radius = factor * BallSpacing * PixelSize
  double TopRoughness = 0.6;             // random variation of the top balls (fraction of R)
  double MinimumOpticalDepth = 0.05;     // columns thinner than this get no balls
  int Iterations = 10;                   // density-fitting iterations
  /// The grid is made tall enough for this optical depth (0: the map's maximum), so that a
  /// pipeline can know the grid before it sees the image.
  double GridOpticalDepth = 0.0;
  std::uint64_t Seed = 1;
};

struct ImageCloud
{
  bool Complete = true; // false: stopped by the progress callback

  GridGeometry Grid;                      // x, y: one point per pixel, z from below the base up
  std::vector<float> Density;             // dimensionless, x fastest
  std::vector<Metaball> Balls;            // the fitted metaballs
  std::vector<double> ColumnOpticalDepth; // achieved tau per pixel, sigma * sum(density) dz
};

/// The grid BuildImageCloud uses for an nx x ny map whose largest optical depth is
/// maximumOpticalDepth. Throws std::invalid_argument, with a message naming the parameter
/// or the real cause, for unusable parameters (NaN, infinite, out of range: PixelSize and
/// VerticalSpacing in [1e-3, 1e6] m, |BaseHeight| and BaseTransitionThickness at most
/// 1e8 m, ExtinctionCoefficient in (0, 1e3] 1/m, NominalDensity in (0, 1e6]), for a
/// grid of more than 4096 layers (a cloud too thick for the vertical spacing) and for a
/// grid of more than 2e9 points (an image too large).
NIMBUSFILTERS_EXPORT GridGeometry ImageCloudGrid(
  int nx, int ny, double maximumOpticalDepth, const ImageCloudParameters& parameters);

/// Builds the cloud over an nx x ny map of target optical depths (tau[x + nx y] >= 0).
/// Grid x/y points sit on the pixels, centred on x = y = 0. Ball columns sit every
/// BallSpacing pixels where tau > MinimumOpticalDepth: stacked from the base up to the
/// thickness tau / (sigma rho), each ball jittered sideways, the top ball's height and radius
/// varied by TopRoughness (the bumpy top); the flat base is ApplyCloudBase. Then the balls of
/// each column are rescaled Iterations times by target / achieved column optical depth at
/// the column (multiplicative fixed point, like Richardson-Lucy), so the rendered thickness
/// matches the image; no ball's density grows beyond 1e6 NominalDensity. Throws
/// std::invalid_argument for unusable parameters. `progress` (optional) is called after
/// each sampling of the field and within it; when it returns false the build stops and
/// the result has Complete = false.
NIMBUSFILTERS_EXPORT ImageCloud BuildImageCloud(const std::vector<double>& opticalDepth, int nx,
  int ny, const ImageCloudParameters& parameters, const ProgressCallback& progress = nullptr);

/// Upper bound of the number of metaballs BuildImageCloud places on an nx x ny map whose
/// largest optical depth is maximumOpticalDepth (for memory and work estimates).
NIMBUSFILTERS_EXPORT double MaximumImageCloudBalls(
  int nx, int ny, double maximumOpticalDepth, const ImageCloudParameters& parameters);

/// sigma * sum_k density(x, y, z_k) * dz for every column (x, y) of the grid.
NIMBUSFILTERS_EXPORT std::vector<double> ColumnOpticalDepth(
  const GridGeometry& grid, const std::vector<float>& density, double extinctionCoefficient);

} // namespace nimbus

#endif
