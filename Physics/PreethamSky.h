// Preetham, Shirley & Smits 1999 ("A Practical Analytic Model for Daylight",
// SIGGRAPH 99), Appendix A.2: the analytic clear sky, implemented from the paper as
// an independent model to validate the spectral sky of Sky.h against (TestSky).
//
// The sky's luminance Y and CIE chromaticity (x, y) in a view direction at zenith
// angle theta and angle gamma from the sun, for turbidity T and sun zenith angle
// theta_s (all angles in radians):
//
//   F(theta, gamma) = (1 + A exp(B / cos theta)) (1 + C exp(D gamma) + E cos^2 gamma)
//                                                            (Perez et al. 1993)
//   Y = Y_z F_Y(theta, gamma) / F_Y(0, theta_s),  likewise x and y with F_x, F_y,
//
// with the Perez coefficients linear in T (Appendix A.2, "distribution coefficients"):
//   Y: A = 0.1787 T - 1.4630, B = -0.3554 T + 0.4275, C = -0.0227 T + 5.3251,
//      D = 0.1206 T - 2.5771, E = -0.0670 T + 0.3703
//   x: A = -0.0193 T - 0.2592, B = -0.0665 T + 0.0008, C = -0.0004 T + 0.2125,
//      D = -0.0641 T - 0.8989, E = -0.0033 T + 0.0452
//   y: A = -0.0167 T - 0.2608, B = -0.0950 T + 0.0092, C = -0.0079 T + 0.2102,
//      D = -0.0441 T - 1.6537, E = -0.0109 T + 0.0529
// the zenith luminance (kcd/m^2)
//   chi = (4/9 - T/120)(pi - 2 theta_s),
//   Y_z = (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192
// and the zenith chromaticity
//   x_z = [T^2 T 1] M_x [theta_s^3 theta_s^2 theta_s 1]^T, y_z likewise with M_y:
//   M_x = [ 0.00166 -0.00375  0.00209  0      ]   M_y = [ 0.00275 -0.00610  0.00317  0      ]
//         [-0.02903  0.06377 -0.03202  0.00394]         [-0.04214  0.08970 -0.04153  0.00516]
//         [ 0.11693 -0.21196  0.06052  0.25886]         [ 0.15346 -0.26756  0.06670  0.26688]
//
// The paper fits T in [2, 10] (its turbidity relation to the aerosol: Atmosphere.h,
// MieScatteringFromTurbidity) for the sun above the horizon. Known limits (Zotti,
// Wilkie & Purgathofer 2007, "A Critical Review of the Preetham Skylight Model";
// Bruneton 2016, "A Qualitative and Quantitative Evaluation of 8 Clear Sky
// Models"): the fit degrades for the sun within a few degrees of the horizon
// (Y_z changes sign for theta_s -> 90 deg at high T) and it has no sharp aureole.
#ifndef nimbus_PreethamSky_h
#define nimbus_PreethamSky_h

#include "NimbusPhysicsExport.h" // for export macro

#include <array>

namespace nimbus
{

/// Preetham et al. 1999 Appendix A.2: absolute zenith luminance in kcd/m^2 for
/// turbidity T and sun zenith angle thetaS (rad), see above.
NIMBUSPHYSICS_EXPORT double PreethamZenithLuminance(double turbidity, double sunZenith);

/// The whole analytic sky of Preetham et al. 1999 for one turbidity and one sun.
class NIMBUSPHYSICS_EXPORT PreethamSky
{
public:
  /// Throws std::invalid_argument unless turbidity is finite and in [1.7, 20]
  /// (fitted over [2, 10]) and sunZenith (rad) is finite and in [0, pi/2].
  PreethamSky(double turbidity, double sunZenith);

  /// Perez distributions normalised at the zenith, F(theta, gamma) / F(0, theta_s)
  /// for Y, x, y (index 0, 1, 2); viewZenith in [0, pi/2) (clamped just above the
  /// horizon), gamma in [0, pi].
  std::array<double, 3> Distributions(double viewZenith, double gamma) const;
  /// Luminance [kcd/m^2] in a direction.
  double Luminance(double viewZenith, double gamma) const;
  /// CIE 1931 chromaticity (x, y) in a direction.
  std::array<double, 2> Chromaticity(double viewZenith, double gamma) const;

  double GetZenithLuminance() const { return this->ZenithY; } // kcd/m^2
  std::array<double, 2> GetZenithChromaticity() const
  {
    return { { this->ZenithX, this->ZenithYc } };
  }

private:
  double Turbidity, SunZenith;
  double Coefficients[3][5]; // A..E for Y, x, y
  double Normalisation[3];   // F(0, theta_s)
  double ZenithY, ZenithX, ZenithYc;
};

} // namespace nimbus

#endif
