// Stability of the shadow-view-slice mapper (vtkNimbusCloudVolumeMapper) over bad and
// extreme input: every case must end in a clear message or a finite image, and no
// exception may leave Render. Small window (64 x 48), few slices; each case renders
// in a fresh scene and reads back the mapper's float radiance (CaptureRadiance) and
// the framebuffer.
//
//   TestCloudMapperStability [case ...]   (no argument: all cases)
//
// Prints one line per case: ok/FAIL, the case, what happened.
#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkNimbusSkyDomeSource.h"
#include "vtkNimbusSunlight.h"

#include "MessageCatcher.h"
#include "TestCumulus.h"

#include "vtkCamera.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkTransform.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>
#endif

namespace
{
constexpr int kWidth = 64;
constexpr int kHeight = 48;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
// --ray-march: every case with the ray-marched method (RenderingMethod RayMarching).
int gRenderingMethod = vtkNimbusCloudVolumeMapper::ShadowViewSlicing;
const double kInf = std::numeric_limits<double>::infinity();

vtkSmartPointer<vtkImageData> MakeCloud()
{
  return nimbus::testing::TestCumulus(24, 24, 16);
}

/// What one render left: whether an exception escaped, the radiance's census and
/// range, the framebuffer's bytes.
struct Frame
{
  bool Escaped = false;
  std::string Exception;
  bool HasRadiance = false;
  std::size_t NaN = 0, Infinite = 0, Negative = 0;
  double MinRadiance = 0.0, MaxRadiance = 0.0, MeanRadiance = 0.0;
  std::vector<unsigned char> Pixels;

  bool Finite() const { return !Escaped && HasRadiance && NaN == 0 && Infinite == 0; }
  bool FiniteNonNegative() const { return Finite() && Negative == 0; }
  double MeanPixel() const
  {
    double sum = 0.0;
    for (unsigned char v : Pixels)
    {
      sum += v;
    }
    return Pixels.empty() ? 0.0 : sum / Pixels.size();
  }
  std::string Describe() const
  {
    std::ostringstream s;
    if (Escaped)
    {
      s << "EXCEPTION escaped Render: " << Exception;
      return s.str();
    }
    if (!HasRadiance)
    {
      s << "nothing drawn (no radiance), framebuffer mean " << MeanPixel();
      return s.str();
    }
    s << "radiance: " << NaN << " NaN, " << Infinite << " inf, " << Negative << " negative; range ["
      << MinRadiance << ", " << MaxRadiance << "], mean " << MeanRadiance << "; framebuffer mean "
      << MeanPixel();
    return s.str();
  }
};

struct Scene
{
  vtkNew<vtkNimbusCloudVolumeMapper> Mapper;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;
  nimbus::testing::MessageCatcher Messages{ Mapper };

