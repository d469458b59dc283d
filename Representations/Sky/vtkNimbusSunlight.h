/**
 * @class   vtkNimbusSunlight
 * @brief   Direction and colour of direct sunlight after the atmosphere.
 *
 * Thin VTK glue around Nimbus::Physics (Physics/Atmosphere.h, Physics/SpectralColor.h):
 * the sun is a 5778 K blackbody outside the atmosphere; its light reaching an
 * observer at SceneAltitudeMetres is attenuated by Rayleigh and Mie extinction along
 * the slanted path to the top of a spherical atmosphere, sampled at
 * nimbus::SpectralSamples' default wavelengths and converted via CIE XYZ to
 * linear sRGB. The colour is normalised so that the sun outside the atmosphere
 * has luminance Y = 1; at noon it is slightly yellow and dimmer, at sunset orange
 * and much dimmer, below the horizon (when the earth blocks it) black.
 *
 * WhiteBalance (default on) divides each linear sRGB channel by that of the sun
 * outside the atmosphere, like a camera set to "daylight": without it even the
 * unattenuated sun is orange-tinted, (1.05, 0.88, 0.73), because a 5778 K
 * blackbody is warmer than sRGB's D65 white point.
 *
 * Scene frame: z up, y north, x east. SunElevationDegrees is the angle above the
 * horizon (degrees, -90..90); SunAzimuthDegrees is measured from north (+y) toward
 * east (+x), degrees.
 */
#ifndef vtkNimbusSunlight_h
#define vtkNimbusSunlight_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkObject.h"

class vtkLight;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusSunlight : public vtkObject
{
public:
  static vtkNimbusSunlight* New();
  vtkTypeMacro(vtkNimbusSunlight, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Sun elevation above the horizon, degrees in [-90, 90]. Default 45.
  virtual void SetSunElevationDegrees(double value);
  virtual double GetSunElevationDegreesMinValue() { return -90.0; }
  virtual double GetSunElevationDegreesMaxValue() { return 90.0; }
  vtkGetMacro(SunElevationDegrees, double);
  ///@}

  ///@{
  /// Sun azimuth from north (+y) toward east (+x), degrees. Default 135 (south-east).
  virtual void SetSunAzimuthDegrees(double value);
  virtual double GetSunAzimuthDegreesMinValue() { return -1e9; }
  virtual double GetSunAzimuthDegreesMaxValue() { return 1e9; }
  vtkGetMacro(SunAzimuthDegrees, double);
  ///@}

  ///@{
  /// Altitude of the lit scene above sea level, metres (>= 0). Default 1500.
  virtual void SetSceneAltitudeMetres(double value);
  virtual double GetSceneAltitudeMetresMinValue() { return 0.0; }
  virtual double GetSceneAltitudeMetresMaxValue() { return 1.0e5; }
  vtkGetMacro(SceneAltitudeMetres, double);
  ///@}

  ///@{
  /// Scale colours so that the sun outside the atmosphere is white. Default on.
  vtkSetMacro(WhiteBalance, bool);
  vtkGetMacro(WhiteBalance, bool);
  vtkBooleanMacro(WhiteBalance, bool);
  ///@}

  /// Unit vector from the scene toward the sun (scene frame, z up).
  void GetDirection(double direction[3]);

  /// Linear sRGB of the direct sunlight at the observer (Y = 1 outside the atmosphere).
  void GetColor(double rgb[3]);

  /// Luminance Y of the direct sunlight at the observer, relative to outside the atmosphere.
  double GetRelativeLuminance();

  /// Makes light a directional light from the sun: colour = GetColor() scaled so
  /// its largest component is 1, intensity = that largest component.
  void ApplyToLight(vtkLight* light);

protected:
  vtkNimbusSunlight();
  ~vtkNimbusSunlight() override = default;

  // The sun's defaults are nimbus::SunParameters' (Physics/Sun.h), set in the constructor.
  double SunElevationDegrees = 0.0;
  double SunAzimuthDegrees = 0.0;
  double SceneAltitudeMetres = 1500.0;
  bool WhiteBalance = true;

private:
  vtkNimbusSunlight(const vtkNimbusSunlight&) = delete;
  void operator=(const vtkNimbusSunlight&) = delete;

  /// XYZ of the direct sun at the observer and outside the atmosphere, both
  /// relative to the luminance outside (so outside[1] = 1).
  void ComputeXyz(double transmitted[3], double outside[3]);
};

#endif
