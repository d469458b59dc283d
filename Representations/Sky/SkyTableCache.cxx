#include "SkyTableCache.h"

#include <cmath>
#include <stdexcept>

namespace nimbus
{
const SkyModel& SkyTableCache::Model(
  const std::vector<double>& key, const std::function<SkyParameters()>& parameters)
{
  if (!this->CachedModel || key != this->ModelKey)
  {
    // The tables refer to the model: dropped before it.
    this->ClearTables();
    this->CachedModel.reset();
    this->CachedModel = std::make_unique<SkyModel>(parameters());
    this->ModelKey = key;
    ++this->ModelGeneration;
    ++this->ModelBuilds;
  }
  return *this->CachedModel;
}

const SkyViewLut& SkyTableCache::SkyView(int slot, double sunElevationDegrees, double altitude,
  double altitudeTolerance, const ViewSize& size)
{
  if (!this->CachedModel || slot < 0 || slot >= static_cast<int>(this->Views.size()))
  {
    throw std::logic_error("SkyTableCache::SkyView: no model, or no such slot");
  }
  View& view = this->Views[slot];
  if (!view.Table || view.Elevation != sunElevationDegrees || view.Size.Width != size.Width ||
    view.Size.AboveRows != size.AboveRows || view.Size.BelowRows != size.BelowRows ||
    !(std::abs(view.Altitude - altitude) <= altitudeTolerance))
  {
    view.Table.reset();
    view.Table = std::make_unique<SkyViewLut>(*this->CachedModel, sunElevationDegrees, altitude,
      size.Width, size.AboveRows, size.BelowRows);
    view.Elevation = sunElevationDegrees;
    view.Altitude = altitude;
    view.Size = size;
    ++this->SkyViewBuilds;
  }
  return *view.Table;
}

const AerialPerspectiveLut& SkyTableCache::Aerial(
  double sunElevationDegrees, double altitude, double altitudeTolerance, double maxDistance)
{
  if (!this->CachedModel)
  {
    throw std::logic_error("SkyTableCache::Aerial: no model");
  }
  if (!this->CachedAerial || this->AerialElevation != sunElevationDegrees ||
    this->AerialRange != maxDistance ||
    std::abs(this->AerialAltitude - altitude) > altitudeTolerance)
  {
    this->CachedAerial.reset();
    this->CachedAerial = std::make_unique<AerialPerspectiveLut>(
      *this->CachedModel, sunElevationDegrees, altitude, maxDistance);
    this->AerialElevation = sunElevationDegrees;
    this->AerialAltitude = altitude;
    this->AerialRange = maxDistance;
    ++this->AerialBuilds;
  }
  return *this->CachedAerial;
}

void SkyTableCache::ClearTables()
{
  for (View& view : this->Views)
  {
    view.Table.reset();
  }
  this->CachedAerial.reset();
}

void SkyTableCache::Clear()
{
  this->ClearTables();
  this->CachedModel.reset();
  this->ModelKey.clear();
}
}