  explicit Scene(vtkImageData* density)
  {
    this->Mapper->SetInputData(density);
    this->Mapper->SetRenderingMethod(gRenderingMethod);
    this->Mapper->SetExposure(4.0);
    this->Mapper->SetEncodeSrgb(true);
    this->Mapper->SetNumberOfSlices(24);
    this->Mapper->SetShadowSurfaceSize(64);
    this->Mapper->SetAtmosphereSteps(8);
    // The default multiple scattering (discrete directions), made cheap: every
    // case also passes its inputs through the solver. Without the sky light (its
    // sky model takes 1.5 s to build; ScatteringBudgetAndMethods has it).
    this->Mapper->SetMultipleScatteringOrders(4);
    this->Mapper->SetMultipleScatteringDirections(6);
    this->Mapper->SkyLightOff();
    this->Mapper->CaptureRadianceOn();
    this->Volume->SetMapper(this->Mapper);
    this->Renderer->AddVolume(this->Volume);
    this->Renderer->SetBackground(0.2, 0.3, 0.4);
    this->Window->SetOffScreenRendering(1);
    this->Window->SetMultiSamples(0);
    this->Window->SetSize(kWidth, kHeight);
    this->Window->AddRenderer(this->Renderer);
    this->LookFrom({ 0, -6000, 1500 }, { 0, 0, 1600 });
  }
  void LookFrom(std::vector<double> position, std::vector<double> focal,
    std::vector<double> up = { 0, 0, 1 }, double nearClip = 10.0, double farClip = 1e6)
  {
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    camera->SetPosition(position.data());
    camera->SetFocalPoint(focal.data());
    camera->SetViewUp(up.data());
    camera->SetViewAngle(35.0);
    camera->SetClippingRange(nearClip, farClip);
  }
  Frame Render()
  {
    Frame frame;
    vtkImageData* radiance = this->Mapper->GetRadianceImage();
    radiance->Initialize();
    try
    {
      this->Window->Render();
    }
    catch (const std::exception& error)
    {
      frame.Escaped = true;
      frame.Exception = error.what();
      return frame;
    }
    catch (...)
    {
      frame.Escaped = true;
      frame.Exception = "(not a std::exception)";
      return frame;
    }
    vtkDataArray* values = radiance->GetPointData()->GetArray("radiance");
    if (values && values->GetNumberOfTuples() > 0)
    {
      frame.HasRadiance = true;
      frame.MinRadiance = std::numeric_limits<double>::infinity();
      frame.MaxRadiance = -frame.MinRadiance;
      double sum = 0.0;
      std::size_t finite = 0;
      for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
      {
        for (int c = 0; c < 3; ++c)
        {
          const double v = values->GetComponent(i, c);
          if (std::isnan(v))
          {
            ++frame.NaN;
          }
          else if (std::isinf(v))
          {
            ++frame.Infinite;
          }
          else
          {
            frame.Negative += v < 0.0 ? 1 : 0;
            frame.MinRadiance = std::min(frame.MinRadiance, v);
            frame.MaxRadiance = std::max(frame.MaxRadiance, v);
            sum += v;
            ++finite;
          }
        }
      }
      frame.MeanRadiance = finite ? sum / finite : 0.0;
    }
    vtkNew<vtkWindowToImageFilter> capture;
    capture->SetInput(this->Window);
    capture->SetInputBufferTypeToRGB();
    capture->ReadFrontBufferOff();
    capture->Update();
    auto* bytes =
      vtkUnsignedCharArray::SafeDownCast(capture->GetOutput()->GetPointData()->GetScalars());
    frame.Pixels.assign(bytes->GetPointer(0), bytes->GetPointer(0) + bytes->GetNumberOfValues());
    return frame;
  }
  std::string AllMessages() const
  {
    return this->Messages.AllErrors() + this->Messages.AllWarnings();
  }
};

double Rmse(const std::vector<unsigned char>& a, const std::vector<unsigned char>& b)
{
  if (a.size() != b.size() || a.empty())
  {
    return kInf;
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    const double d = static_cast<double>(a[i]) - b[i];
    sum += d * d;
  }
  return std::sqrt(sum / a.size());
}

bool Contains(const std::string& text, const std::string& part)
{
  return text.find(part) != std::string::npos;
}

// The first message's text (VTK's messages start with a line "ERROR: In file, line
// n" and then "vtkClass (0x...): text").
std::string FirstLine(std::string text)
{
  if (text.compare(0, 6, "ERROR:") == 0 || text.compare(0, 8, "Warning:") == 0)
  {
    text = text.substr(text.find('\n') + 1);
    const std::size_t colon = text.find("): ");
    text = colon != std::string::npos ? text.substr(colon + 3) : text;
  }
  const std::string line = text.substr(0, text.find('\n'));
  return line.size() > 160 ? line.substr(0, 160) + "..." : line;
}

struct Result
{
  bool Ok;
  std::string What;
};

// --- the cases ----------------------------------------------------------------------------
// A refused value: the setter says so (an error naming the property), the property
// keeps its value, and the frame is the finite image of the kept value.
Result Refused(const std::string& property,
  const std::function<void(vtkNimbusCloudVolumeMapper*)>& set,
  const std::function<double(vtkNimbusCloudVolumeMapper*)>& get)
{
  Scene s(MakeCloud());
  const double before = get(s.Mapper);
  set(s.Mapper);
  const double after = get(s.Mapper);
  const Frame frame = s.Render();
  const std::string errors = s.Messages.AllErrors();
  const bool kept = after == before;
  const bool said = Contains(errors, property);
  return { kept && said && frame.FiniteNonNegative(),
    std::string(said ? "error: " + FirstLine(errors.substr(errors.find(property))) : "no message") +
      "; value " + (kept ? "kept" : "changed to " + std::to_string(after)) + "; " +
      frame.Describe() };
}

Result FiniteImage(const std::function<void(Scene&)>& setUp, bool requireLight = true)
{
  Scene s(MakeCloud());
  setUp(s);
  const Frame frame = s.Render();
  const bool lit = !requireLight || frame.MeanPixel() > 1.0;
  const std::string messages = s.AllMessages();
  return { frame.FiniteNonNegative() && lit,
    frame.Describe() + (messages.empty() ? "" : "; message: " + FirstLine(messages)) };
}

Result SunElevation(double elevation)
{
  return FiniteImage(
    [elevation](Scene& s) { s.Mapper->SetSunElevationDegrees(elevation); }, elevation > -1.0);
}

// The same scene with a clipping range of 1 ... 1e8 renders as with 10 ... 1e6.
Result WideClippingRange()
{
  Scene s(MakeCloud());
  const Frame normal = s.Render();
  s.LookFrom({ 0, -6000, 1500 }, { 0, 0, 1600 }, { 0, 0, 1 }, 1.0, 1e8);
  const Frame wide = s.Render();
  const double rmse = Rmse(normal.Pixels, wide.Pixels);
  return { wide.FiniteNonNegative() && rmse < 2.0,
    wide.Describe() + "; RMSE against clipping 10...1e6: " + std::to_string(rmse) + " (< 2)" };
}

Result CameraFarAbove()
{
  return FiniteImage(
    [](Scene& s) {
      s.LookFrom({ 0, 0, 1.0e6 }, { 0, 0, 0 }, { 0, 1, 0 }, 1e4, 2e6);
    });
}

Result CameraInside()
{
  return FiniteImage(
    [](Scene& s)
    {
      s.Mapper->SetExtinctionPerDensity(0.002); // optical depth ~5: a grey fog
      s.LookFrom({ 0, 0, 1500 }, { 0, 1000, 1600 });
    });
}

// Camera on the sun's line through the cloud (sun 20 deg high in the north):
// looking toward the sun (sign 1, view parallel to it) or away from it (-1).
Result ViewAlongSun(double sign)
{
  return FiniteImage(
    [sign](Scene& s)
    {
      const double e = 20.0 * M_PI / 180.0, d = 7000.0;
      s.LookFrom({ 0, -sign * d * std::cos(e), 1600 - sign * d * std::sin(e) }, { 0, 0, 1600 });
      s.Mapper->SetSunAzimuthDegrees(0);
      s.Mapper->SetSunElevationDegrees(20);
    });
}

Result ConstantDensity(double value, bool doubleArray)
{
  vtkSmartPointer<vtkImageData> image = MakeCloud();
  vtkSmartPointer<vtkDataArray> array;
  if (doubleArray)
  {
    array = vtkSmartPointer<vtkDoubleArray>::New();
  }
  else
  {
    array = vtkSmartPointer<vtkFloatArray>::New();
  }
  array->SetName("density");
  array->SetNumberOfTuples(image->GetNumberOfPoints());
  array->Fill(value);
  image->GetPointData()->SetScalars(array);
  Scene s(image);
  const Frame frame = s.Render();
  const std::string messages = s.AllMessages();
  return { frame.FiniteNonNegative(),
    frame.Describe() + (messages.empty() ? "" : "; message: " + FirstLine(messages)) };
}

// NaN, infinite and negative densities: one warning per version of the array, with
// the counts; the frame is finite.
Result BadDensities()
{
  vtkSmartPointer<vtkImageData> image = MakeCloud();
  auto* values = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
  values->SetValue(10, static_cast<float>(kNaN));
  values->SetValue(11, static_cast<float>(kNaN));
  values->SetValue(12, static_cast<float>(kInf));
  values->SetValue(13, -1.0f);
  values->SetValue(14, -2.0f);
  values->SetValue(15, -3.0f);
  Scene s(image);
  const Frame first = s.Render();
  s.Render();
  const std::size_t afterTwo = s.Messages.Warnings.size();
  const std::string warning = s.Messages.AllWarnings();
  values->SetValue(16, -4.0f);
  values->Modified();
  s.Render();
  const std::size_t afterChange = s.Messages.Warnings.size();
  const bool counted = Contains(warning, "2 NaN") && Contains(warning, "1 infinite") &&
    Contains(warning, "3 negative");
  return { first.FiniteNonNegative() && counted && afterTwo == 1 && afterChange == 2,
    "warnings after two renders: " + std::to_string(afterTwo) +
      ", after a change: " + std::to_string(afterChange) + "; " +
      (warning.empty() ? "no warning" : FirstLine(warning)) + "; " + first.Describe() };
}

Result OneVoxel()
{
  vtkNew<vtkImageData> voxel;
  voxel->SetDimensions(1, 1, 1);
  voxel->SetOrigin(0, 0, 1600);
  vtkNew<vtkFloatArray> value;
  value->SetName("density");
  value->InsertNextValue(1.0f);
  voxel->GetPointData()->SetScalars(value);
  Scene s(voxel);
  const Frame frame = s.Render();
  return { frame.FiniteNonNegative(), frame.Describe() };
}

// A rotated direction matrix renders as the unrotated image in a vtkVolume turned
// by the same rotation about the image's origin.
Result RotatedDirection()
{
  vtkSmartPointer<vtkImageData> cloud = MakeCloud();
  vtkNew<vtkTransform> rotation;
  rotation->RotateZ(30.0);
  rotation->RotateX(20.0);
  vtkNew<vtkMatrix3x3> direction;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      direction->SetElement(r, c, rotation->GetMatrix()->GetElement(r, c));
    }
  }
  vtkNew<vtkImageData> rotated;
  rotated->ShallowCopy(cloud);
  rotated->SetDirectionMatrix(direction);
  Scene withDirection(rotated);
  const Frame a = withDirection.Render();

  Scene withVolumeMatrix(cloud);
  double origin[3];
  cloud->GetOrigin(origin);
  vtkNew<vtkTransform> aboutOrigin;
  aboutOrigin->Translate(origin);
  aboutOrigin->Concatenate(rotation);
  aboutOrigin->Translate(-origin[0], -origin[1], -origin[2]);
  withVolumeMatrix.Volume->SetUserMatrix(aboutOrigin->GetMatrix());
  const Frame b = withVolumeMatrix.Render();
  Scene unrotated(cloud);
  const Frame c = unrotated.Render();
  const double rmse = Rmse(a.Pixels, b.Pixels);
  const double change = Rmse(b.Pixels, c.Pixels);
  const std::string messages = withDirection.AllMessages();
  return { a.FiniteNonNegative() && rmse < 1.0 && change > 5.0,
    "RMSE direction matrix vs volume matrix: " + std::to_string(rmse) +
      " (< 1); the rotation itself changes the image by " + std::to_string(change) + " (> 5)" +
      (messages.empty() ? "" : "; message: " + FirstLine(messages)) };
}

