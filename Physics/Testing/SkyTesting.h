// Test support shared by the sky's tests (Physics/Testing/TestSky.cxx and
// Testing/Cxx/TestSkyAgainstReference.cxx): the two models they measure and the
// error measure they report. Header-only.
#ifndef NimbusSkyTesting_h
#define NimbusSkyTesting_h

#include "Sky.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace nimbus
{
namespace testing
{
using Rgb = std::array<double, 3>;

/// Relative luminance of linear sRGB.
inline double Y(const Rgb& c)
{
  return LinearSrgbLuminance(c);
}

/// The default model (multiple scattering, ground albedo 0.3, the clear sky of the
/// default turbidity: ClearSkyAtmosphere(kDefaultTurbidity)), built once.
inline const SkyModel& FullSkyModel()
{
  static const SkyModel model{ SkyParameters() };
  return model;
}

/// A single-scattering model (K = 1, ground albedo 0) of the reference renderer's air
/// (AtmosphereParameters' defaults: grey aerosol, no ozone, which is what the scene
/// format and nimbus::SunAndAir model), built once.
inline const SkyModel& SingleScatteringSkyModel()
{
  static const SkyModel model{ []
    {
      SkyParameters p;
      p.Atmosphere = AtmosphereParameters();
      p.ScatteringOrders = 1;
      p.GroundAlbedo = 0.0;
      return p;
    }() };
  return model;
}

/// |a - b| per channel relative to the reference luminance (so that a dim channel
/// at twilight does not count as a large error), maximum over channels; the
/// luminance is floored at `floor` (absolute).
inline double RelativeError(const Rgb& a, const Rgb& ref, double floor = 1e-30)
{
  const double y = std::max(Y(ref), floor);
  double e = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    e = std::max(e, std::abs(a[c] - ref[c]) / y);
  }
  return e;
}
} // namespace testing
} // namespace nimbus

#endif
