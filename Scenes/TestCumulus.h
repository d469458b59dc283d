// The metaball cumulus that the cloud mapper's tests (Testing/Cxx) and benchmarks
// (Benchmarks/) render (3 km wide, base 1 km, top about 2.8 km;
// vtkNimbusMetaballCloudSource), on an nx x ny x nz grid. A copy of the source's output
// (the source is gone on return). Header-only, in Scenes/ so that neither the tests nor
// the benchmarks include the other's files; a user of it links Nimbus::Filters.
#ifndef NimbusTestCumulus_h
#define NimbusTestCumulus_h

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkSmartPointer.h"

namespace nimbus
{
namespace testing
{
inline vtkSmartPointer<vtkImageData> TestCumulus(int nx, int ny, int nz, int seed = 1)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  source->SetDimensions(nx, ny, nz);
  source->SetBounds(-1500, 1500, -1500, 1500, 800, 2800);
  source->SetSeed(seed);
  source->SetFootprintRadius(700);
  source->SetBaseBallRadiusRange(350, 600);
  source->SetTowerHeight(600);
  source->SetBaseHeight(1000);
  source->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(source->GetOutput());
  return image;
}
} // namespace testing
} // namespace nimbus

#endif