// An exception inside the frame (a NaN position makes the slice planes throw):
// caught at Render's boundary, an error, nothing drawn over the scene.
Result NonFiniteVolumePosition()
{
  Scene s(MakeCloud());
  const Frame clean = s.Render(); // compiles the shaders, allocates the targets
  s.Volume->SetPosition(kNaN, 0.0, 0.0);
  s.Messages.Errors.clear();
  const Frame frame = s.Render();
  const std::string errors = s.Messages.AllErrors();
  // Nothing drawn: the framebuffer is the renderer's background (0.2, 0.3, 0.4).
  bool background = !frame.Pixels.empty();
  for (std::size_t i = 0; i + 2 < frame.Pixels.size(); i += 3)
  {
    background &= std::abs(frame.Pixels[i] - 51) <= 1 && std::abs(frame.Pixels[i + 1] - 77) <= 1 &&
      std::abs(frame.Pixels[i + 2] - 102) <= 1;
  }
  // VTK culls a volume whose bounds are NaN before the mapper runs: no message can
  // come from the mapper then; what matters is that nothing breaks.
  return { !frame.Escaped && background && clean.Finite(),
    (frame.Escaped ? "EXCEPTION escaped Render: " + frame.Exception
                   : "error: " + (errors.empty() ? std::string("none") : FirstLine(errors))) +
      (background ? "; the frame is the scene's background" : "; the frame was drawn over") };
}

