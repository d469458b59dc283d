// Uses the installed Nimbus modules: generates a small metaball cloud and asks for
// the noon sun's colour. Exit code 0 when both give sensible numbers.
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusSunlight.h"
#include "vtkPointData.h"

#include <iostream>

int main()
{
  vtkNew<vtkNimbusMetaballCloudSource> cloud;
  cloud->SetDimensions(32, 32, 24);
  cloud->Update();
  double range[2] = { 0.0, 0.0 };
  cloud->GetOutput()->GetPointData()->GetArray("density")->GetRange(range);

  vtkNew<vtkNimbusSunlight> sun;
  sun->SetSunElevationDegrees(60.0);
  double rgb[3];
  sun->GetColor(rgb);

  std::cout << "points " << cloud->GetOutput()->GetNumberOfPoints() << ", density range ["
            << range[0] << ", " << range[1] << "], noon sun rgb (" << rgb[0] << ", " << rgb[1]
            << ", " << rgb[2] << ")\n";
  const bool ok = cloud->GetOutput()->GetNumberOfPoints() == 32 * 32 * 24 && range[0] >= 0.0 &&
    range[1] > 0.5 && rgb[0] > 0.5 && rgb[2] > 0.3;
  return ok ? 0 : 1;
}
