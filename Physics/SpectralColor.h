// Spectrum -> CIE XYZ -> linear / encoded sRGB.
//
// Units: wavelength lambda in nanometres.  Spectra are any spectral quantity
// per nm (e.g. radiance in W m^-2 sr^-1 nm^-1); XYZ is normalised so that a flat
// spectrum S(lambda) = 1 over [380, 780] nm gives Y = 1, i.e.
//     X = integral S xbar dlambda / integral ybar dlambda   (likewise Y, Z).
// Colour-matching functions: CIE 1931 2-degree observer, multi-lobe
// piecewise-Gaussian fit of Wyman, Sloan & Shirley, "Simple Analytic
// Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013,
// Eq. 4.  The paper reports that the fit's error is smaller than the variance
// between the human-subject data aggregated into the CIE standard (see the
// paper for its numeric error figures); it is not the tabulated CIE data.
#ifndef nimbus_SpectralColor_h
#define nimbus_SpectralColor_h

#include "NimbusPhysicsExport.h" // for export macro

#include <array>
#include <cstddef>
#include <vector>

namespace nimbus
{

/// CIE 1931 2-degree colour-matching functions (Wyman-Sloan-Shirley multi-lobe
/// fit, JCGT 2013 Eq. 4); lambda in nm; dimensionless (ybar peak ~1 at 555 nm).
NIMBUSPHYSICS_EXPORT double CieXBar1931(double lambdaNm);
NIMBUSPHYSICS_EXPORT double CieYBar1931(double lambdaNm);
NIMBUSPHYSICS_EXPORT double CieZBar1931(double lambdaNm);
NIMBUSPHYSICS_EXPORT std::array<double, 3> CieXyzBar1931(double lambdaNm);

/// CIE XYZ -> linear sRGB (D65 white, ITU-R BT.709 primaries), matrix of
/// IEC 61966-2-1.  No clamping: out-of-gamut colours give components < 0 or > 1.
NIMBUSPHYSICS_EXPORT std::array<double, 3> XyzToLinearSrgb(const std::array<double, 3>& xyz);
/// sRGB transfer function (IEC 61966-2-1) linear -> encoded, input clamped to
/// [0, 1]: 12.92 c for c <= 0.0031308, else 1.055 c^(1/2.4) - 0.055.
NIMBUSPHYSICS_EXPORT double SrgbEncode(double linear);
/// Its inverse, encoded -> linear, input clamped to [0, 1]: c / 12.92 for
/// c <= 0.04045, else ((c + 0.055) / 1.055)^2.4.
NIMBUSPHYSICS_EXPORT double SrgbDecode(double encoded);
/// Chromaticity (x, y) = (X, Y) / (X + Y + Z); (0, 0) for X + Y + Z = 0.
NIMBUSPHYSICS_EXPORT std::array<double, 2> XyzToChromaticity(const std::array<double, 3>& xyz);

/// Planck's law: blackbody spectral radiance B(lambda, T) in W m^-2 sr^-1 nm^-1.
/// Use T = 5778 K for the sun.
NIMBUSPHYSICS_EXPORT double PlanckSpectralRadiance(double lambdaNm, double temperatureK);

/// How a spectrum known at the sample wavelengths is reconstructed between them
/// before it is integrated against the CMFs.
enum class SpectralReconstruction
{
  PiecewiseLinear,   // hat functions: weights >= 0, error O(h^2); use for N < 8
  NaturalCubicSpline // natural cubic spline: error O(h^4) for smooth spectra, but
                     // may ring (negative weights) at very small N (worse than
                     // linear at N <= 4, see README.md)
};

/// N wavelength samples lambda_i = lambdaMin + i h, h = (lambdaMax - lambdaMin)/(N - 1)
/// (end points included) with integration weights.  The spectrum is reconstructed
/// from its samples as S(l) = sum_i S_i phi_i(l) (phi_i: hat or cardinal-spline
/// basis functions, see SpectralReconstruction), so
///     X = sum_i S_i Wx_i,  Wx_i = integral phi_i xbar dlambda / integral ybar dlambda
/// (Wy, Wz likewise; integrals over [lambdaMin, lambdaMax] by fine composite
/// Simpson, normalised by the same ybar integral).  Both reconstructions
/// reproduce constants exactly, so a flat spectrum gives Y = sum_i Wy_i = 1 up to
/// rounding for every N.
/// Default N = 16 with the spline: measured against 1-nm sampling, the worst of
/// the sun (5778 K), Rayleigh-sky and sunset test spectra is Delta E*ab = 0.02
/// and max |delta linear sRGB| = 5.0e-5 (at Y = 1); N = 8 gives dE 0.76 and
/// piecewise linear gives dE 1.7 at N = 16 and still 0.1 at N = 64
/// (TestSpectralColor, README.md).
class NIMBUSPHYSICS_EXPORT SpectralSamples
{
public:
  static constexpr int kDefaultSampleCount = 16;

  /// Throws std::invalid_argument unless n >= 2 and 0 < lambdaMin < lambdaMax.
  explicit SpectralSamples(int n = kDefaultSampleCount,
    SpectralReconstruction reconstruction = SpectralReconstruction::NaturalCubicSpline,
    double lambdaMinNm = 380.0, double lambdaMaxNm = 780.0);

  SpectralReconstruction GetReconstruction() const { return this->Reconstruction; }
  std::size_t GetNumberOfSamples() const { return this->Wavelengths.size(); }
  /// lambda_i [nm].
  const std::vector<double>& GetWavelengths() const { return this->Wavelengths; }
  /// Integration weights per sample for X, Y, Z (dimensionless), see above.
  const std::vector<std::array<double, 3>>& GetWeights() const { return this->Weights; }

  /// Spectrum values at GetWavelengths() -> XYZ.  Throws std::invalid_argument on a
  /// size mismatch.
  std::array<double, 3> ToXyz(const std::vector<double>& spectrum) const;
  std::array<double, 3> ToLinearSrgb(const std::vector<double>& spectrum) const;

  /// Evaluates f(lambdaNm) at the sample wavelengths.
  template <class F>
  std::vector<double> Sample(F&& f) const
  {
    std::vector<double> s;
    s.reserve(this->Wavelengths.size());
    for (double lambda : this->Wavelengths)
    {
      s.push_back(f(lambda));
    }
    return s;
  }

private:
  SpectralReconstruction Reconstruction;
  std::vector<double> Wavelengths;
  std::vector<std::array<double, 3>> Weights;
};

} // namespace nimbus

#endif