// A NaN camera: an error (once, not every frame), nothing drawn over the scene.
Result NonFiniteCamera()
{
  Scene s(MakeCloud());
  s.Render();
  s.Renderer->GetActiveCamera()->SetPosition(kNaN, -6000, 1500);
  s.Messages.Errors.clear();
  const Frame frame = s.Render();
  s.Render();
  const std::string errors = s.Messages.AllErrors();
  return { !frame.Escaped && s.Messages.Errors.size() == 1 && !frame.HasRadiance,
    (frame.Escaped ? "EXCEPTION escaped Render: " + frame.Exception + "; " : "") +
      std::to_string(s.Messages.Errors.size()) + " error(s) in two frames" +
      (errors.empty() ? "" : ": " + FirstLine(errors.substr(errors.find("The")))) +
      (frame.HasRadiance ? "; drawn" : "; nothing drawn") };
}

// The texture memory budget: a volume over it is downsampled (a warning); one that
// cannot fit even one texel is not drawn (an error).
Result TextureBudget()
{
  Scene s(MakeCloud());
  s.Mapper->SetTextureMemoryBudgetMiB(0.01); // 10 KiB: 24x24x16 x 8 B = 72 KiB
  const Frame small = s.Render();
  int dims[3];
  s.Mapper->GetTextureDimensions(dims);
  const std::string warning = s.Messages.AllWarnings();
  const bool fits = 8.0 * dims[0] * dims[1] * dims[2] <= 0.01 * 1024 * 1024;
  s.Mapper->SetTextureMemoryBudgetMiB(1e-7);
  s.Messages.Errors.clear();
  const Frame none = s.Render();
  const std::string error = s.Messages.AllErrors();
  return { small.FiniteNonNegative() && fits && Contains(warning, "budget") && !none.Escaped &&
      !none.HasRadiance && Contains(error, "budget"),
    "0.01 MiB: texture " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
      std::to_string(dims[2]) + ", " + (warning.empty() ? "no warning" : FirstLine(warning)) +
      "; 1e-7 MiB: " + (error.empty() ? "no error" : FirstLine(error)) +
      (none.HasRadiance ? ", drawn" : ", nothing drawn") };
}

