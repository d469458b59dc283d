// Checks of the lightning glow (vtkNimbusLightningGlowMapper) against its closed form.
//
//   TestLightningGlowMapper <case> <output dir>
//
// Every case looks straight down (parallel projection, 4 m per pixel) at point sources
// at the origin, glow radius R = 300 m (75 pixels), and compares pixels with the sum of
// the sources' profiles, L(b) = sigma_s I / (4 b) x (1 - (b/R)^2)^2 (Physics/Lightning.h,
// LightningGlowRadiance), in 8-bit units:
//   FaintSourcesAddUp   400 coincident sources, each below 1/500 of white (rounded away
//                       one by one in an 8-bit frame), their sum 0.3 at b = R/2;
//   FaintBesideBright   the same faint sources beside one 1000 times brighter, off the
//                       picture (the faint ones' share is not rounded away either);
//   HiddenBehindOpaque  an opaque square over half the glow, between it and the camera,
//                       hides that half; one behind the sources does not;
//   Viewport            the glow in the right half of a window twice as wide.
#include "vtkNimbusLightningGlowMapper.h"
#include "vtkNimbusOffscreenRenderWindow.h"

#include "Lightning.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPlaneSource.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace
{
constexpr int kSize = 200; // pixels per side of the glow's viewport
constexpr double kMetresPerPixel = 4.0;
constexpr double kRadius = 300.0; // glow radius, metres
constexpr double kSigma = 1e-3;   // sigma_s, 1/m
constexpr int kFaintSources = 400;

double Fade(double b)
{
  return b < 1.0 ? (1.0 - b * b) * (1.0 - b * b) : 0.0;
}

// The faint sources' intensity: their sum 0.3 at b = R/2.
double FaintIntensity()
{
  const double one = nimbus::LightningGlowRadiance(kSigma, 1.0, 0.5 * kRadius) * Fade(0.5);
  return 0.3 / (kFaintSources * one);
}

// Sources at the given points (vertices) with point data "intensity".
vtkSmartPointer<vtkPolyData> Sources(
  const std::vector<std::array<double, 3>>& where, const std::vector<double>& intensity)
{
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> verts;
  vtkNew<vtkDoubleArray> values;
  values->SetName("intensity");
  for (std::size_t i = 0; i < where.size(); ++i)
  {
    verts->InsertNextCell(1);
    verts->InsertCellPoint(points->InsertNextPoint(where[i].data()));
    values->InsertNextValue(intensity[i]);
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  data->SetVerts(verts);
  data->GetPointData()->AddArray(values);
  return data;
}

vtkSmartPointer<vtkPolyData> FaintSources()
{
  return Sources(std::vector<std::array<double, 3>>(kFaintSources, { 0.0, 0.0, 0.0 }),
    std::vector<double>(kFaintSources, FaintIntensity()));
}

struct Scene
{
  vtkNew<vtkNimbusLightningGlowMapper> Glow;
  vtkNew<vtkActor> GlowActor;
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderer> Left; // the left half beside a right-half glow: black
  vtkNew<vtkRenderWindow> Window;
  int Width = kSize;

  explicit Scene(vtkPolyData* sources, bool rightHalf = false)
  {
    this->Glow->SetInputData(sources);
    this->Glow->SetAirScatteringPerMetre(kSigma);
    this->Glow->SetGlowRadiusMetres(kRadius);
    this->Glow->SetColor(1.0, 1.0, 1.0);
    this->GlowActor->SetMapper(this->Glow);
    this->Renderer->SetBackground(0.0, 0.0, 0.0);
    this->Width = rightHalf ? 2 * kSize : kSize;
    if (rightHalf)
    {
      this->Renderer->SetViewport(0.5, 0.0, 1.0, 1.0);
      this->Left->SetViewport(0.0, 0.0, 0.5, 1.0);
      this->Left->SetBackground(0.0, 0.0, 0.0);
      this->Window->AddRenderer(this->Left);
    }
    this->Window->SetOffScreenRendering(1);
    this->Window->SetMultiSamples(0);
    this->Window->SetSize(this->Width, kSize);
    this->Window->AddRenderer(this->Renderer);
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    camera->ParallelProjectionOn();
    camera->SetParallelScale(0.5 * kSize * kMetresPerPixel);
    camera->SetPosition(0.0, 0.0, 2000.0);
    camera->SetFocalPoint(0.0, 0.0, 0.0);
    camera->SetViewUp(0.0, 1.0, 0.0);
    camera->SetClippingRange(10.0, 5000.0);
  }
  // An opaque, unlit square of the given colour at height z over [x0, x1] x [-400, 400].
  void AddSquare(double x0, double x1, double z, double r, double g, double b)
  {
    vtkNew<vtkPlaneSource> plane;
    plane->SetOrigin(x0, -400.0, z);
    plane->SetPoint1(x1, -400.0, z);
    plane->SetPoint2(x0, 400.0, z);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(plane->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(r, g, b);
    actor->GetProperty()->LightingOff();
    this->Renderer->AddActor(actor);
  }
  // Renders (the glow after the actors already added) and returns RGB bytes.
  std::vector<unsigned char> Render(const std::string& png)
  {
    this->Renderer->AddActor(this->GlowActor);
    this->Window->Render();
    vtkNew<vtkWindowToImageFilter> capture;
    capture->SetInput(this->Window);
    capture->SetInputBufferTypeToRGB();
    capture->ReadFrontBufferOff();
    capture->ShouldRerenderOff();
    capture->Update();
    vtkNew<vtkPNGWriter> writer;
    writer->SetInputConnection(capture->GetOutputPort());
    writer->SetFileName(png.c_str());
    writer->Write();
    auto* bytes =
      vtkUnsignedCharArray::SafeDownCast(capture->GetOutput()->GetPointData()->GetScalars());
    return std::vector<unsigned char>(
      bytes->GetPointer(0), bytes->GetPointer(0) + bytes->GetNumberOfValues());
  }
};

bool Check(bool condition, const std::string& what)
{
  std::cout << (condition ? "ok:   " : "FAIL: ") << what << "\n";
  return condition;
}

// The glow's pixels along the row through the sources (y = 2 m, the pixel centre), from
// b = 0.2 R to beyond R, against `sources` x L(b) in 8-bit units (within 1.5 + 1 %).
// `x0`: the first column of the glow's viewport. `channel` 0-2.
bool ProfileMatches(const std::vector<unsigned char>& rgb, int width, int x0, double intensity,
  int sources, const std::string& what, int channel = 1, int background = 0)
{
  bool ok = true;
  int checked = 0;
  std::string half; // the pixel nearest b = R/2
  for (int i = kSize / 2 - 100; i < kSize / 2; ++i)
  {
    const double x = (i + 0.5 - 0.5 * kSize) * kMetresPerPixel;
    const double y = 0.5 * kMetresPerPixel;
    const double b = std::hypot(x, y) / kRadius;
    if (b < 0.2)
    {
      continue;
    }
    const double expected = std::min(255.0,
      background +
        255.0 * sources * nimbus::LightningGlowRadiance(kSigma, intensity, b * kRadius) * Fade(b));
    const int row = kSize / 2;
    const int got = rgb[3 * (row * width + x0 + i) + channel];
    if (half.empty() && b < 0.5)
    {
      half = "at b = " + std::to_string(b) + " R: " + std::to_string(got) + " (sum " +
        std::to_string(expected) + ")";
    }
    if (std::abs(got - expected) > 1.5 + 0.01 * expected)
    {
      ok = false;
      if (++checked <= 4) // the first few, from the rim inwards
      {
        Check(false,
          what + ": at b = " + std::to_string(b) + " R the pixel is " + std::to_string(got) +
            ", the sum of the profiles " + std::to_string(expected));
      }
    }
  }
  return Check(ok, what + " (b from 0.2 R to past R; " + half + ")");
}

bool FaintSourcesAddUp(const std::string& out)
{
  Scene s(FaintSources());
  const auto rgb = s.Render(out + "/TestLightningGlowMapper_FaintSourcesAddUp.png");
  const double one =
    255.0 * nimbus::LightningGlowRadiance(kSigma, FaintIntensity(), 0.5 * kRadius) * Fade(0.5);
  bool ok = Check(one < 0.5,
    "each source adds " + std::to_string(one) + " of 255 at b = R/2 (rounded away alone)");
  ok &= ProfileMatches(rgb, kSize, 0, FaintIntensity(), kFaintSources, "400 faint sources");
  return ok;
}

bool FaintBesideBright(const std::string& out)
{
  std::vector<std::array<double, 3>> where(kFaintSources, { 0.0, 0.0, 0.0 });
  std::vector<double> intensity(kFaintSources, FaintIntensity());
  where.push_back({ 5000.0, 0.0, 0.0 }); // off the picture (and its glow)
  intensity.push_back(1000.0 * FaintIntensity());
  Scene s(Sources(where, intensity));
  const auto rgb = s.Render(out + "/TestLightningGlowMapper_FaintBesideBright.png");
  return ProfileMatches(
    rgb, kSize, 0, FaintIntensity(), kFaintSources, "400 faint sources beside a bright one");
}

bool HiddenBehindOpaque(const std::string& out)
{
  Scene s(FaintSources());
  s.AddSquare(0.0, 400.0, 100.0, 0.5, 0.0, 0.0);   // over the right half, in front
  s.AddSquare(-400.0, 0.0, -100.0, 0.0, 0.0, 0.2); // under the left half, behind
  const auto rgb = s.Render(out + "/TestLightningGlowMapper_HiddenBehindOpaque.png");
  bool hidden = true;
  for (int j = 0; j < kSize && hidden; ++j)
  {
    for (int i = kSize / 2 + 1; i < kSize && hidden; ++i)
    {
      const unsigned char* p = &rgb[3 * (j * kSize + i)];
      hidden = (p[0] == 127 || p[0] == 128) && p[1] == 0 && p[2] == 0;
    }
  }
  bool ok = Check(hidden, "the square in front hides the glow (its pixels stay 0.5, 0, 0)");
  ok &= ProfileMatches(
    rgb, kSize, 0, FaintIntensity(), kFaintSources, "the glow over the square behind (green)", 1);
  ok &= ProfileMatches(rgb, kSize, 0, FaintIntensity(), kFaintSources,
    "the glow over the square behind (blue: 51 + glow)", 2, 51);
  return ok;
}

bool Viewport(const std::string& out)
{
  Scene s(FaintSources(), true);
  const auto rgb = s.Render(out + "/TestLightningGlowMapper_Viewport.png");
  bool ok = ProfileMatches(rgb, 2 * kSize, kSize, FaintIntensity(), kFaintSources,
    "the glow in the right half of the window");
  bool leftBlack = true;
  for (int j = 0; j < kSize; ++j)
  {
    for (int i = 0; i < kSize; ++i)
    {
      leftBlack &= rgb[3 * (j * 2 * kSize + i) + 1] == 0;
    }
  }
  return ok & Check(leftBlack, "the left half (another viewport) stays black");
}
} // namespace

int main(int argc, char* argv[])
{
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  const std::map<std::string, std::function<bool(const std::string&)>> cases = {
    { "FaintSourcesAddUp", FaintSourcesAddUp }, { "FaintBesideBright", FaintBesideBright },
    { "HiddenBehindOpaque", HiddenBehindOpaque }, { "Viewport", Viewport }
  };
  if (argc != 3 || !cases.count(argv[1]))
  {
    std::cerr << "usage: TestLightningGlowMapper <case> <output dir>; cases:";
    for (const auto& entry : cases)
    {
      std::cerr << " " << entry.first;
    }
    std::cerr << "\n";
    return EXIT_FAILURE;
  }
  return cases.at(argv[1])(argv[2]) ? EXIT_SUCCESS : EXIT_FAILURE;
}
