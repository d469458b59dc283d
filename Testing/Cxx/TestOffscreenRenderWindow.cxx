// vtkNimbusOffscreenRenderWindow: rendering with no X server (DISPLAY is removed first).
// The run-time selection (--offscreen, NIMBUS_OFFSCREEN), the factory override, pixels
// read back after a render and after a resize, two windows taking turns, and the report,
// on EGL and on OSMesa (where the build has it); an EGL window and an OSMesa window taking
// turns; OSMesa taken where no EGL context can be made (run with libglvnd's EGL vendors
// hidden: offscreen.RenderWindow.no-egl).
#include "vtkNimbusOffscreenRenderWindow.h"

#include "vtkActor.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkUnsignedCharArray.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace
{
// A red sphere in the middle of a blue-grey background.
struct Scene
{
  vtkSmartPointer<vtkRenderWindow> Window;
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkSphereSource> Sphere;
  vtkNew<vtkPolyDataMapper> Mapper;
  vtkNew<vtkActor> Actor;

  Scene(int width, int height, double red)
  {
    this->Window = vtkSmartPointer<vtkRenderWindow>::New();
    this->Window->SetSize(width, height);
    this->Window->SetOffScreenRendering(1);
    this->Window->AddRenderer(this->Renderer);
    this->Renderer->SetBackground(0.25, 0.5, 0.75);
    this->Sphere->SetRadius(0.5);
    this->Mapper->SetInputConnection(this->Sphere->GetOutputPort());
    this->Actor->SetMapper(this->Mapper);
    this->Actor->GetProperty()->SetColor(red, 0.0, 0.0);
    this->Actor->GetProperty()->SetAmbient(1.0);
    this->Actor->GetProperty()->SetDiffuse(0.0);
    this->Renderer->AddActor(this->Actor);
    this->Renderer->ResetCamera();
  }

  // RGB at (x, y), read back from the last render.
  std::vector<int> Pixel(int x, int y)
  {
    vtkNew<vtkUnsignedCharArray> pixels;
    this->Window->GetPixelData(x, y, x, y, 0, pixels);
    return { pixels->GetValue(0), pixels->GetValue(1), pixels->GetValue(2) };
  }
};

void ExpectNear(const std::vector<int>& pixel, int r, int g, int b)
{
  EXPECT_NEAR(pixel[0], r, 2);
  EXPECT_NEAR(pixel[1], g, 2);
  EXPECT_NEAR(pixel[2], b, 2);
}
}

TEST(OffscreenRenderWindow, RequestParsing)
{
  ::unsetenv("NIMBUS_OFFSCREEN");
  vtkNimbusOffscreenRenderWindow::RemoveFactory();
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), 0);
  ::setenv("NIMBUS_OFFSCREEN", "0", 1);
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), 0);
  ::setenv("NIMBUS_OFFSCREEN", "", 1);
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), 0);
  EXPECT_FALSE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
  ::setenv("NIMBUS_OFFSCREEN", "glx", 1);
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), -1);
  EXPECT_FALSE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
  ::setenv("NIMBUS_OFFSCREEN", "osmesa", 1);
  if (vtkNimbusOffscreenRenderWindow::HasOSMesa())
  {
    EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), 1);
    EXPECT_TRUE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
    EXPECT_EQ(vtkNimbusOffscreenRenderWindow::GetDefaultRequestedContextAPI(),
      vtkNimbusOffscreenRenderWindow::OSMesaOnly);
    vtkNew<vtkNimbusOffscreenRenderWindow> window;
    EXPECT_EQ(window->GetRequestedContextAPI(), vtkNimbusOffscreenRenderWindow::OSMesaOnly);
    vtkNimbusOffscreenRenderWindow::RemoveFactory();
  }
  else
  {
    EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), -1);
    EXPECT_FALSE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
  }
  ::setenv("NIMBUS_OFFSCREEN", "egl", 1);
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallFactoryIfRequested(), 1);
  EXPECT_TRUE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::GetDefaultRequestedContextAPI(),
    vtkNimbusOffscreenRenderWindow::EGLThenOSMesa);
  vtkNimbusOffscreenRenderWindow::RemoveFactory();
  ::unsetenv("NIMBUS_OFFSCREEN");

  // --offscreen leaves argv (every occurrence) and installs the override.
  std::string words[] = { "prog", "--offscreen", "--size", "--offscreen", "3" };
  char* argv[] = { &words[0][0], &words[1][0], &words[2][0], &words[3][0], &words[4][0], nullptr };
  int argc = 5;
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv), 1);
  ASSERT_EQ(argc, 3);
  EXPECT_EQ(std::string(argv[1]), "--size");
  EXPECT_EQ(std::string(argv[2]), "3");
  EXPECT_EQ(argv[3], nullptr);
  EXPECT_TRUE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());

  // Without the flag or the variable nothing is installed.
  vtkNimbusOffscreenRenderWindow::RemoveFactory();
  int plainArgc = 1;
  EXPECT_EQ(vtkNimbusOffscreenRenderWindow::InstallIfRequested(plainArgc, argv), 0);
  EXPECT_EQ(plainArgc, 1);
  EXPECT_FALSE(vtkNimbusOffscreenRenderWindow::IsFactoryInstalled());
}