// Multiple scattering over its memory budget: the term is off with an error naming
// the budget, the cloud is still drawn; every method renders a finite image.
Result ScatteringBudgetAndMethods()
{
  Scene s(MakeCloud());
  s.Mapper->SetMultipleScatteringMemoryBudgetMiB(1e-6);
  const Frame over = s.Render();
  const std::string error = s.Messages.AllErrors();
  bool ok = over.FiniteNonNegative() && over.MeanPixel() > 1.0 && Contains(error, "budget") &&
    s.Mapper->GetNumberOfMultipleScatteringSolves() == 0;
  std::string what = "1e-6 MiB: " + (error.empty() ? "no error" : FirstLine(error));
  s.Mapper->SetMultipleScatteringMemoryBudgetMiB(0.0);
  s.Mapper->SkyLightOn();
  for (int method = 0; method <= 3; ++method)
  {
    s.Messages.Errors.clear();
    s.Mapper->SetMultipleScatteringMethod(method);
    const Frame frame = s.Render();
    // Reference patterns may not be built in yet: then an error, and the cloud drawn.
    ok &= frame.FiniteNonNegative() && frame.MeanPixel() > 1.0;
    what += "; method " + std::to_string(method) + ": " + frame.Describe() +
      (s.Messages.AllErrors().empty() ? "" : " (" + FirstLine(s.Messages.AllErrors()) + ")");
  }
  return { ok, what };
}

// Spacing 1e300: a box of 1e301 world units, whose sizes overflow float in the
// shaders. Either VTK culls it (its bounds are beyond any frustum) or the mapper
// draws a finite image or says why; no exception leaves Render.
Result HugeSpacing()
{
  vtkSmartPointer<vtkImageData> image = MakeCloud();
  image->SetSpacing(1e300, 1e300, 1e300);
  Scene s(image);
  const Frame frame = s.Render();
  const std::string messages = s.AllMessages();
  return { !frame.Escaped && (!frame.HasRadiance || frame.FiniteNonNegative()),
    frame.Describe() + "; " + (messages.empty() ? "no message" : FirstLine(messages)) };
}

// std::bad_alloc inside the frame: the converted copy of a 64 MiB double density
// cannot be allocated under an address-space limit (Linux: RLIMIT_AS at what the
// process maps already). Caught at Render's boundary: an error, nothing drawn
// over the scene, and the next frame, without the limit, draws again.
Result OutOfMemoryInFrame()
{
#ifdef __linux__
  Scene s(MakeCloud());
  s.Mapper->SetTextureMemoryBudgetMiB(1e6); // the budget would refuse it first
  s.Render();                               // shaders, targets, tables: allocated now
  vtkNew<vtkImageData> big;
  big->SetDimensions(256, 256, 128);
  big->SetOrigin(-1500, -1500, 800);
  big->SetSpacing(3000.0 / 255, 3000.0 / 255, 2000.0 / 127);
  vtkNew<vtkDoubleArray> values;
  values->SetName("density");
  values->SetNumberOfTuples(256 * 256 * 128);
  values->Fill(0.5);
  big->GetPointData()->SetScalars(values);
  s.Mapper->SetInputData(big);
  long pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const rlim_t used = static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE));
  rlimit saved{};
  getrlimit(RLIMIT_AS, &saved);
  rlimit tight = saved;
  tight.rlim_cur = used; // no new mapping: the copy (32 MiB) needs one
  if (tight.rlim_cur > saved.rlim_cur || setrlimit(RLIMIT_AS, &tight) != 0)
  {
    return { true, "skipped (the address-space limit is already lower)" };
  }
  const Frame frame = s.Render();
  setrlimit(RLIMIT_AS, &saved);
  const std::string errors = s.Messages.AllErrors();
  const Frame after = s.Render();
  return { !frame.Escaped && !frame.HasRadiance && Contains(errors, "not drawn: out of memory") &&
      after.FiniteNonNegative(),
    (frame.Escaped       ? "EXCEPTION escaped Render: " + frame.Exception
        : errors.empty() ? std::string("no error")
                         : FirstLine(errors)) +
      (frame.HasRadiance ? "; drawn" : "; nothing drawn") +
      "; without the limit: " + after.Describe() };
#else
  return { true, "skipped (needs Linux's RLIMIT_AS)" };
#endif
}

