// The sky parameters that vtkNimbusSkyDomeSource writes into its output's field
// data (what ParaView's "Sky Background" representation reads back): every
// parameter round-trips exactly, presets are applied before they are written,
// and a missing array means that parameter's vtkNimbusSky default.
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyDomeSource.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <cmath>

namespace
{
void ExpectSameSky(vtkNimbusSky* a, vtkNimbusSky* b)
{
  EXPECT_EQ(a->GetSunElevationDegrees(), b->GetSunElevationDegrees());
  EXPECT_EQ(a->GetSunAzimuthDegrees(), b->GetSunAzimuthDegrees());
  EXPECT_EQ(a->GetMieScatteringPerMetre(), b->GetMieScatteringPerMetre());
  EXPECT_DOUBLE_EQ(a->GetTurbidity(), b->GetTurbidity());
  EXPECT_EQ(a->GetGroundAlbedo(), b->GetGroundAlbedo());
  EXPECT_EQ(a->GetExposure(), b->GetExposure());
  EXPECT_EQ(a->GetWhiteBalance(), b->GetWhiteBalance());
  EXPECT_EQ(a->GetSunDisc(), b->GetSunDisc());
  EXPECT_EQ(a->GetSceneAltitudeMetres(), b->GetSceneAltitudeMetres());
  EXPECT_EQ(a->GetMetresPerUnit(), b->GetMetresPerUnit());
  EXPECT_EQ(a->GetMaxAerialDistanceMetres(), b->GetMaxAerialDistanceMetres());
  EXPECT_EQ(a->GetScatteringOrders(), b->GetScatteringOrders());
  EXPECT_EQ(a->GetUpAxis(), b->GetUpAxis());
}
}

TEST(SkyDomeParameters, OutputFieldDataAfterPreset)
{
  vtkNew<vtkNimbusSkyDomeSource> dome;
  dome->SetElevationResolution(4);
  dome->SetAzimuthResolution(8);
  dome->SetPreset(vtkNimbusSky::Sunset);
  dome->SetSunElevationDegrees(70.0); // overridden by the preset
  dome->SetExposure(25.0);
  dome->SetMieScatteringPerMetre(3.0 * 2.0e-5);
  dome->SetGroundAlbedo(0.1);
  dome->SetSceneAltitudeMetres(1500.0);
  dome->SetMetresPerUnit(1000.0);
  dome->SetScatteringOrders(2);
  dome->SetWhiteBalance(false);
  dome->SetSunDisc(false);
  dome->SetUpAxis(1); // +Y
  dome->Update();
  vtkFieldData* fields = dome->GetOutput()->GetFieldData();
  const char* names[] = { "SunElevationDegrees", "SunAzimuthDegrees", "Turbidity",
    "MieScatteringPerMetre", "GroundAlbedo", "Exposure", "WhiteBalance", "SunDisc",
    "SceneAltitudeMetres", "MetresPerUnit", "MaxAerialDistanceMetres", "ScatteringOrders",
    "UpAxis" };
  for (const char* name : names)
  {
    vtkDataArray* array = fields->GetArray(name);
    ASSERT_NE(array, nullptr) << name;
    EXPECT_EQ(array->GetNumberOfTuples(), 1) << name;
    EXPECT_EQ(array->GetNumberOfComponents(), 1) << name;
    EXPECT_TRUE(vtkDoubleArray::SafeDownCast(array)) << name;
  }
  EXPECT_EQ(fields->GetNumberOfArrays(), 13);
  EXPECT_EQ(fields->GetArray("SunElevationDegrees")->GetComponent(0, 0), 2.0);
  EXPECT_EQ(fields->GetArray("SunAzimuthDegrees")->GetComponent(0, 0), 270.0);
  EXPECT_EQ(fields->GetArray("Exposure")->GetComponent(0, 0), 25.0);
  EXPECT_EQ(fields->GetArray("SceneAltitudeMetres")->GetComponent(0, 0), 1500.0);
  EXPECT_EQ(fields->GetArray("ScatteringOrders")->GetComponent(0, 0), 2.0);
  EXPECT_EQ(fields->GetArray("SunDisc")->GetComponent(0, 0), 0.0);

  // Read back into another sky: the same parameters.
  vtkNew<vtkNimbusSky> copy;
  EXPECT_EQ(fields->GetArray("UpAxis")->GetComponent(0, 0), 1.0);
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(fields, copy), 13);
  ExpectSameSky(dome->GetSky(), copy);

  // A second update replaces the arrays instead of adding more.
  dome->SetExposure(5.0);
  dome->Update();
  fields = dome->GetOutput()->GetFieldData();
  EXPECT_EQ(fields->GetNumberOfArrays(), 13);
  EXPECT_EQ(fields->GetArray("Exposure")->GetComponent(0, 0), 5.0);
}

