// The Nimbus GLSL library: one file per topic, each the twin of a Physics/ header
// with the same function names and steps (checked on grids of arguments against the
// C++ by the test TestShaderTwins):
//   nimbusPhase.glsl       Rayleigh, HenyeyGreenstein, CornetteShanks   (PhaseFunctions.h)
//   nimbusColor.glsl       SrgbEncode, SrgbDecode                       (SpectralColor.h)
//   nimbusAtmosphere.glsl  DistanceToTopOfAtmosphere, FlatLayerOpticalLength (Atmosphere.h)
//   nimbusSkyView.glsl     SkyViewRow, SkyViewTexel, SkyRadiance        (Sky.h, SkyViewLut)
// A shader asks for them with the lines "//NIMBUS::Library" (phase, colour,
// atmosphere) and "//NIMBUS::SkyView" (the sky-view lookup, after the library).
// Plain C++ in the static library NimbusShaderLibrary (Representations/CMakeLists.txt).
#ifndef nimbus_ShaderLibrary_h
#define nimbus_ShaderLibrary_h

#include <string>

namespace nimbus
{
/// The library's GLSL in dependency order: phase (defines kPi), colour, atmosphere.
std::string ShaderLibrarySource();

/// `source` with "//NIMBUS::Library" replaced by ShaderLibrarySource() and
/// "//NIMBUS::SkyView" by nimbusSkyView.glsl.
std::string WithShaderLibrary(const std::string& source);
} // namespace nimbus

#endif
