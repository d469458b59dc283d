// nimbus-render: render a Nimbus scene with a reference renderer.
//
//   nimbus-render SCENE.json [--mode single|path] [--output PREFIX]
//     single scattering: [--step-scale S] [--tolerance T] [--max-refinements K]
//     path tracing:      [--min-spp N] [--max-spp N] [--target-error E] [--max-order K] [--seed S]
//     [--threads N] [--exposure X]
//
// Writes PREFIX.pfm (linear float RGB), PREFIX.vti (the same as vtkImageData,
// with "standard_error" for path tracing) and PREFIX.png (exposure, clip, sRGB),
// then prints one JSON line with the render's figures.
//
// Exit status: 0 on success; 1 when the scene cannot be read or rendered (the
// message says why: a bad value with its key path, a size over the memory
// budget, a render with NaN or infinite pixels); 2 for bad options. Nothing
// aborts or leaves an uncaught exception.
#include "FloatImage.h"
#include "MemoryBudget.h"
#include "vtkNimbusReferenceRenderer.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkXMLImageDataWriter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void Usage(std::ostream& os)
{
  os << "usage: nimbus-render SCENE.json [--mode single|path] [--output PREFIX]\n"
        "  single scattering: [--step-scale S] [--tolerance T] [--max-refinements K]\n"
        "  path tracing:      [--min-spp N] [--max-spp N] [--target-error E] [--max-order K]"
        " [--seed S]\n"
        "  [--threads N] [--exposure X]\n";
}

bool Number(const char* text, double& value)
{
  char* end = nullptr;
  value = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(value);
}

double FieldValue(vtkImageData* image, const char* name)
{
  vtkDataArray* array = image->GetFieldData()->GetArray(name);
  return array ? array->GetTuple1(0) : 0.0;
}

int Run(int argc, char* argv[]);
}

int main(int argc, char* argv[])
{
  try
  {
    return Run(argc, argv);
  }
  catch (const std::exception& error)
  {
    std::cerr << "nimbus-render: " << error.what() << "\n";
  }
  catch (...)
  {
    std::cerr << "nimbus-render: failed (unknown exception)\n";
  }
  return 1;
}

