// Benchmark (not a test) of the sky tables: build time and size against table
// resolution, wavelength count and scattering orders. Prints a table; median of
// `repeats` builds. Usage: BenchSky [repeats=3] [threads=0]
#include "Sky.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace
{
template <class F>
double Median(int repeats, const F& f)
{
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i)
  {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}
}

int main(int argc, char* argv[])
{
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 3;
  const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
  std::printf("# SkyModel build (transmittance + multiple scattering), median of %d\n", repeats);
  std::printf("wavelengths,orders,ms_r,ms_mus,dirs,seconds,transmittance_bytes,ms_bytes\n");
  struct Case
  {
    int wavelengths, orders, r, mus, zenith, azimuth;
  };
  const Case cases[] = { { 16, 1, 16, 32, 16, 8 }, { 8, 4, 16, 32, 16, 8 },
    { 16, 4, 16, 32, 16, 8 }, { 32, 4, 16, 32, 16, 8 }, { 16, 2, 16, 32, 16, 8 },
    { 16, 6, 16, 32, 16, 8 }, { 16, 4, 32, 64, 16, 8 }, { 16, 4, 16, 32, 32, 16 } };
  for (const Case& c : cases)
  {
    nimbus::SkyParameters p;
    p.Wavelengths = c.wavelengths;
    p.ScatteringOrders = c.orders;
    p.ScatteringRSize = c.r;
    p.ScatteringMuSSize = c.mus;
    p.ScatteringZenithDirections = c.zenith;
    p.ScatteringAzimuthDirections = c.azimuth;
    p.Threads = threads;
    std::size_t tBytes = 0, mBytes = 0;
    const double s = Median(repeats,
      [&]
      {
        nimbus::SkyModel model(p);
        tBytes = model.GetTransmittanceTable().size() * sizeof(float);
        mBytes = model.GetMultipleScatteringTable().size() * sizeof(float);
      });
    std::printf("%d,%d,%d,%d,%dx%d,%.3f,%zu,%zu\n", c.wavelengths, c.orders, c.r, c.mus, c.zenith,
      c.azimuth, s, tBytes, mBytes);
  }
  std::printf(
    "# sky-view and aerial-perspective tables (per sun elevation / altitude), 16 wavelengths\n");
  std::printf("table,size,seconds,bytes\n");
  for (int wl : { 8, 16, 32 })
  {
    nimbus::SkyParameters p;
    p.Wavelengths = wl;
    p.Threads = threads;
    const nimbus::SkyModel model(p);
    const int sizes[][3] = { { 64, 32, 16 }, { 128, 64, 32 }, { 256, 128, 64 } };
    for (const auto& z : sizes)
    {
      std::size_t bytes = 0;
      const double s = Median(repeats,
        [&]
        {
          nimbus::SkyViewLut lut(model, 10.0, 0.0, z[0], z[1], z[2]);
          bytes = lut.GetTable().size() * sizeof(float);
        });
      std::printf("skyview(wl=%d),%dx%d,%.4f,%zu\n", wl, z[0], z[1] + z[2], s, bytes);
    }
    std::size_t bytes = 0;
    const double s = Median(repeats,
      [&]
      {
        nimbus::AerialPerspectiveLut lut(model, 10.0, 500.0);
        bytes = lut.GetTable().size() * sizeof(float);
      });
    std::printf("aerial(wl=%d),32x64x32,%.4f,%zu\n", wl, s, bytes);
  }
  return 0;
}
