// The light hot smoke and fire emit (Planck's law): a blackbody source term in the
// radiative transfer equation, shared by the GPU Cloud representation and the reference
// path tracer so that both draw the same medium.
//
// Emission coefficient (radiance added per metre of path, Y/(sr m) in the renderers'
// relative units, the sun's illuminance being 1):
//     eta(x, lambda) = E rho(x) B(lambda, T(x)) / Y[B(., T_ref)]
// with B Planck's law (SpectralColor.h), Y[.] the luminance of a spectrum
// (SpectralSamples::ToXyz), rho the density (dimensionless), T the temperature [K] and E
// [Y/(sr m)] the luminance emitted per metre per unit density at the reference
// temperature T_ref. Hotter gas is brighter and bluer, cooler gas dimmer and redder:
// relative to T_ref = 1500 K, Y[B(1000 K)] is 3.5e-4 of it, Y[B(600 K)] 8.6e-11 (smoke
// at a few hundred kelvin does not glow), Y[B(2000 K)] 60x (TestBlackbodyEmission).
//
// This is not Kirchhoff's law (eta = sigma_a B): the emission is tied to the density, not
// to the absorption, so the glow of a flame can be set apart from how dark its smoke is,
// as artists' volume shaders do (e.g. Blender's Principled Volume: blackbody intensity
// and temperature).
#ifndef nimbus_BlackbodyEmission_h
#define nimbus_BlackbodyEmission_h

#include "NimbusPhysicsExport.h" // for export macro
#include "SpectralColor.h"

#include <array>
#include <vector>

namespace nimbus
{

class NIMBUSPHYSICS_EXPORT BlackbodyEmission
{
public:
  /// Throws std::invalid_argument unless 500 K <= referenceTemperatureKelvin <= 50000 K.
  BlackbodyEmission(const SpectralSamples& samples, double referenceTemperatureKelvin);

  double GetReferenceTemperatureKelvin() const { return this->ReferenceTemperature; }

  /// B(lambda_i, T) / Y[B(., T_ref)] at the samples' wavelengths (all 0 for T <= 0 or
  /// non-finite T).
  std::vector<double> RelativeSpectrum(double temperatureKelvin) const;
  /// Its luminance, Y[B(T)] / Y[B(T_ref)] (1 at T_ref).
  double RelativeLuminance(double temperatureKelvin) const;
  /// Its linear sRGB, from a table every kTableStepKelvin up to kTableMaxKelvin (linear
  /// in between; exact above): the largest relative error against the exact value is
  /// stated by TestBlackbodyEmission.
  std::array<double, 3> RelativeRgb(double temperatureKelvin) const;
  std::array<double, 3> ExactRelativeRgb(double temperatureKelvin) const;

  static constexpr double kTableStepKelvin = 1.0;
  static constexpr double kTableMaxKelvin = 20000.0;

private:
  SpectralSamples Samples;
  double ReferenceTemperature;
  double ReferenceLuminance; // Y[B(., T_ref)] in W m^-2 sr^-1 (of the samples' ToXyz)
  std::vector<std::array<double, 3>> RgbTable;
};

} // namespace nimbus

#endif
