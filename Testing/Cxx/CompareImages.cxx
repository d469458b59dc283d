// nimbus-compare-images: the image tests' comparison as a command, for the Python tests.
//
//   nimbus-compare-images TEST.png BASELINE.png OUTPUT_DIR [--max-rmse R] [--vtk-threshold T]
//
// Exit code 0 when the images match (see ImageComparison.h for the criteria).
#include "ImageComparison.h"

#include <cstdlib>
#include <cstring>
#include <iostream>

int main(int argc, char* argv[])
{
  if (argc < 4)
  {
    std::cerr << "usage: nimbus-compare-images TEST.png BASELINE.png OUTPUT_DIR"
                 " [--max-rmse R] [--vtk-threshold T]\n";
    return 2;
  }
  nimbus::testing::ImageComparisonLimits limits;
  for (int i = 4; i + 1 < argc; i += 2)
  {
    if (std::strcmp(argv[i], "--max-rmse") == 0)
    {
      limits.MaxRMSE = std::atof(argv[i + 1]);
    }
    else if (std::strcmp(argv[i], "--vtk-threshold") == 0)
    {
      limits.VTKThreshold = std::atof(argv[i + 1]);
    }
    else
    {
      std::cerr << "nimbus-compare-images: unknown option " << argv[i] << "\n";
      return 2;
    }
  }
  const bool same =
    nimbus::testing::CompareImageFiles(argv[1], argv[2], argv[3], limits, std::cout);
  std::cout << (same ? "images match" : "IMAGES DIFFER") << std::endl;
  return same ? 0 : 1;
}
