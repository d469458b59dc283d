/**
 * @class   vtkNimbusSky
 * @brief   Shared sky parameters and their look-up tables.
 *
 * One object that the sky background / aerial-perspective pass
 * (vtkNimbusSkyPass), the sky dome (vtkNimbusSkyDomeSource) and a cloud mapper
 * share, so that sky, haze and clouds agree. It is thin glue around
 * Physics/Sky.h (plain C++): it holds the parameters, builds the tables lazily
 * and rebuilds each only when what it depends on changed (cache keys; SkyTableCache.h,
 * the cache the cloud mapper keeps its own sky tables in too):
 *  - SkyModel (transmittance + multiple scattering): Turbidity (= MieScatteringPerMetre),
 *    GroundAlbedo, ScatteringOrders;
 *  - sky-view table: the model, SunElevationDegrees, SceneAltitudeMetres;
 *  - aerial-perspective table: the model, SunElevationDegrees, the camera altitude,
 *    MaxAerialDistanceMetres.
 * SunAzimuthDegrees, Exposure and WhiteBalance never rebuild anything.
 *
 * Radiance is relative to the sun: the solar irradiance outside the atmosphere
 * has luminance Y = 1 (so a white Lambertian plane facing the sun there has
 * radiance 1/pi). Display value = Exposure x radiance, then (WhiteBalance) each
 * linear sRGB channel divided by that of the sun outside the atmosphere (as
 * vtkNimbusSunlight).
 *
 * Scene frame: UpAxis up (+Z by default: z up, y north, x east; +X, +Y or -Y turn the
 * sun, the sky and the ground about that axis instead, Physics/UpAxis.h); scene
 * lengths x MetresPerUnit = metres;
 * scene z = 0 is at SceneAltitudeMetres above sea level.
 *
 * For a GL mapper: GetTransmittanceTable / GetMultipleScatteringTable give the
 * atmosphere's float tables, GetSkyViewTable / GetAerialPerspectiveTable the
 * per-sun tables, with their sizes and parametrisations documented in Sky.h.
 */
#ifndef vtkNimbusSky_h
#define vtkNimbusSky_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkObject.h"

#include <memory> // for std::unique_ptr