// The sky classes refuse the same non-finite numbers; a cloud over a sky at its
// extremes (sun at the nadir, 1000 km up, exposure 1e6) renders a finite image.
Result SkyExtremes()
{
  vtkNew<vtkNimbusSkyBackground> background;
  vtkNimbusSky* sky = background->GetSky();
  nimbus::testing::MessageCatcher skyMessages(sky);
  sky->SetSunElevationDegrees(kNaN);
  sky->SetSunAzimuthDegrees(kInf);
  sky->SetMetresPerUnit(-kInf);
  sky->SetExposure(kNaN);
  const bool kept = sky->GetSunElevationDegrees() == 45.0 && sky->GetSunAzimuthDegrees() == 135.0 &&
    sky->GetMetresPerUnit() == 1.0 && sky->GetExposure() == 10.0;
  const std::size_t skyErrors = skyMessages.Errors.size();

  vtkNew<vtkNimbusSunlight> sunlight;
  nimbus::testing::MessageCatcher sunMessages(sunlight);
  sunlight->SetSunElevationDegrees(kNaN);
  sunlight->SetSceneAltitudeMetres(kInf);
  vtkNew<vtkNimbusSkyDomeSource> dome;
  nimbus::testing::MessageCatcher domeMessages(dome);
  dome->SetCenter(kNaN, 0.0, 0.0);
  dome->SetRadius(kInf);
  const bool otherKept = std::isfinite(sunlight->GetSunElevationDegrees()) &&
    std::isfinite(sunlight->GetSceneAltitudeMetres()) && std::isfinite(dome->GetCenter()[0]) &&
    std::isfinite(dome->GetRadius());
  const std::size_t otherErrors = sunMessages.Errors.size() + domeMessages.Errors.size();

  sky->SetSunElevationDegrees(-90.0);
  sky->SetExposure(1e6);
  Scene s(MakeCloud());
  s.Renderer->AddViewProp(background);
  s.Mapper->SetSkyBackground(background);
  s.LookFrom({ 0, 0, 1.0e6 }, { 0, 0, 0 }, { 0, 1, 0 }, 1e4, 2e6);
  const Frame nadir = s.Render();
  sky->SetSunElevationDegrees(0.0);
  const Frame horizon = s.Render();
  return { kept && skyErrors == 4 && otherKept && otherErrors == 4 && nadir.FiniteNonNegative() &&
      horizon.FiniteNonNegative() && s.Mapper->GetLastRenderUsedSceneSky(),
    std::string("sky: ") + std::to_string(skyErrors) + " of 4 refused" +
      (kept ? ", kept" : ", CHANGED") + "; sunlight and dome: " + std::to_string(otherErrors) +
      " of 4 refused; over the sky, sun at "
      "the nadir: " +
      nadir.Describe() + "; at the horizon: " + horizon.Describe() };
}

// A size no texture can take: a message, no crash (the array does not match such an
// image; the mapper must say so without computing the product in int).
Result AbsurdDimensions()
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(70000, 70000, 70000);
  vtkNew<vtkFloatArray> values;
  values->SetName("density");
  values->SetNumberOfTuples(8);
  values->Fill(1.0f);
  image->GetPointData()->SetScalars(values);
  Scene s(image);
  const Frame frame = s.Render();
  const std::string errors = s.Messages.AllErrors();
  return { !frame.Escaped && Contains(errors, "343000000000000"),
    (frame.Escaped ? "EXCEPTION " + frame.Exception : "") +
      (errors.empty() ? "no error" : "error: " + FirstLine(errors)) };
}
}