TEST(OffscreenRenderWindow, FactoryOverride)
{
  vtkNimbusOffscreenRenderWindow::InstallFactory();
  vtkNimbusOffscreenRenderWindow::InstallFactory(); // idempotent
  vtkSmartPointer<vtkRenderWindow> window = vtkSmartPointer<vtkRenderWindow>::New();
  ASSERT_NE(window, nullptr);
  EXPECT_TRUE(window->IsA("vtkNimbusOffscreenRenderWindow")) << window->GetClassName();
  vtkNew<vtkRenderWindow> viaNew;
  EXPECT_TRUE(viaNew->IsA("vtkNimbusOffscreenRenderWindow")) << viaNew->GetClassName();
  // No X interactor either (it opens the display when its window first renders).
  vtkNew<vtkRenderWindowInteractor> interactor;
  EXPECT_TRUE(interactor->IsA("vtkGenericRenderWindowInteractor")) << interactor->GetClassName();
  interactor->SetRenderWindow(window);
  window->Render();

  vtkNimbusOffscreenRenderWindow::RemoveFactory();
  vtkSmartPointer<vtkRenderWindow> other = vtkSmartPointer<vtkRenderWindow>::New();
  ASSERT_NE(other, nullptr); // VTK's own (X) window: made, never shown
  EXPECT_FALSE(other->IsA("vtkNimbusOffscreenRenderWindow"));
  vtkNimbusOffscreenRenderWindow::InstallFactory();
}

// The tests below on each API: EGL only, OSMesa only.
class OffscreenAPI : public ::testing::TestWithParam<int>
{
protected:
  void SetUp() override
  {
    if (GetParam() == vtkNimbusOffscreenRenderWindow::OSMesaOnly &&
      !vtkNimbusOffscreenRenderWindow::HasOSMesa())
    {
      GTEST_SKIP() << "this build has no OSMesa";
    }
    vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(GetParam());
    vtkNimbusOffscreenRenderWindow::InstallFactory();
  }
  void TearDown() override
  {
    vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(
      vtkNimbusOffscreenRenderWindow::EGLThenOSMesa);
  }
  bool OnOSMesa() const { return GetParam() == vtkNimbusOffscreenRenderWindow::OSMesaOnly; }
};

TEST_P(OffscreenAPI, RendersAndReadsBack)
{
  Scene scene(64, 48, 1.0);
  scene.Window->Render();
  auto* window = vtkNimbusOffscreenRenderWindow::SafeDownCast(scene.Window);
  ASSERT_NE(window, nullptr);
  EXPECT_TRUE(window->IsCurrent());
  EXPECT_EQ(window->SupportsOpenGL(), 1);
  EXPECT_NE(window->GetGenericContext(), nullptr);
  EXPECT_EQ(std::string(window->GetContextAPI()), OnOSMesa() ? "OSMesa" : "EGL");
  EXPECT_EQ(std::string(window->GetEGLPlatform()).empty(), OnOSMesa());
  ExpectNear(scene.Pixel(32, 24), 255, 0, 0);  // the sphere
  ExpectNear(scene.Pixel(1, 1), 64, 128, 191); // the background
  ExpectNear(scene.Pixel(62, 46), 64, 128, 191);

  // A new size: a new pbuffer (OSMesa buffer), the image follows.
  scene.Window->SetSize(100, 30);
  scene.Window->Render();
  EXPECT_EQ(scene.Window->GetSize()[0], 100);
  ExpectNear(scene.Pixel(50, 15), 255, 0, 0);
  ExpectNear(scene.Pixel(98, 28), 64, 128, 191);
  ExpectNear(scene.Pixel(2, 15), 64, 128, 191);

  const std::string report = scene.Window->ReportCapabilities();
  EXPECT_NE(report.find(OnOSMesa() ? "OSMesa library: " : "EGL platform: "), std::string::npos)
    << report;
  EXPECT_NE(report.find("OpenGL renderer string"), std::string::npos) << report;
  // Which display (library) and GL renderer this machine gave (logged for the record).
  const std::size_t extensions = report.find("OpenGL extensions");
  std::cout << report.substr(0, extensions) << std::flush;
}