namespace nimbus
{
class SkyModel;
class SkyViewLut;
class AerialPerspectiveLut;
}

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusSky : public vtkObject
{
public:
  static vtkNimbusSky* New();
  vtkTypeMacro(vtkNimbusSky, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Presets
  {
    Noon = 0,      ///< sun 60 deg, south
    Afternoon = 1, ///< sun 30 deg, south-west
    Sunset = 2,    ///< sun 2 deg, west
    Twilight = 3   ///< sun -4 deg, west (civil twilight)
  };
  /// Sets SunElevationDegrees and SunAzimuthDegrees from a preset (an error for an unknown one).
  void SetPreset(int preset);

  ///@{
  /// Sun elevation above the horizon, degrees, [-90, 90]. Default 45.
  virtual void SetSunElevationDegrees(double value);
  virtual double GetSunElevationDegreesMinValue() { return -90.0; }
  virtual double GetSunElevationDegreesMaxValue() { return 90.0; }
  vtkGetMacro(SunElevationDegrees, double);
  ///@}
  ///@{
  /// Sun azimuth from north (+y) toward east (+x), degrees. Default 135.
  virtual void SetSunAzimuthDegrees(double value);
  virtual double GetSunAzimuthDegreesMinValue() { return -1e9; }
  virtual double GetSunAzimuthDegreesMaxValue() { return 1e9; }
  vtkGetMacro(SunAzimuthDegrees, double);
  ///@}
  ///@{
  /// How hazy the air is: the turbidity T of Preetham, Shirley & Smits 1999
  /// (dimensionless, [1, 10]; 2 very clear, 3 clear, 5 light haze, 10 hazy; 1 is air
  /// without aerosol). It sets the aerosol amount (Ångström beta = 0.04608 T - 0.04586,
  /// the aerosol optical depth at 550 nm is beta 0.55^-1.3: 0.10 at T = 2, 0.20 at 3,
  /// 0.70 at 8); the rest of the air is fixed (Ångström exponent 1.3, measured-aerosol
  /// phase function, ozone 300 DU: nimbus::ClearSkyAtmosphere). Default 2 (AOD 0.10).
  /// Turbidity and MieScatteringPerMetre are two names of one setting: setting one
  /// sets the other.
  virtual void SetTurbidity(double value);
  virtual double GetTurbidityMinValue() { return 1.0; }
  virtual double GetTurbidityMaxValue() { return 10.0; }
  vtkGetMacro(Turbidity, double);
  ///@}
  ///@{
  /// The same setting as the aerosol (Mie) scattering coefficient at sea level and
  /// 550 nm, 1/m, [0, 6.8e-4] (the mapper's and the scene format's name and unit):
  /// 1.875e-5 at the default turbidity 2 (nimbus::MieScatteringFromTurbidity); 2e-5
  /// (the default before turbidity) is turbidity 2.07. Setting it sets Turbidity
  /// (1 + 53.3 per 1e-3 /m: 10 at 1.69e-4, 37 at the top of the range).
  virtual void SetMieScatteringPerMetre(double value);
  virtual double GetMieScatteringPerMetreMinValue() { return 0.0; }
  virtual double GetMieScatteringPerMetreMaxValue() { return 6.8e-4; }
  vtkGetMacro(MieScatteringPerMetre, double);
  ///@}
  ///@{
  /// Grey Lambertian albedo of the ground, [0, 1]. Default 0.3.
  virtual void SetGroundAlbedo(double value);
  virtual double GetGroundAlbedoMinValue() { return 0.0; }
  virtual double GetGroundAlbedoMaxValue() { return 1.0; }
  vtkGetMacro(GroundAlbedo, double);
  ///@}
  ///@{
  /// Display scale of the radiance, [0, 1e6]. Default 10.
  virtual void SetExposure(double value);
  virtual double GetExposureMinValue() { return 0.0; }
  virtual double GetExposureMaxValue() { return 1.0e6; }
  vtkGetMacro(Exposure, double);
  ///@}
  ///@{
  /// Altitude of the scene's z = 0 (and of the dome's observer) above sea level,
  /// metres, [0, 1e6]. Default 0.
  virtual void SetSceneAltitudeMetres(double value);
  virtual double GetSceneAltitudeMetresMinValue() { return 0.0; }
  virtual double GetSceneAltitudeMetresMaxValue() { return 1.0e6; }
  vtkGetMacro(SceneAltitudeMetres, double);
  ///@}
  ///@{
  /// Which axis of the scene points up (nimbus::UpAxis: 0 +X, 1 +Y, 2 +Z (default),
  /// 3 -Y); the sky and its sun turn about it, and a cloud that follows this sky
  /// (vtkNimbusCloudVolumeMapper) takes it. Other values are refused with an error.
  virtual void SetUpAxis(int value);
  vtkGetMacro(UpAxis, int);
  ///@}
  ///@{
  /// Metres per scene unit, (0, 1e6]. Default 1.
  virtual void SetMetresPerUnit(double value);
  virtual double GetMetresPerUnitMinValue() { return 1e-6; }
  virtual double GetMetresPerUnitMaxValue() { return 1.0e6; }
  vtkGetMacro(MetresPerUnit, double);
  ///@}
  ///@{
  /// Range of the aerial-perspective table, metres, [100, 1e6]. Default 1e5.
  virtual void SetMaxAerialDistanceMetres(double value);
  virtual double GetMaxAerialDistanceMetresMinValue() { return 100.0; }
  virtual double GetMaxAerialDistanceMetresMaxValue() { return 1.0e6; }
  vtkGetMacro(MaxAerialDistanceMetres, double);
  ///@}
  ///@{
  /// Scattering orders K (1 = single scattering), [1, 10]. Default 4.
  vtkSetClampMacro(ScatteringOrders, int, 1, 10);
  vtkGetMacro(ScatteringOrders, int);
  ///@}
  ///@{
  /// Divide colours by the sun's colour outside the atmosphere. Default on.
  vtkSetMacro(WhiteBalance, bool);
  vtkGetMacro(WhiteBalance, bool);
  vtkBooleanMacro(WhiteBalance, bool);
  ///@}
  ///@{
  /// Draw the limb-darkened sun disc in the background. Default on.
  vtkSetMacro(SunDisc, bool);
  vtkGetMacro(SunDisc, bool);
  vtkBooleanMacro(SunDisc, bool);
  ///@}

  /// Unit vector toward the sun (scene frame).
  void GetSunDirection(double direction[3]);

  /// Sky radiance (linear sRGB, relative to the sun, no exposure) seen from the
  /// observer (scene z = 0) along unit direction, from the sky-view table.
  void GetRadiance(const double direction[3], double rgb[3]);
  /// Display colour of that radiance: Exposure and white balance applied (linear).
  void GetDisplayColor(const double direction[3], double rgb[3]);
  /// Per-channel display factors: Exposure / sun colour (or Exposure).
  void GetDisplayScale(double scale[3]);

  /// Aerial perspective between two scene points (camera, point): transmittance
  /// (linear sRGB factor) and in-scattered radiance (linear sRGB, relative to the
  /// sun, no exposure), integrated directly (all scattering orders).
  void AerialPerspective(const double cameraPosition[3], const double point[3],
    double transmittance[3], double inscatter[3]);

  /// Radiance of the sun's disc centre (linear sRGB, relative; 0 below the horizon)
  /// at the observer, for a disc of angular radius GetSunAngularRadius().
  void GetSunDiscRadiance(double rgb[3]);
  static double GetSunAngularRadius() { return 0.004654; } // rad (0.2667 deg)

  /// The tables (built on demand). Not wrapped; see Sky.h for the layouts.
  const nimbus::SkyModel& GetSkyModel();
  const nimbus::SkyViewLut& GetSkyViewLut();
  /// Sky-view table seen from another altitude (m; a camera's): below the
  /// horizon it holds the air between that altitude and the ground. The
  /// observer's table when the altitude is within max(25 m, 2 %) of
  /// SceneAltitudeMetres; otherwise a second cached table, rebuilt when the altitude
  /// moves by more than max(25 m, 2 %) (0.2 s at the default size).
  const nimbus::SkyViewLut& GetSkyViewLutAt(double altitude);
  /// Aerial-perspective table for a camera at the given altitude (m); rebuilt
  /// when the altitude moves by more than 1 % (or 10 m).
  const nimbus::AerialPerspectiveLut& GetAerialPerspectiveLut(double cameraAltitude);

  /// Number of table builds so far (tests of the cache keys).
  vtkGetMacro(ModelBuilds, int);
  vtkGetMacro(SkyViewBuilds, int);
  vtkGetMacro(AerialBuilds, int);

protected:
  vtkNimbusSky();
  ~vtkNimbusSky() override;

  // The sun's defaults are nimbus::SunParameters' (Physics/Sun.h), set in the constructor.
  double SunElevationDegrees = 0.0;
  double SunAzimuthDegrees = 0.0;
  double Turbidity = 2.0;                  // nimbus::kDefaultTurbidity
  double MieScatteringPerMetre = 1.875e-5; // of Turbidity (set in the constructor)
  double GroundAlbedo = 0.3;
  double Exposure = 10.0;
  double SceneAltitudeMetres = 0.0;
  double MetresPerUnit = 1.0;
  int UpAxis = 2;
  double MaxAerialDistanceMetres = 1.0e5;
  int ScatteringOrders = 4;
  bool WhiteBalance = true;
  bool SunDisc = true;
  int ModelBuilds = 0;
  int SkyViewBuilds = 0;
  int AerialBuilds = 0;

private:
  vtkNimbusSky(const vtkNimbusSky&) = delete;
  void operator=(const vtkNimbusSky&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