TEST(SkyDomeParameters, MissingArraysMeanDefaults)
{
  vtkNew<vtkNimbusSky> defaults;
  vtkNew<vtkNimbusSky> sky;
  sky->SetPreset(vtkNimbusSky::Twilight);
  sky->SetExposure(400.0);
  sky->SunDiscOff();
  sky->SetScatteringOrders(7);

  vtkNew<vtkFieldData> empty;
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(empty, sky), 0);
  ExpectSameSky(sky, defaults);

  vtkNew<vtkFieldData> one;
  vtkNew<vtkDoubleArray> elevation;
  elevation->SetName("SunElevationDegrees");
  elevation->InsertNextValue(12.5);
  one->AddArray(elevation);
  sky->SetExposure(400.0);
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(one, sky), 1);
  EXPECT_EQ(sky->GetSunElevationDegrees(), 12.5);
  EXPECT_EQ(sky->GetExposure(), defaults->GetExposure());

  // An empty array counts as missing; a null field data too.
  vtkNew<vtkDoubleArray> emptyArray;
  emptyArray->SetName("Exposure");
  one->AddArray(emptyArray);
  sky->SetExposure(400.0);
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(one, sky), 1);
  EXPECT_EQ(sky->GetExposure(), defaults->GetExposure());
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(nullptr, sky), 0);
  ExpectSameSky(sky, defaults);
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(one, nullptr), 0);
}

// Turbidity and MieScatteringPerMetre are one setting on the sky; on the dome source
// (ParaView's properties) a MieScatteringPerMetre >= 0 overrides Turbidity whatever the
// order of the calls, and field data written before Turbidity existed (only
// MieScatteringPerMetre) gives that aerosol back.
TEST(SkyDomeParameters, TurbidityAndMieScattering)
{
  vtkNew<vtkNimbusSky> sky;
  EXPECT_EQ(sky->GetTurbidity(), 2.0);
  // 0.9 * 0.025 (T - 1) / 1200 m (Atmosphere.h: MieScatteringFromTurbidity)
  EXPECT_NEAR(sky->GetMieScatteringPerMetre(), 1.875e-5, 1e-9);
  sky->SetTurbidity(5.0);
  EXPECT_NEAR(sky->GetMieScatteringPerMetre(), 7.5e-5, 1e-9);
  sky->SetMieScatteringPerMetre(2.0e-5);
  EXPECT_NEAR(sky->GetTurbidity(), 2.0667, 0.0005);
  sky->SetTurbidity(100.0); // clamped
  EXPECT_EQ(sky->GetTurbidity(), 10.0);
  sky->SetTurbidity(std::nan("")); // refused (an error), value kept
  EXPECT_EQ(sky->GetTurbidity(), 10.0);

  vtkNew<vtkNimbusSkyDomeSource> dome;
  dome->SetMieScatteringPerMetre(6.0e-5);
  dome->SetTurbidity(4.0);
  EXPECT_EQ(dome->GetSky()->GetMieScatteringPerMetre(), 6.0e-5);
  dome->SetMieScatteringPerMetre(-1.0); // back to Turbidity
  EXPECT_EQ(dome->GetSky()->GetTurbidity(), 4.0);
  dome->SetTurbidity(3.0);
  EXPECT_EQ(dome->GetSky()->GetTurbidity(), 3.0);

  vtkNew<vtkFieldData> old;
  vtkNew<vtkDoubleArray> mie;
  mie->SetName("MieScatteringPerMetre");
  mie->InsertNextValue(2.0e-5);
  old->AddArray(mie);
  vtkNew<vtkNimbusSky> restored;
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(old, restored), 1);
  EXPECT_EQ(restored->GetMieScatteringPerMetre(), 2.0e-5);

  vtkNew<vtkFieldData> onlyTurbidity;
  vtkNew<vtkDoubleArray> turbidity;
  turbidity->SetName("Turbidity");
  turbidity->InsertNextValue(4.0);
  onlyTurbidity->AddArray(turbidity);
  EXPECT_EQ(vtkNimbusSkyDomeSource::ApplySkyParameters(onlyTurbidity, restored), 1);
  EXPECT_EQ(restored->GetTurbidity(), 4.0);
}