TEST_P(OffscreenAPI, TwoWindowsTakeTurns)
{
  Scene first(40, 40, 1.0);
  Scene second(50, 30, 0.5);
  for (int round = 0; round < 2; ++round)
  {
    first.Window->Render();
    second.Window->Render();
    ExpectNear(first.Pixel(20, 20), 255, 0, 0);
    ExpectNear(second.Pixel(25, 15), 128, 0, 0);
    ExpectNear(second.Pixel(1, 1), 64, 128, 191);
  }
  // One window gone, the other renders on (the EGL display is shared).
  first.Window = nullptr;
  second.Window->Render();
  ExpectNear(second.Pixel(25, 15), 128, 0, 0);
}

INSTANTIATE_TEST_SUITE_P(OffscreenRenderWindow, OffscreenAPI,
  ::testing::Values(
    vtkNimbusOffscreenRenderWindow::EGLOnly, vtkNimbusOffscreenRenderWindow::OSMesaOnly),
  [](const ::testing::TestParamInfo<int>& info)
  { return info.param == vtkNimbusOffscreenRenderWindow::OSMesaOnly ? "OSMesa" : "EGL"; });

// libglvnd has one current API per thread: each window lets go of the other's.
TEST(OffscreenRenderWindow, EGLAndOSMesaTakeTurns)
{
  if (!vtkNimbusOffscreenRenderWindow::HasOSMesa())
  {
    GTEST_SKIP() << "this build has no OSMesa";
  }
  vtkNimbusOffscreenRenderWindow::InstallFactory();
  vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(
    vtkNimbusOffscreenRenderWindow::EGLOnly);
  Scene egl(40, 40, 1.0);
  vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(
    vtkNimbusOffscreenRenderWindow::OSMesaOnly);
  Scene osmesa(50, 30, 0.5);
  vtkNimbusOffscreenRenderWindow::SetDefaultRequestedContextAPI(
    vtkNimbusOffscreenRenderWindow::EGLThenOSMesa);
  for (int round = 0; round < 2; ++round)
  {
    egl.Window->Render();
    osmesa.Window->Render();
    ExpectNear(egl.Pixel(20, 20), 255, 0, 0);
    ExpectNear(osmesa.Pixel(25, 15), 128, 0, 0);
    ExpectNear(osmesa.Pixel(1, 1), 64, 128, 191);
  }
  EXPECT_EQ(
    std::string(vtkNimbusOffscreenRenderWindow::SafeDownCast(egl.Window)->GetContextAPI()), "EGL");
  EXPECT_EQ(
    std::string(vtkNimbusOffscreenRenderWindow::SafeDownCast(osmesa.Window)->GetContextAPI()),
    "OSMesa");
}

// Where no EGL context can be made, the default (NIMBUS_OFFSCREEN=egl, --offscreen) takes
// OSMesa. Skipped where EGL works (every run but offscreen.RenderWindow.no-egl).
TEST(OffscreenRenderWindow, FallsBackToOSMesa)
{
  vtkNimbusOffscreenRenderWindow::InstallFactory();
  vtkNew<vtkNimbusOffscreenRenderWindow> probe;
  probe->SetRequestedContextAPI(vtkNimbusOffscreenRenderWindow::EGLOnly);
  probe->GlobalWarningDisplayOff(); // its error is expected here
  probe->Initialize();
  const bool eglWorks = std::string(probe->GetContextAPI()) == "EGL";
  probe->GlobalWarningDisplayOn();
  if (eglWorks)
  {
    GTEST_SKIP() << "EGL works here: nothing to fall back from";
  }
  if (!vtkNimbusOffscreenRenderWindow::HasOSMesa())
  {
    GTEST_SKIP() << "no EGL here and this build has no OSMesa";
  }
  Scene scene(64, 48, 1.0);
  scene.Window->Render();
  auto* window = vtkNimbusOffscreenRenderWindow::SafeDownCast(scene.Window);
  ASSERT_NE(window, nullptr);
  EXPECT_EQ(window->GetRequestedContextAPI(), vtkNimbusOffscreenRenderWindow::EGLThenOSMesa);
  EXPECT_EQ(std::string(window->GetContextAPI()), "OSMesa");
  ExpectNear(scene.Pixel(32, 24), 255, 0, 0);
  ExpectNear(scene.Pixel(1, 1), 64, 128, 191);
}

int main(int argc, char* argv[])
{
  // No X: whatever this test renders comes through EGL or OSMesa.
  ::unsetenv("DISPLAY");
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
