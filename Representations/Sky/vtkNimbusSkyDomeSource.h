/**
 * @class   vtkNimbusSkyDomeSource
 * @brief   Polygonised sky hemisphere with per-vertex sky colours (002 §2).
 *
 * As in 002 §2: "the sky is considered to be a hemisphere with a large radius;
 * the hemisphere is polygonised and the colour of the sky at each vertex is
 * obtained by using the look-up table". Colours come from a vtkNimbusSky (its
 * sky-view table); the output has point arrays "Colors" (unsigned char RGB,
 * display colour: Exposure, white balance, clamp, sRGB encoding) and "Radiance"
 * (float RGB, linear sRGB relative to the sun, no exposure). Rings crowd toward
 * the horizon (elevation = 90 deg (i/n)^1.5 ... measured from the horizon), where
 * the sky changes fastest. Render it with the mapper's scalar colouring and
 * lighting off (vtkProperty::LightingOff) so the colours are shown as they are.
 *
 * The output's field data carries the sky's parameters, as they were when the
 * colours were computed (after the Preset), one one-tuple vtkDoubleArray each,
 * named as the vtkNimbusSky parameter (units as there):
 *  - "SunElevationDegrees" (deg above the horizon), "SunAzimuthDegrees" (deg from +y toward +x),
 *  - "Turbidity", "MieScatteringPerMetre" (1/m at sea level and 550 nm; the same
 *    setting, both written; read in this order, so the second wins), "GroundAlbedo",
 *  - "Exposure", "WhiteBalance" (0/1), "SunDisc" (0/1),
 *  - "SceneAltitudeMetres" (m), "MetresPerUnit", "MaxAerialDistanceMetres" (m),
 *  - "ScatteringOrders" (1 = single scattering), "UpAxis" (nimbus::UpAxis: 0 +X, 1 +Y,
 *    2 +Z, 3 -Y; the dome stands on that axis).
 * Consumers (ParaView's "Sky Background" representation) rebuild the same sky
 * from them with ApplySkyParameters(); AddSkyParameters() writes them.
 */
#ifndef vtkNimbusSkyDomeSource_h
#define vtkNimbusSkyDomeSource_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

class vtkFieldData;
class vtkNimbusSky;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusSkyDomeSource : public vtkPolyDataAlgorithm
{
public:
  static vtkNimbusSkyDomeSource* New();
  vtkTypeMacro(vtkNimbusSkyDomeSource, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The sky whose colours are used (the source starts with its own sky; share
  /// one with a vtkNimbusSkyPass / cloud mapper by setting it). Null is an error.
  void SetSky(vtkNimbusSky* sky);
  vtkGetObjectMacro(Sky, vtkNimbusSky);
  ///@}

  ///@{
  /// Preset applied to the sky at every update (vtkNimbusSky::Presets), or -1
  /// (custom: the sun angles below). For ParaView's Preset drop-down. Default -1.
  vtkSetClampMacro(Preset, int, -1, 3);
  vtkGetMacro(Preset, int);
  ///@}

  ///@{
  /// Forwarded to the sky (one place for ParaView's properties).
  void SetSunElevationDegrees(double v);
  void SetSunAzimuthDegrees(double v);
  ///@}
  ///@{
  /// The haze: Turbidity (vtkNimbusSky::SetTurbidity) unless MieScatteringPerMetre is
  /// >= 0, which then sets the aerosol directly (vtkNimbusSky::SetMieScatteringPerMetre)
  /// whatever the order of the two calls (ParaView's property "MieScatteringPerMetre",
  /// -1 by default, keeps states saved before Turbidity existed as they were).
  /// Defaults: Turbidity 2, MieScatteringPerMetre -1 (from Turbidity).
  void SetTurbidity(double v);
  vtkGetMacro(Turbidity, double);
  void SetMieScatteringPerMetre(double v);
  vtkGetMacro(MieScatteringPerMetre, double);
  ///@}
  ///@{
  void SetGroundAlbedo(double v);
  void SetExposure(double v);
  void SetSceneAltitudeMetres(double v);
  void SetMetresPerUnit(double v);
  void SetUpAxis(int v);
  void SetScatteringOrders(int v);
  void SetWhiteBalance(bool v);
  void SetSunDisc(bool v);
  ///@}

  /// Writes the sky's parameters into field data (the arrays listed above,
  /// replacing arrays of the same names).
  static void AddSkyParameters(vtkNimbusSky* sky, vtkFieldData* fieldData);
  /// Sets the sky's parameters from those arrays; a parameter whose array is
  /// missing (or empty) gets the vtkNimbusSky default. Returns how many of the
  /// arrays were found.
  static int ApplySkyParameters(vtkFieldData* fieldData, vtkNimbusSky* sky);

  ///@{
  /// Radius of the dome, scene units, > 0. Default 10000.
  virtual void SetRadius(double value);
  virtual double GetRadiusMinValue() { return 1e-6; }
  virtual double GetRadiusMaxValue() { return 1e30; }
  vtkGetMacro(Radius, double);
  ///@}
  ///@{
  /// Centre of the dome (the observer), scene units. Default (0, 0, 0).
  virtual void SetCenter(double x, double y, double z);
  virtual void SetCenter(const double center[3]);
  vtkGetVector3Macro(Center, double);
  ///@}
  ///@{
  /// Rings from the horizon to the zenith, [2, 1024]. Default 32.
  vtkSetClampMacro(ElevationResolution, int, 2, 1024);
  vtkGetMacro(ElevationResolution, int);
  ///@}
  ///@{
  /// Vertices per ring, [3, 4096]. Default 64.
  vtkSetClampMacro(AzimuthResolution, int, 3, 4096);
  vtkGetMacro(AzimuthResolution, int);
  ///@}

  /// Includes the sky's modification time.
  vtkMTimeType GetMTime() override;

protected:
  vtkNimbusSkyDomeSource();
  ~vtkNimbusSkyDomeSource() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  vtkNimbusSky* Sky = nullptr;
  int Preset = -1;
  double Radius = 10000.0;
  double Center[3] = { 0.0, 0.0, 0.0 };
  int ElevationResolution = 32;
  int AzimuthResolution = 64;
  double Turbidity = 2.0;
  double MieScatteringPerMetre = -1.0;
  void ApplyHaze();

private:
  vtkNimbusSkyDomeSource(const vtkNimbusSkyDomeSource&) = delete;
  void operator=(const vtkNimbusSkyDomeSource&) = delete;
};

#endif