// The values refused with a message: NaN and infinities of every setter.
std::vector<std::pair<std::string, std::function<Result()>>> RefusedValueCases()
{
  using M = vtkNimbusCloudVolumeMapper;
  return {
    { "SunElevationNaN",
      []
      {
        return Refused(
          "SunElevationDegrees", [](M* m) { m->SetSunElevationDegrees(kNaN); },
          [](M* m) { return m->GetSunElevationDegrees(); });
      } },
    { "SunElevation+Inf",
      []
      {
        return Refused(
          "SunElevationDegrees", [](M* m) { m->SetSunElevationDegrees(kInf); },
          [](M* m) { return m->GetSunElevationDegrees(); });
      } },
    { "SunElevation-Inf",
      []
      {
        return Refused(
          "SunElevationDegrees", [](M* m) { m->SetSunElevationDegrees(-kInf); },
          [](M* m) { return m->GetSunElevationDegrees(); });
      } },
    { "SunAzimuthNaN",
      []
      {
        return Refused(
          "SunAzimuthDegrees", [](M* m) { m->SetSunAzimuthDegrees(kNaN); },
          [](M* m) { return m->GetSunAzimuthDegrees(); });
      } },
    { "SunAzimuth+Inf",
      []
      {
        return Refused(
          "SunAzimuthDegrees", [](M* m) { m->SetSunAzimuthDegrees(kInf); },
          [](M* m) { return m->GetSunAzimuthDegrees(); });
      } },
    { "SunIlluminanceNaN",
      []
      {
        return Refused(
          "SunIlluminance", [](M* m) { m->SetSunIlluminance(kNaN); },
          [](M* m) { return m->GetSunIlluminance(); });
      } },
    { "SunTemperatureNaN",
      []
      {
        return Refused(
          "SunTemperatureKelvin", [](M* m) { m->SetSunTemperatureKelvin(kNaN); },
          [](M* m) { return m->GetSunTemperatureKelvin(); });
      } },
    { "MieScatteringNaN",
      []
      {
        return Refused(
          "MieScatteringPerMetre", [](M* m) { m->SetMieScatteringPerMetre(kNaN); },
          [](M* m) { return m->GetMieScatteringPerMetre(); });
      } },
    { "RayleighScatteringInf",
      []
      {
        return Refused(
          "RayleighScatteringPerMetre", [](M* m) { m->SetRayleighScatteringPerMetre(kInf); },
          [](M* m) { return m->GetRayleighScatteringPerMetre(); });
      } },
    { "MieGNaN",
      []
      {
        return Refused(
          "MieG", [](M* m) { m->SetMieG(kNaN); }, [](M* m) { return m->GetMieG(); });
      } },
    { "CloudGNaN",
      []
      {
        return Refused(
          "CloudG", [](M* m) { m->SetCloudG(kNaN); }, [](M* m) { return m->GetCloudG(); });
      } },
    { "AlbedoNaN",
      []
      {
        return Refused(
          "Albedo", [](M* m) { m->SetAlbedo(kNaN); }, [](M* m) { return m->GetAlbedo(); });
      } },
    { "ExtinctionNaN",
      []
      {
        return Refused(
          "ExtinctionPerDensity", [](M* m) { m->SetExtinctionPerDensity(kNaN); },
          [](M* m) { return m->GetExtinctionPerDensity(); });
      } },
    { "MultipleScatteringNaN",
      []
      {
        return Refused(
          "MultipleScattering", [](M* m) { m->SetMultipleScattering(kNaN); },
          [](M* m) { return m->GetMultipleScattering(); });
      } },
    { "SceneAltitudeNaN",
      []
      {
        return Refused(
          "SceneAltitudeMetres", [](M* m) { m->SetSceneAltitudeMetres(kNaN); },
          [](M* m) { return m->GetSceneAltitudeMetres(); });
      } },
    { "MetresPerUnitNaN",
      []
      {
        return Refused(
          "MetresPerUnit", [](M* m) { m->SetMetresPerUnit(kNaN); },
          [](M* m) { return m->GetMetresPerUnit(); });
      } },
    { "ExposureNaN",
      []
      {
        return Refused(
          "Exposure", [](M* m) { m->SetExposure(kNaN); }, [](M* m) { return m->GetExposure(); });
      } },
    { "GroundHeightNaN",
      []
      {
        return Refused(
          "GroundHeight", [](M* m) { m->SetGroundHeight(kNaN); },
          [](M* m) { return m->GetGroundHeight(); });
      } },
    { "GroundAlbedoNaN",
      []
      {
        return Refused(
          "GroundAlbedo", [](M* m) { m->SetGroundAlbedo(kNaN); },
          [](M* m) { return m->GetGroundAlbedo(); });
      } },
    { "SliceAngleRatioNaN",
      []
      {
        return Refused(
          "SliceAngleRatio", [](M* m) { m->SetSliceAngleRatio(kNaN); },
          [](M* m) { return m->GetSliceAngleRatio(); });
      } },
  };
}

