// nimbus-render: render a Nimbus scene with a reference renderer.
//
//   nimbus-render SCENE.json [--mode single|path] [--output PREFIX]
//     single scattering: [--step-scale S] [--tolerance T] [--max-refinements K]
//     path tracing:      [--min-spp N] [--max-spp N] [--target-error E] [--max-order K] [--seed S]
//                        [--time-limit SECONDS] [--target-image-error E]
//     [--threads N] [--exposure X] [--progress on|off]
//
// On a terminal (or with --progress on) a progress line on stderr shows the fraction
// done, the time, and for path tracing the image-wide relative error after the last
// round of samples and an estimate of the time left: to the image target when one is
// set (the error falls as 1/sqrt(time)), else to the last round.
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

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkXMLImageDataWriter.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <unistd.h>

namespace
{
void Usage(std::ostream& os)
{
  os << "usage: nimbus-render SCENE.json [--mode single|path] [--output PREFIX]\n"
        "  single scattering: [--step-scale S] [--tolerance T] [--max-refinements K]\n"
        "  path tracing:      [--min-spp N] [--max-spp N] [--target-error E] [--max-order K]"
        " [--seed S]\n"
        "                     [--time-limit SECONDS] [--target-image-error E]\n"
        "  [--threads N] [--exposure X] [--progress on|off]\n";
}

/// An integer option in [low, high] (a cast of anything else would be undefined).
bool Integer(const char* text, double low, double high, int& value)
{
  char* end = nullptr;
  const double number = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(number >= low && number <= high) ||
    number != std::floor(number))
  {
    return false;
  }
  value = static_cast<int>(number);
  return true;
}

/// The progress line: fraction, time, and for path tracing the error and time left.
struct ProgressLine
{
  vtkNimbusReferenceRenderer* Renderer = nullptr;
  std::chrono::steady_clock::time_point Start = std::chrono::steady_clock::now();
  double LastPrinted = -1.0;

  static std::string Duration(double seconds)
  {
    char text[32];
    if (!std::isfinite(seconds) || seconds < 0.0)
    {
      return "?";
    }
    if (seconds < 90.0)
    {
      std::snprintf(text, sizeof(text), "%.0f s", seconds);
    }
    else if (seconds < 5400.0)
    {
      std::snprintf(text, sizeof(text), "%.1f min", seconds / 60.0);
    }
    else
    {
      std::snprintf(text, sizeof(text), "%.1f h", seconds / 3600.0);
    }
    return text;
  }

  void Print(double fraction)
  {
    const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - this->Start).count();
    if (fraction < 1.0 && elapsed - this->LastPrinted < 0.25)
    {
      return; // at most four lines a second
    }
    this->LastPrinted = elapsed;
    const int width = 30;
    const int filled =
      static_cast<int>(std::lround(std::min(1.0, std::max(0.0, fraction)) * width));
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(static_cast<std::size_t>(width), '.');
    std::string detail;
    const double error = this->Renderer->GetCurrentImageRelativeError();
    if (this->Renderer->GetMode() == vtkNimbusReferenceRenderer::PATH_TRACING && error > 0.0)
    {
      char text[96];
      std::snprintf(text, sizeof(text), "  %.0f spp  error %.2f %%",
        this->Renderer->GetCurrentSamplesPerPixel(), 100.0 * error);
      detail = text;
      const double target = this->Renderer->GetTargetImageRelativeError();
      double left = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : -1.0;
      if (target > 0.0)
      {
        left = std::min(left, elapsed * ((error / target) * (error / target) - 1.0));
        char goal[48];
        std::snprintf(goal, sizeof(goal), " (target %.2f %%)", 100.0 * target);
        detail += goal;
      }
      detail += "  left ~" + Duration(std::max(0.0, left));
    }
    std::fprintf(stderr, "\r[%s] %3.0f %%  %s%s   ", bar.c_str(), 100.0 * fraction,
      Duration(elapsed).c_str(), detail.c_str());
    std::fflush(stderr);
  }

  static void OnProgress(vtkObject*, unsigned long, void* clientData, void* callData)
  {
    static_cast<ProgressLine*>(clientData)->Print(*static_cast<double*>(callData));
  }
};

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
  bool showProgress = isatty(STDERR_FILENO) != 0;
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
    int integer = 0;
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
    else if (option == "--max-refinements" && Integer(value, 0, 64, integer))
    {
      renderer->SetMaxRefinements(integer);
    }
    else if (option == "--min-spp" && Integer(value, 1, 2147483647, integer))
    {
      renderer->SetMinSamplesPerPixel(integer);
    }
    else if (option == "--max-spp" && Integer(value, 1, 2147483647, integer))
    {
      renderer->SetMaxSamplesPerPixel(integer);
    }
    else if (option == "--target-error" && numeric && number >= 0.0)
    {
      renderer->SetTargetRelativeError(number);
    }
    else if (option == "--max-order" && Integer(value, 0, 2147483647, integer))
    {
      renderer->SetMaxScatteringOrder(integer);
    }
    else if (option == "--seed" && Integer(value, -2147483648.0, 2147483647, integer))
    {
      renderer->SetSeed(integer);
    }
    else if (option == "--threads" && Integer(value, 0, 4096, integer))
    {
      renderer->SetNumberOfThreads(integer);
    }
    else if (option == "--time-limit" && numeric && number >= 0.0 && number <= 1.0e9)
    {
      renderer->SetTimeLimitSeconds(number);
    }
    else if (option == "--target-image-error" && numeric && number >= 0.0 && number <= 1.0)
    {
      renderer->SetTargetImageRelativeError(number);
    }
    else if (option == "--progress" && (std::string(value) == "on" || std::string(value) == "off"))
    {
      showProgress = std::string(value) == "on";
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

  ProgressLine progressLine;
  progressLine.Renderer = renderer;
  vtkNew<vtkCallbackCommand> progressCallback;
  progressCallback->SetCallback(&ProgressLine::OnProgress);
  progressCallback->SetClientData(&progressLine);
  if (showProgress)
  {
    renderer->AddObserver(vtkCommand::ProgressEvent, progressCallback);
  }
  renderer->Update();
  if (showProgress)
  {
    std::fprintf(stderr, "\n");
  }
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
            << ", \"stopped_at_time_limit\": "
            << (FieldValue(image, "StoppedAtTimeLimit") > 0.0 ? "true" : "false")
            << ", \"reached_image_target\": "
            << (FieldValue(image, "ReachedImageTarget") > 0.0 ? "true" : "false")
            << ", \"estimated_seconds_to_target\": "
            << FieldValue(image, "EstimatedSecondsToTarget") << ", \"output\": \"" << output
            << "\"}" << std::endl;
  return 0;
}
}
