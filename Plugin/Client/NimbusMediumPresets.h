// The Cloud representation's media presets (issue 17), shared by the panel's Medium
// Preset menu (pqNimbusMediumPresetWidget) and the first Apply of a Nimbus Smoke
// (pqNimbusFirstApplyBehavior). A preset sets the optics and the temperature emission;
// every value stays editable afterwards.
#ifndef NimbusMediumPresets_h
#define NimbusMediumPresets_h

namespace nimbus
{
struct MediumPreset
{
  const char* Name;
  const char* Description;         // for the menu's tooltip
  double ExtinctionPerDensity;     // 1/m per unit density
  double Albedo;                   // 0..1
  double CloudG;                   // -1..1
  int TemperatureEmission;         // 0 or 1
  double EmissionRadiancePerMetre; // Y/(sr m) per unit density at the reference temperature
};

// Cloud: water droplets (the representation's defaults). Smoke: the smoke's density is
// about 1 near the source over metres, not a cloud's over kilometres, and soot absorbs:
// an optical depth of a few across the plume, grey (albedo 0.6), mildly forward (0.3).
// Dark smoke: sootier (albedo 0.25, thicker). Fire: smoke's optics and its blackbody
// glow on (the temperature array in kelvin; a unit density at 1500 K emits 1 per metre).
constexpr MediumPreset kMediumPresets[] = {
  { "Cloud (water droplets)",
    "Extinction 0.02 /m per unit density, albedo 0.99, forward scattering 0.85, no glow.", 0.02,
    0.99, 0.85, 0, 1.0 },
  { "Smoke (grey)", "Extinction 1.5 /m per unit density, albedo 0.6, forward scattering 0.3.", 1.5,
    0.6, 0.3, 0, 1.0 },
  { "Dark smoke (soot)",
    "Extinction 3 /m per unit density, albedo 0.25, forward scattering 0.4: sooty, absorbing.", 3.0,
    0.25, 0.4, 0, 1.0 },
  { "Fire (hot smoke that glows)",
    "Smoke's optics with Temperature Emission on: the temperature array glows as a blackbody "
    "(brighter and bluer when hotter; nothing below about 800 K).",
    1.5, 0.6, 0.3, 1, 1.0 },
};
constexpr int kSmokePreset = 1;
} // namespace nimbus

#endif
