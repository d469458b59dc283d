// The Cloud representation's media presets, shared by the panel's Medium
// Preset menu (pqNimbusMediumPresetWidget) and the first Apply of a Nimbus Smoke
// (pqNimbusFirstApplyBehavior). A preset sets the optics and the temperature emission;
// every value stays editable afterwards, and the menu shows the preset whose values the
// display has (MatchingMediumPreset), or "Custom".
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
constexpr int kNumberOfMediumPresets =
  static_cast<int>(sizeof(kMediumPresets) / sizeof(kMediumPresets[0]));

// The values a preset sets, as a display has them.
struct MediumValues
{
  double ExtinctionPerDensity;
  double Albedo;
  double CloudG;
  int TemperatureEmission;
  double EmissionRadiancePerMetre;
};

// Equal within a small tolerance: 1e-3 relative, with an absolute floor of 1e-6, so a
// value typed with fewer digits or read back through text still matches its preset.
inline bool SameMediumValue(double a, double b)
{
  const double difference = a > b ? a - b : b - a;
  const double magnitude = b < 0.0 ? -b : b;
  return difference <= 1e-6 + 1e-3 * magnitude;
}

// The preset whose values these are (its index in kMediumPresets), or -1: none (the
// menu's "Custom"). The glow's brightness counts only while the glow is on.
inline int MatchingMediumPreset(const MediumValues& values)
{
  for (int i = 0; i < kNumberOfMediumPresets; ++i)
  {
    const MediumPreset& preset = kMediumPresets[i];
    if (SameMediumValue(values.ExtinctionPerDensity, preset.ExtinctionPerDensity) &&
      SameMediumValue(values.Albedo, preset.Albedo) &&
      SameMediumValue(values.CloudG, preset.CloudG) &&
      (values.TemperatureEmission != 0) == (preset.TemperatureEmission != 0) &&
      (values.TemperatureEmission == 0 ||
        SameMediumValue(values.EmissionRadiancePerMetre, preset.EmissionRadiancePerMetre)))
    {
      return i;
    }
  }
  return -1;
}
} // namespace nimbus

#endif