namespace
{
int Run(int argc, char* argv[])
{
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")
  {
    Usage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? 2 : 0;
  }
  vtkNew<vtkNimbusReferenceRenderer> renderer;
  renderer->SetSceneFileName(argv[1]);
  std::string output = "nimbus-render";
  double exposure = 6.0;
  for (int i = 2; i < argc; ++i)
  {
    const std::string option = argv[i];
    if (i + 1 >= argc)
    {
      std::cerr << "nimbus-render: " << option << " needs a value\n";
      return 2;
    }
    const char* value = argv[++i];
    double number = 0.0;
    const bool numeric = Number(value, number);
    if (option == "--mode" && std::string(value) == "single")
    {
      renderer->SetModeToSingleScattering();
    }
    else if (option == "--mode" && std::string(value) == "path")
    {
      renderer->SetModeToPathTracing();
    }
    else if (option == "--output")
    {
      output = value;
    }
    else if (option == "--step-scale" && numeric && number > 0.0)
    {
      renderer->SetStepScale(number);
    }
    else if (option == "--tolerance" && numeric && number > 0.0)
    {
      renderer->SetRelativeTolerance(number);
    }
    else if (option == "--max-refinements" && numeric && number >= 0.0)
    {
      renderer->SetMaxRefinements(static_cast<int>(number));
    }
    else if (option == "--min-spp" && numeric && number >= 1.0)
    {
      renderer->SetMinSamplesPerPixel(static_cast<int>(number));
    }
    else if (option == "--max-spp" && numeric && number >= 1.0)
    {
      renderer->SetMaxSamplesPerPixel(static_cast<int>(number));
    }
    else if (option == "--target-error" && numeric && number >= 0.0)
    {
      renderer->SetTargetRelativeError(number);
    }
    else if (option == "--max-order" && numeric && number >= 0.0)
    {
      renderer->SetMaxScatteringOrder(static_cast<int>(number));
    }
    else if (option == "--seed" && numeric)
    {
      renderer->SetSeed(static_cast<int>(number));
    }
    else if (option == "--threads" && numeric && number >= 0.0)
    {
      renderer->SetNumberOfThreads(static_cast<int>(number));
    }
    else if (option == "--exposure" && numeric && number > 0.0)
    {
      exposure = number;
    }
    else
    {
      std::cerr << "nimbus-render: bad option or value: " << option << " " << value << "\n";
      Usage(std::cerr);
      return 2;
    }
  }

  renderer->Update();
  vtkImageData* image = renderer->GetOutput();
  auto* radiance = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("radiance"));
  if (!radiance)
  {
    std::cerr << "nimbus-render: rendering failed (see the errors above)\n";
    return 1;
  }
  int dims[3];
  image->GetDimensions(dims);
  // This program's own copies: the linear image (3 floats a pixel), the tone-mapped
  // bytes and their VTK array (3 bytes a pixel each).
  const std::string overBudget = nimbus::OverBudgetMessage("the output copies",
    (3.0 * sizeof(float) + 6.0) * static_cast<double>(dims[0]) * dims[1],
    static_cast<double>(nimbus::DefaultMemoryBudgetBytes()));
  if (!overBudget.empty())
  {
    std::cerr << "nimbus-render: " << overBudget << "\n";
    return 1;
  }
  nimbus::FloatImage linear(dims[0], dims[1]);
  std::copy(
    radiance->GetPointer(0), radiance->GetPointer(0) + linear.Pixels.size(), linear.Pixels.begin());
  // The renderer refuses non-finite pixels; checked again here, where files are written.
  const std::string nonFinite = nimbus::NonFiniteMessage(linear);
  if (!nonFinite.empty())
  {
    std::cerr << "nimbus-render: the render has " << nonFinite << "; nothing written\n";
    return 1;
  }

  try
  {
    linear.WritePFM(output + ".pfm");
  }
  catch (const std::exception& error)
  {
    std::cerr << "nimbus-render: " << error.what() << "\n";
    return 1;
  }
  vtkNew<vtkXMLImageDataWriter> vtiWriter;
  vtiWriter->SetFileName((output + ".vti").c_str());
  vtiWriter->SetInputData(image);
  if (!vtiWriter->Write())
  {
    std::cerr << "nimbus-render: cannot write " << output << ".vti\n";
    return 1;
  }
  const std::vector<unsigned char> bytes = nimbus::ToneMap(linear, exposure);
  vtkNew<vtkImageData> display;
  display->SetDimensions(dims[0], dims[1], 1);
  vtkNew<vtkUnsignedCharArray> rgb;
  rgb->SetNumberOfComponents(3);
  rgb->SetNumberOfTuples(static_cast<vtkIdType>(dims[0]) * dims[1]);
  std::copy(bytes.begin(), bytes.end(), rgb->GetPointer(0));
  display->GetPointData()->SetScalars(rgb);
  vtkNew<vtkPNGWriter> pngWriter;
  pngWriter->SetFileName((output + ".png").c_str());
  pngWriter->SetInputData(display);
  pngWriter->Write();
  if (pngWriter->GetErrorCode() != 0)
  {
    std::cerr << "nimbus-render: cannot write " << output << ".png\n";
    return 1;
  }

  std::cout << "{\"scene\": \"" << argv[1] << "\", \"mode\": \""
            << (renderer->GetMode() == vtkNimbusReferenceRenderer::SINGLE_SCATTERING ? "single"
                                                                                     : "path")
            << "\", \"width\": " << dims[0] << ", \"height\": " << dims[1]
            << ", \"seconds\": " << FieldValue(image, "RenderSeconds")
            << ", \"estimated_relative_error\": " << FieldValue(image, "EstimatedRelativeError")
            << ", \"samples_per_pixel\": " << FieldValue(image, "SamplesPerPixel")
            << ", \"output\": \"" << output << "\"}" << std::endl;
  return 0;
}
}
