// The sky's tables kept between frames, each rebuilt only when its key changed: a sky model
// (Physics/Sky.h: transmittance and multiple scattering, about 1.5 s to build), the sky-view
// tables made from it and an aerial-perspective table. Plain C++ (no VTK): one cache used by
// vtkNimbusSky (the scene's sky: its model, the observer's and a camera's sky-view tables,
// the aerial perspective) and by vtkNimbusCloudVolumeMapper (the sky model of the frame's air
// and the sky seen from the cloud). Each owner keys the model by the parameters it builds it
// from; the tables made from a model are dropped when the model is rebuilt (they refer to it).
#ifndef nimbus_SkyTableCache_h
#define nimbus_SkyTableCache_h

#include "Sky.h"

#include <array>
#include <functional>
#include <memory>
#include <vector>

namespace nimbus
{
/// The size of a sky-view table (SkyViewLut's columns, rows above and below the horizon;
/// SkyViewLut's defaults).
struct SkyViewSize
{
  int Width = 128, AboveRows = 64, BelowRows = 32;
};

class SkyTableCache
{
public:
  using ViewSize = SkyViewSize;

  /// The model for `key`: the cached one while `key` is the one it was built for, else one
  /// built from `parameters()` (every table made from the old model dropped first). Throws
  /// what SkyModel throws; nothing is cached then.
  const SkyModel& Model(
    const std::vector<double>& key, const std::function<SkyParameters()>& parameters);
  /// The current model (nullptr before the first Model or after Clear).
  const SkyModel* CurrentModel() const { return this->CachedModel.get(); }
  /// Counts the models built: a table or a frame made from the model can key on it.
  int GetModelGeneration() const { return this->ModelGeneration; }

  /// The current model's sky-view table in `slot` (0 or 1: two observers) for the sun's
  /// elevation (degrees) and the observer's altitude (m): rebuilt when the model, the
  /// elevation or the size changed, or when the altitude moved by more than
  /// `altitudeTolerance` m from the table's. Model() must have been called.
  const SkyViewLut& SkyView(int slot, double sunElevationDegrees, double altitude,
    double altitudeTolerance, const ViewSize& size = ViewSize());

  /// The current model's aerial-perspective table for the sun's elevation (degrees), a
  /// camera at `altitude` m and distances up to `maxDistance` m: rebuilt when the model,
  /// the elevation or the range changed, or when the altitude moved by more than
  /// `altitudeTolerance` m from the table's. Model() must have been called.
  const AerialPerspectiveLut& Aerial(
    double sunElevationDegrees, double altitude, double altitudeTolerance, double maxDistance);

  /// Drops the model and every table.
  void Clear();

  /// Tables built so far (tests of the cache keys).
  int GetModelBuilds() const { return this->ModelBuilds; }
  int GetSkyViewBuilds() const { return this->SkyViewBuilds; }
  int GetAerialBuilds() const { return this->AerialBuilds; }

private:
  void ClearTables();

  std::unique_ptr<SkyModel> CachedModel;
  std::vector<double> ModelKey;
  int ModelGeneration = 0;

  struct View
  {
    std::unique_ptr<SkyViewLut> Table;
    double Elevation = 0.0, Altitude = 0.0;
    ViewSize Size;
  };
  std::array<View, 2> Views;

  std::unique_ptr<AerialPerspectiveLut> CachedAerial;
  double AerialElevation = 0.0, AerialAltitude = 0.0, AerialRange = 0.0;

  int ModelBuilds = 0, SkyViewBuilds = 0, AerialBuilds = 0;
};
}

#endif
