#include "ImageComparison.h"

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGReader.h"
#include "vtkPointData.h"
#include "vtkTesting.h"
#include "vtkUnsignedCharArray.h"
#include <vtksys/SystemTools.hxx>

#include <cmath>
#include <fstream>

namespace nimbus
{
namespace testing
{

namespace
{
bool ReadPNG(const std::string& path, vtkImageData* image)
{
  if (!std::ifstream(path).good())
  {
    return false;
  }
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  image->DeepCopy(reader->GetOutput());
  return image->GetNumberOfPoints() > 0;
}
}

bool CompareImageFiles(const std::string& testPngPath, const std::string& baselinePngPath,
  const std::string& outputDirPath, const ImageComparisonLimits& limits, std::ostream& log)
{
  // Absolute paths: vtkTesting prefixes relative ones with its data root.
  const std::string testPng = vtksys::SystemTools::CollapseFullPath(testPngPath);
  const std::string baselinePng = vtksys::SystemTools::CollapseFullPath(baselinePngPath);
  const std::string outputDir = vtksys::SystemTools::CollapseFullPath(outputDirPath);
  vtkNew<vtkImageData> test, baseline;
  if (!ReadPNG(testPng, test))
  {
    log << "image comparison: cannot read the test image " << testPng << "\n";
    return false;
  }
  if (!ReadPNG(baselinePng, baseline))
  {
    log << "image comparison: no baseline " << baselinePng << "; look at " << testPng
        << " and copy it there if it is right\n";
    return false;
  }
  int testDims[3], baselineDims[3];
  test->GetDimensions(testDims);
  baseline->GetDimensions(baselineDims);
  if (testDims[0] != baselineDims[0] || testDims[1] != baselineDims[1])
  {
    log << "image comparison: size " << testDims[0] << "x" << testDims[1]
        << " differs from the baseline's " << baselineDims[0] << "x" << baselineDims[1] << "\n";
    return false;
  }

  // RMSE over the RGB channels (alpha ignored), in 8-bit units.
  auto* testPixels = vtkUnsignedCharArray::SafeDownCast(test->GetPointData()->GetScalars());
  auto* basePixels = vtkUnsignedCharArray::SafeDownCast(baseline->GetPointData()->GetScalars());
  if (!testPixels || !basePixels || testPixels->GetNumberOfComponents() < 3 ||
    basePixels->GetNumberOfComponents() < 3)
  {
    log << "image comparison: expected 8-bit RGB(A) PNGs\n";
    return false;
  }
  double sumSquares = 0.0;
  int maxDifference = 0;
  const vtkIdType pixels = testPixels->GetNumberOfTuples();
  for (vtkIdType p = 0; p < pixels; ++p)
  {
    for (int c = 0; c < 3; ++c)
    {
      const int difference =
        static_cast<int>(testPixels->GetTypedComponent(p, c)) - basePixels->GetTypedComponent(p, c);
      sumSquares += static_cast<double>(difference) * difference;
      maxDifference = std::max(maxDifference, std::abs(difference));
    }
  }
  const double rmse = std::sqrt(sumSquares / (3.0 * static_cast<double>(pixels)));

  vtkNew<vtkTesting> testing;
  for (const std::string& argument :
    { std::string("-V"), baselinePng, std::string("-T"), outputDir })
  {
    testing->AddArgument(argument.c_str());
  }
  const bool vtkPassed =
    testing->RegressionTest(testPng, limits.VTKThreshold, log) == vtkTesting::PASSED;
  const bool rmsePassed = rmse <= limits.MaxRMSE;
  log << "\nimage comparison of " << testPng << " with " << baselinePng << ": RMSE " << rmse
      << " (limit " << limits.MaxRMSE << "), max |difference| " << maxDifference << ", vtkTesting "
      << (vtkPassed ? "passed" : "FAILED") << " at threshold " << limits.VTKThreshold << "\n";
  return vtkPassed && rmsePassed;
}

} // namespace testing
} // namespace nimbus