// The extremes that must give a finite picture or a clear message.
std::vector<std::pair<std::string, std::function<Result()>>> ExtremeCases()
{
  return {
    { "SunElevation+90", [] { return SunElevation(90.0); } },
    { "SunElevation-90", [] { return SunElevation(-90.0); } },
    { "SunElevation0", [] { return SunElevation(0.0); } },
    { "SunElevation-0.5", [] { return SunElevation(-0.5); } },
    { "SunElevation-5", [] { return SunElevation(-5.0); } },
    { "SunAzimuth1e6",
      [] { return FiniteImage([](Scene& s) { s.Mapper->SetSunAzimuthDegrees(1e6); }); } },
    { "CameraFarAbove", CameraFarAbove },
    { "ClippingRange1To1e8", WideClippingRange },
    { "CameraInsideVolume", CameraInside },
    { "ViewTowardSun", [] { return ViewAlongSun(1.0); } },
    { "ViewAwayFromSun", [] { return ViewAlongSun(-1.0); } },
    { "ZeroDensity", [] { return ConstantDensity(0.0, false); } },
    { "Density1e30", [] { return ConstantDensity(1e30, false); } },
    { "Density1e300Double", [] { return ConstantDensity(1e300, true); } },
    { "NaNInfNegativeDensities", BadDensities },
    { "OneVoxel", OneVoxel },
    { "RotatedDirectionMatrix", RotatedDirection },
    { "RayleighMax",
      [] {
        return FiniteImage([](Scene& s) { s.Mapper->SetRayleighScatteringPerMetre(1.0); }, false);
      } },
    { "MieMax",
      []
      { return FiniteImage([](Scene& s) { s.Mapper->SetMieScatteringPerMetre(1.0); }, false); } },
    { "MieG+-0.999",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetMieG(0.999);
            s.Mapper->SetCloudG(-0.999);
          });
      } },
    { "SceneAltitudeMax",
      []
      { return FiniteImage([](Scene& s) { s.Mapper->SetSceneAltitudeMetres(1e300); }, false); } },
    { "MetresPerUnitMax",
      [] { return FiniteImage([](Scene& s) { s.Mapper->SetMetresPerUnit(1e300); }, false); } },
    { "MetresPerUnitMin",
      [] { return FiniteImage([](Scene& s) { s.Mapper->SetMetresPerUnit(1e-300); }, false); } },
    { "ExposureAndIlluminanceMax",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetExposure(1e300);
            s.Mapper->SetSunIlluminance(1e300);
          });
      } },
    { "SunTemperature1000K",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetSunTemperatureKelvin(1000);
            s.Mapper->SetSunElevationDegrees(2);
          });
      } },
    { "ExtinctionMax",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetExtinctionPerDensity(1e300);
            s.Mapper->SetMultipleScattering(1e300);
          });
      } },
    { "GroundHeightHuge",
      [] { return FiniteImage([](Scene& s) { s.Mapper->SetGroundHeight(-1e300); }, false); } },
    { "NonFiniteVolumePosition", NonFiniteVolumePosition },
    { "NonFiniteCamera", NonFiniteCamera },
    { "AbsurdDimensions", AbsurdDimensions },
    { "TextureBudget", TextureBudget },
    { "HugeSpacing", HugeSpacing },
    { "OutOfMemoryInFrame", OutOfMemoryInFrame },
    { "SkyExtremes", SkyExtremes },
    { "ScatteringBudgetAndMethods", ScatteringBudgetAndMethods },
    { "ScatteringOneDirectionGrid",
      []
      { return FiniteImage([](Scene& s) { s.Mapper->SetMultipleScatteringDownsampling(256); }); } },
    { "ScatteringHugeExtinction",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetExtinctionPerDensity(1e6);
            s.Mapper->SetAlbedo(1.0);
          },
          false);
      } },
    { "ScatteringOctavesEverything",
      []
      {
        return FiniteImage(
          [](Scene& s)
          {
            s.Mapper->SetMultipleScatteringMethodToOctaves();
            s.Mapper->SetOctaves(16);
            s.Mapper->SetOctaveExtinctionScale(1.0);
            s.Mapper->SetOctaveScatteringScale(1.0);
            s.Mapper->SetCloudG(0.999);
          });
      } },
  };
}

// Every case: a name and the check that runs it.
std::vector<std::pair<std::string, std::function<Result()>>> AllCases()
{
  auto cases = RefusedValueCases();
  const auto extremes = ExtremeCases();
  cases.insert(cases.end(), extremes.begin(), extremes.end());
  return cases;
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  for (int a = 1; a < argc; ++a)
  {
    if (std::string(argv[a]) == "--ray-march")
    {
      gRenderingMethod = vtkNimbusCloudVolumeMapper::RayMarching;
    }
  }
  const auto cases = AllCases();
  std::vector<std::string> selected;
  for (int a = 1; a < argc; ++a)
  {
    if (std::string(argv[a]) != "--ray-march")
    {
      selected.emplace_back(argv[a]);
    }
  }
  int failures = 0, run = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& entry : cases)
  {
    if (!selected.empty() &&
      std::find(selected.begin(), selected.end(), entry.first) == selected.end())
    {
      continue;
    }
    const Result result = entry.second();
    ++run;
    failures += result.Ok ? 0 : 1;
    std::cout << (result.Ok ? "ok:   " : "FAIL: ") << entry.first << ": " << result.What
              << std::endl;
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << run << " cases, " << failures << " failed, " << seconds << " s\n";
  return failures == 0 && run > 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
