// Extreme parameters for the three cloud sources (label fuzz): every numeric property of
// vtkNimbusMetaballCloudSource, vtkNimbusCloudAutomatonSource and vtkNimbusImageCloudFilter
// set in turn to 0, -1, 1e-300, 1e308, NaN, +-Inf, INT_MAX, INT_MIN and a typical value
// (those the type allows), then random combinations with a fixed seed. Each run happens in
// a forked child under an address-space limit (RLIMIT_AS, 3 GiB) and an alarm, and must end
// in a clean error (an error message, empty outputs) or a valid output (the right
// dimensions, finite non-negative densities) -- no crash, no abort inside VTK, no hang.
// A progress observer sets AbortExecute when a run passes 2 s, so a long run must also stop
// when asked. NaN and infinities must always be refused where the property is a parameter:
// by the setter at once where the property has one that clamps (Common/FiniteSetters.h: an
// error naming the property and the value, the previous value kept, and the run then goes
// on with it), else by the run (an error, empty outputs).
// Then: AbortExecute stops the long paths quickly, and they report progress.
#include "vtkNimbusCloudAutomatonSource.h"
#include "vtkNimbusImageCloudFilter.h"
#include "vtkNimbusMetaballCloudSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace
{
using nimbus::testing::MessageCatcher;
using Clock = std::chrono::steady_clock;

constexpr rlim_t AddressSpaceLimit = rlim_t(3) << 30; // 3 GiB
constexpr double AbortAfterSeconds = 2.0;             // the observer then sets AbortExecute
constexpr unsigned AlarmSeconds = 15;                 // a child still running is killed

const double NaN = std::numeric_limits<double>::quiet_NaN();
const double Inf = std::numeric_limits<double>::infinity();

double Seconds(Clock::time_point since)
{
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// --- outcomes ----------------------------------------------------------------------------
enum Outcome
{
  Valid = 0,    // no error, a valid output
  Refused = 1,  // an error message and empty outputs
  Aborted = 2,  // stopped by the 2 s observer, empty outputs
  Invalid = 3,  // an output that is not valid (wrong size, NaN, negative ...)
  Silent = 4,   // empty or partial output with no error message
  NotEmpty = 5, // an error message but outputs not empty
  Crashed = 6,  // killed by a signal (including the alarm) or an unexpected exit
};

const char* OutcomeName(int outcome)
{
  static const char* names[] = { "valid", "error", "aborted", "INVALID", "SILENT", "NOT-EMPTY",
    "CRASH" };
  return outcome >= 0 && outcome <= Crashed ? names[outcome] : "CRASH";
}

// Added to a child's exit status when a setter reported an error before the update.
constexpr int SetterRefusedFlag = 16;

struct ChildResult
{
  int Outcome = Crashed;
  double Seconds = 0.0;
  std::string Text;           // the child's note, or how it died
  bool SetterRefused = false; // a setter reported an error before the update
};

// Runs `body` in a forked child under the address-space limit. The child writes its note
// to a pipe and exits with the outcome.
ChildResult RunIsolated(const std::function<int(std::string&)>& body)
{
  int fds[2];
  if (pipe(fds) != 0)
  {
    return { Crashed, 0.0, "pipe failed" };
  }
  std::cout.flush();
  std::cerr.flush();
  const Clock::time_point start = Clock::now();
  const pid_t pid = fork();
  if (pid == 0)
  {
    close(fds[0]);
    rlimit limit{ AddressSpaceLimit, AddressSpaceLimit };
    setrlimit(RLIMIT_AS, &limit);
    alarm(AlarmSeconds);
    std::string note;
    int outcome = Crashed;
    // An exception leaving the source would end ParaView: count it as a crash, and never let
    // it reach gtest in this child.
    try
    {
      outcome = body(note);
    }
    catch (const std::exception& error)
    {
      note = std::string("uncaught exception: ") + error.what();
    }
    catch (...)
    {
      note = "uncaught exception";
    }
    note = note.substr(0, 2000);
    const ssize_t written = write(fds[1], note.data(), note.size());
    (void)written;
    close(fds[1]);
    _exit(outcome);
  }
  close(fds[1]);
  ChildResult result;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof(buffer))) > 0)
  {
    result.Text.append(buffer, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  result.Seconds = Seconds(start);
  if (WIFEXITED(status) && (WEXITSTATUS(status) & ~SetterRefusedFlag) <= Crashed)
  {
    result.Outcome = WEXITSTATUS(status) & ~SetterRefusedFlag;
    result.SetterRefused = (WEXITSTATUS(status) & SetterRefusedFlag) != 0;
  }
  else
  {
    result.Outcome = Crashed;
    std::ostringstream text;
    if (WIFSIGNALED(status))
    {
      text << "killed by signal " << WTERMSIG(status) << " (" << strsignal(WTERMSIG(status)) << ")";
    }
    else
    {
      text << "exit status " << WEXITSTATUS(status);
    }
    result.Text = text.str() + "; " + result.Text;
  }
  return result;
}

// Sets AbortExecute once a run has lasted AbortAfterSeconds (from a progress event).
struct Watchdog
{
  explicit Watchdog(vtkAlgorithm* algorithm)
    : Algorithm(algorithm)
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(
      [](vtkObject*, unsigned long, void* clientData, void*)
      {
        auto* self = static_cast<Watchdog*>(clientData);
        if (!self->Fired && Seconds(self->Start) > AbortAfterSeconds)
        {
          self->Fired = true;
          self->Algorithm->SetAbortExecute(1);
        }
      });
    algorithm->AddObserver(vtkCommand::ProgressEvent, this->Callback);
  }
  vtkAlgorithm* Algorithm;
  Clock::time_point Start = Clock::now();
  bool Fired = false;
  vtkNew<vtkCallbackCommand> Callback;
};

// The message of a VTK error or warning text ("ERROR: In file, line n\nvtkX (0x..): message").
std::string MessageOf(const std::string& text)
{
  const std::size_t colon = text.find("): ");
  std::string message = colon == std::string::npos ? text : text.substr(colon + 3);
  while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
  {
    message.pop_back();
  }
  return message;
}

// The verdict on a density image: empty, or the expected size with values in [0, upper].
int Judge(vtkImageData* image, const int expected[3], double upper, const MessageCatcher& messages,
  bool aborted, std::string& note)
{
  const vtkIdType points = image->GetNumberOfPoints();
  if (!messages.Errors.empty())
  {
    note = MessageOf(messages.Errors.front());
    return points == 0 ? Refused : NotEmpty;
  }
  if (points == 0)
  {
    note = aborted ? "stopped by AbortExecute" : "empty output, no error";
    return aborted ? Aborted : Silent;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] != expected[0] || dims[1] != expected[1] || dims[2] != expected[2])
  {
    std::ostringstream text;
    text << "dimensions " << dims[0] << " x " << dims[1] << " x " << dims[2] << ", expected "
         << expected[0] << " x " << expected[1] << " x " << expected[2];
    note = text.str();
    return Invalid;
  }
  auto* density = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("density"));
  if (!density || density->GetNumberOfTuples() != points)
  {
    note = "no float \"density\" array of the right size";
    return Invalid;
  }
  const float* values = density->GetPointer(0);
  float largest = 0.0f;
  for (vtkIdType i = 0; i < points; ++i)
  {
    if (!(values[i] >= 0.0f && values[i] <= upper))
    {
      std::ostringstream text;
      text << "density " << values[i] << " at point " << i;
      note = text.str();
      return Invalid;
    }
    largest = std::max(largest, values[i]);
  }
  std::ostringstream text;
  text << points << " points, largest density " << largest
       << (messages.Warnings.empty() ? "" : "; warning: " + MessageOf(messages.Warnings.front()));
  note = text.str();
  return Valid;
}

// The errors the setters reported (caught before the update) are taken out of `messages`, so
// that Judge sees only the run's; the first is noted. Returns the flag for the exit status.
int TakeSetterErrors(MessageCatcher& messages, std::string& setterNote)
{
  if (messages.Errors.empty())
  {
    return 0;
  }
  setterNote = "setter: " + MessageOf(messages.Errors.front()) + "; ";
  messages.Errors.clear();
  return SetterRefusedFlag;
}

// --- the properties ------------------------------------------------------------------------
// One numeric property (or one component of a vector property) and how to set it.
template <typename Setup>
struct Property
{
  std::string Name;
  bool Integer;
  // NaN and +-Inf must be refused (false where they have a documented meaning).
  bool RefuseNonFinite;
  std::function<void(Setup&, double)> Set;
  double Typical;
  // Where the property has a finite setter (Common/FiniteSetters.h): its getter. NaN and
  // +-Inf must then be refused by the setter at once, the previous value kept.
  std::function<double(Setup&)> Get = nullptr;
};

std::vector<double> ValuesFor(bool integer, double typical)
{
  if (integer)
  {
    return { 0.0, -1.0, 1.0, double(INT_MAX), double(INT_MIN), typical };
  }
  return { 0.0, -1.0, 1e-300, 1e308, NaN, Inf, -Inf, double(INT_MAX), double(INT_MIN), typical };
}

int ToInt(double value)
{
  return static_cast<int>(std::clamp(value, double(INT_MIN), double(INT_MAX)));
}

std::string Show(double value)
{
  if (value == double(INT_MAX))
  {
    return "INT_MAX";
  }
  if (value == double(INT_MIN))
  {
    return "INT_MIN";
  }
  std::ostringstream text;
  text << value;
  return text.str();
}

// What a run of one source needs: the source's settings applied before Update.
struct MetaballSetup
{
  vtkNimbusMetaballCloudSource* Source;
  bool HasBall = false; // AddBall(Ball) before the update
  double Ball[5] = { 0, 0, 1800, 500, 1 };
};
struct AutomatonSetup
{
  vtkNimbusCloudAutomatonSource* Source;
  double Time = 5.5;   // requested time, s
  bool HasMap = false; // a p_hum input map with MapValue at one cell
  double MapValue = 0.01;
};
struct ImageSetup
{
  vtkNimbusImageCloudFilter* Filter;
  double Nx = 24, Ny = 20;
  bool HasPixel = false; // a float image with PixelValue at one pixel
  double PixelValue = 200;
};

// One property per element of a vector setting of N values of type T: element a
// set to the value (rounded for integers), the others kept as they are.
template <typename T, int N, typename Setup, typename Get, typename SetAll>
void AddElements(std::vector<Property<Setup>>& properties, const std::string& name, Get get,
  SetAll set, const std::array<double, N>& typical)
{
  for (int a = 0; a < N; ++a)
  {
    properties.push_back({ name + "[" + std::to_string(a) + "]", std::is_integral<T>::value, true,
      [get, set, a](Setup& s, double v)
      {
        T values[N];
        get(s, values);
        values[a] = std::is_integral<T>::value ? static_cast<T>(ToInt(v)) : static_cast<T>(v);
        set(s, values);
      },
      typical[a] });
  }
}

std::vector<Property<MetaballSetup>> MetaballProperties()
{
  using S = MetaballSetup;
  std::vector<Property<S>> properties;
  AddElements<int, 3>(
    properties, "Dimensions", [](S& s, int* v) { s.Source->GetDimensions(v); },
    [](S& s, int* v) { s.Source->SetDimensions(v); }, { { 40, 40, 40 } });
  AddElements<double, 6>(
    properties, "Bounds", [](S& s, double* v) { s.Source->GetBounds(v); },
    [](S& s, double* v) { s.Source->SetBounds(v); }, { { -1500, 1500, -1500, 1500, 800, 2800 } });
  AddElements<double, 2>(
    properties, "BaseBallRadiusRange", [](S& s, double* v) { s.Source->GetBaseBallRadiusRange(v); },
    [](S& s, double* v) { s.Source->SetBaseBallRadiusRange(v); }, { { 350.0, 600.0 } });
  auto scalar = [&properties](const std::string& name, bool integer,
                  std::function<void(vtkNimbusMetaballCloudSource*, double)> set, double typical)
  {
    properties.push_back(
      { name, integer, true, [set](S& s, double v) { set(s.Source, v); }, typical });
  };
  scalar(
    "Seed", true, [](vtkNimbusMetaballCloudSource* s, double v) { s->SetSeed(ToInt(v)); }, 7);
  scalar(
    "NumberOfLevels", true,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetNumberOfLevels(ToInt(v)); }, 3);
  scalar(
    "NumberOfBaseBalls", true,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetNumberOfBaseBalls(ToInt(v)); }, 10);
  scalar(
    "BallsPerLevel", true,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetBallsPerLevel(ToInt(v)); }, 60);
  scalar(
    "FootprintRadius", false,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetFootprintRadius(v); }, 700);
  scalar(
    "TowerHeight", false, [](vtkNimbusMetaballCloudSource* s, double v) { s->SetTowerHeight(v); },
    600);
  scalar(
    "BallCountFactor", false,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetBallCountFactor(v); }, 2);
  scalar(
    "RadiusScalePerLevel", false,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetRadiusScalePerLevel(v); }, 0.5);
  scalar(
    "BallDensity", false, [](vtkNimbusMetaballCloudSource* s, double v) { s->SetBallDensity(v); },
    1);
  scalar(
    "IsoValue", false, [](vtkNimbusMetaballCloudSource* s, double v) { s->SetIsoValue(v); }, 0.5);
  scalar(
    "BaseHeight", false, [](vtkNimbusMetaballCloudSource* s, double v) { s->SetBaseHeight(v); },
    1000);
  scalar(
    "BaseTransitionThickness", false,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetBaseTransitionThickness(v); }, 100);
  scalar(
    "MemoryBudgetMiB", false,
    [](vtkNimbusMetaballCloudSource* s, double v) { s->SetMemoryBudgetMiB(v); }, 2048);
  const char* ball[5] = { "AddBall.x", "AddBall.y", "AddBall.z", "AddBall.radius",
    "AddBall.density" };
  const double typicalBall[5] = { 0, 0, 1800, 500, 1 };
  for (int c = 0; c < 5; ++c)
  {
    properties.push_back({ ball[c], false, true,
      [c](S& s, double v)
      {
        s.HasBall = true;
        s.Ball[c] = v;
      },
      typicalBall[c] });
  }
  return properties;
}

std::vector<Property<AutomatonSetup>> AutomatonProperties()
{
  using S = AutomatonSetup;
  std::vector<Property<S>> properties;
  AddElements<int, 3>(
    properties, "Dimensions", [](S& s, int* v) { s.Source->GetDimensions(v); },
    [](S& s, int* v) { s.Source->SetDimensions(v); }, { { 48, 48, 48 } });
  AddElements<double, 6>(
    properties, "Bounds", [](S& s, double* v) { s.Source->GetBounds(v); },
    [](S& s, double* v) { s.Source->SetBounds(v); }, { { -6400, 6400, -6400, 6400, 1000, 2600 } });
  AddElements<double, 2>(
    properties, "Wind", [](S& s, double* v) { s.Source->GetWind(v); },
    [](S& s, double* v) { s.Source->SetWind(v); }, { { 12.0, 12.0 } });
  AddElements<double, 2>(
    properties, "Shear", [](S& s, double* v) { s.Source->GetShear(v); },
    [](S& s, double* v) { s.Source->SetShear(v); }, { { 0.01, 0.01 } });
  auto scalar = [&properties](const std::string& name, bool integer, bool refuseNonFinite,
                  std::function<void(vtkNimbusCloudAutomatonSource*, double)> set, double typical)
  {
    properties.push_back(
      { name, integer, refuseNonFinite, [set](S& s, double v) { set(s.Source, v); }, typical });
  };
  using A = vtkNimbusCloudAutomatonSource;
  // A property with a finite setter: finite values clamped, NaN and infinities refused by
  // the setter at once.
  auto finite = [&properties](const std::string& name, std::function<void(A*, double)> set,
                  std::function<double(A*)> get, double typical)
  {
    properties.push_back({ name, false, true, [set](S& s, double v) { set(s.Source, v); }, typical,
      [get](S& s) { return get(s.Source); } });
  };
  scalar(
    "Seed", true, true, [](A* s, double v) { s->SetSeed(ToInt(v)); }, 9);
  finite(
    "ExtinctionProbability", [](A* s, double v) { s->SetExtinctionProbability(v); },
    [](A* s) { return s->GetExtinctionProbability(); }, 0.05);
  finite(
    "HumidityProbability", [](A* s, double v) { s->SetHumidityProbability(v); },
    [](A* s) { return s->GetHumidityProbability(); }, 0.002);
  finite(
    "ActivationProbability", [](A* s, double v) { s->SetActivationProbability(v); },
    [](A* s) { return s->GetActivationProbability(); }, 0.0002);
  finite(
    "InitialHumidity", [](A* s, double v) { s->SetInitialHumidity(v); },
    [](A* s) { return s->GetInitialHumidity(); }, 0.3);
  finite(
    "InitialActivation", [](A* s, double v) { s->SetInitialActivation(v); },
    [](A* s) { return s->GetInitialActivation(); }, 0.001);
  scalar(
    "StepDuration", false, true, [](A* s, double v) { s->SetStepDuration(v); }, 1.0);
  scalar(
    "NumberOfTimeSteps", true, true, [](A* s, double v) { s->SetNumberOfTimeSteps(ToInt(v)); },
    100);
  finite(
    "SmoothingRadius", [](A* s, double v) { s->SetSmoothingRadius(v); },
    [](A* s) { return s->GetSmoothingRadius(); }, 2.5);
  scalar(
    "NumberOfThreads", true, true, [](A* s, double v) { s->SetNumberOfThreads(ToInt(v)); }, 2);
  scalar(
    "CheckpointInterval", true, true, [](A* s, double v) { s->SetCheckpointInterval(ToInt(v)); },
    10);
  scalar(
    "MaximumNumberOfCheckpoints", true, true,
    [](A* s, double v) { s->SetMaximumNumberOfCheckpoints(ToInt(v)); }, 16);
  scalar(
    "MemoryBudgetMiB", false, true, [](A* s, double v) { s->SetMemoryBudgetMiB(v); }, 2048);
  scalar(
    "NumberOfFormationRegions", true, true,
    [](A* s, double v) { s->SetNumberOfFormationRegions(ToInt(v)); }, 6);
  AddElements<double, 2>(
    properties, "FormationRegionRadiusRange",
    [](S& s, double* v) { s.Source->GetFormationRegionRadiusRange(v); },
    [](S& s, double* v) { s.Source->SetFormationRegionRadiusRange(v); }, { { 500.0, 900.0 } });
  scalar(
    "SpinUpSteps", true, true, [](A* s, double v) { s->SetSpinUpSteps(ToInt(v)); }, 40);
  // The requested time: NaN reads as time 0, infinities are clamped to the time range.
  properties.push_back({ "UpdateTimeStep", false, false, [](S& s, double v) { s.Time = v; }, 3.5 });
  // One cell of an input p_hum map: values outside [0, 1] are refused.
  properties.push_back({ "p_hum map value", false, true,
    [](S& s, double v)
    {
      s.HasMap = true;
      s.MapValue = v;
    },
    0.01 });
  return properties;
}

std::vector<Property<ImageSetup>> ImageProperties()
{
  using S = ImageSetup;
  using F = vtkNimbusImageCloudFilter;
  std::vector<Property<S>> properties;
  AddElements<double, 2>(
    properties, "IntensityRange", [](S& s, double* v) { s.Filter->GetIntensityRange(v); },
    [](S& s, double* v) { s.Filter->SetIntensityRange(v); }, { { 0.0, 255.0 } });
  properties.push_back({ "image nx", true, true, [](S& s, double v) { s.Nx = v; }, 24 });
  properties.push_back({ "image ny", true, true, [](S& s, double v) { s.Ny = v; }, 20 });
  // Intensities may be anything: NaN reads as clear sky, infinities clamp (with a warning).
  properties.push_back({ "pixel value", false, false,
    [](S& s, double v)
    {
      s.HasPixel = true;
      s.PixelValue = v;
    },
    200 });
  auto scalar = [&properties](const std::string& name, bool integer,
                  std::function<void(F*, double)> set, double typical)
  {
    properties.push_back(
      { name, integer, true, [set](S& s, double v) { set(s.Filter, v); }, typical });
  };
  // A property with a finite setter: finite values clamped, NaN and infinities refused by
  // the setter at once.
  auto finite = [&properties](const std::string& name, std::function<void(F*, double)> set,
                  std::function<double(F*)> get, double typical)
  {
    properties.push_back({ name, false, true, [set](S& s, double v) { set(s.Filter, v); }, typical,
      [get](S& s) { return get(s.Filter); } });
  };
  scalar(
    "MappingType", true, [](F* f, double v) { f->SetMappingType(ToInt(v)); }, 1);
  scalar(
    "ClearIntensity", false, [](F* f, double v) { f->SetClearIntensity(v); }, 0.1);
  scalar(
    "WhiteIntensity", false, [](F* f, double v) { f->SetWhiteIntensity(v); }, 1.0);
  finite(
    "Gamma", [](F* f, double v) { f->SetGamma(v); }, [](F* f) { return f->GetGamma(); }, 1.5);
  finite(
    "MaximumOpticalDepth", [](F* f, double v) { f->SetMaximumOpticalDepth(v); },
    [](F* f) { return f->GetMaximumOpticalDepth(); }, 30);
  finite(
    "AsymmetryParameter", [](F* f, double v) { f->SetAsymmetryParameter(v); },
    [](F* f) { return f->GetAsymmetryParameter(); }, 0.85);
  scalar(
    "PixelSize", false, [](F* f, double v) { f->SetPixelSize(v); }, 100);
  scalar(
    "VerticalSpacing", false, [](F* f, double v) { f->SetVerticalSpacing(v); }, 50);
  scalar(
    "ExtinctionCoefficient", false, [](F* f, double v) { f->SetExtinctionCoefficient(v); }, 0.02);
  scalar(
    "NominalDensity", false, [](F* f, double v) { f->SetNominalDensity(v); }, 1);
  scalar(
    "BaseHeight", false, [](F* f, double v) { f->SetBaseHeight(v); }, 1000);
  scalar(
    "BaseTransitionThickness", false, [](F* f, double v) { f->SetBaseTransitionThickness(v); }, 50);
  scalar(
    "BallSpacing", true, [](F* f, double v) { f->SetBallSpacing(ToInt(v)); }, 2);
  finite(
    "BallRadiusFactor", [](F* f, double v) { f->SetBallRadiusFactor(v); },
    [](F* f) { return f->GetBallRadiusFactor(); }, 3);
  finite(
    "TopRoughness", [](F* f, double v) { f->SetTopRoughness(v); },
    [](F* f) { return f->GetTopRoughness(); }, 0.6);
  scalar(
    "Iterations", true, [](F* f, double v) { f->SetIterations(ToInt(v)); }, 10);
  scalar(
    "Seed", true, [](F* f, double v) { f->SetSeed(ToInt(v)); }, 3);
  scalar(
    "MemoryBudgetMiB", false, [](F* f, double v) { f->SetMemoryBudgetMiB(v); }, 2048);
  return properties;
}

// --- one run of each source ------------------------------------------------------------------
int RunMetaballUpdate(
  const std::function<void(MetaballSetup&)>& apply, std::string& note, std::string& setterNote)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  source->SetDimensions(24, 24, 16); // a cheap base: fractions of a millisecond per level
  source->SetNumberOfLevels(2);
  MessageCatcher messages(source);
  Watchdog watchdog(source);
  MetaballSetup setup{ source };
  apply(setup);
  const int setterFlag = TakeSetterErrors(messages, setterNote);
  if (setup.HasBall)
  {
    source->AddBall(setup.Ball[0], setup.Ball[1], setup.Ball[2], setup.Ball[3], setup.Ball[4]);
  }
  source->Update();
  int expected[3];
  source->GetDimensions(expected);
  const int verdict = Judge(source->GetOutput(), expected, std::numeric_limits<float>::max(),
    messages, watchdog.Fired, note);
  if (verdict == Valid || verdict == Aborted)
  {
    // Port 1: finite ball radii and densities.
    vtkPolyData* balls = source->GetMetaballs();
    for (const char* name : { "radius", "density" })
    {
      vtkDataArray* array = balls->GetPointData()->GetArray(name);
      for (vtkIdType i = 0; array && i < array->GetNumberOfTuples(); ++i)
      {
        if (!(std::isfinite(array->GetComponent(i, 0)) && array->GetComponent(i, 0) >= 0.0))
        {
          note = std::string("ball ") + name + " " + std::to_string(array->GetComponent(i, 0));
          return Invalid | setterFlag;
        }
      }
    }
  }
  return verdict | setterFlag;
}

// A run's exit status and note: the update's outcome, the setters' refusal flag and note.
int RunMetaball(const std::function<void(MetaballSetup&)>& apply, std::string& note)
{
  std::string setterNote;
  const int status = RunMetaballUpdate(apply, note, setterNote);
  note = setterNote + note;
  return status;
}

int RunAutomaton(const std::function<void(AutomatonSetup&)>& apply, std::string& note)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  source->SetDimensions(24, 20, 6);
  source->SetNumberOfTimeSteps(8);
  source->SetNumberOfThreads(2);
  MessageCatcher messages(source);
  Watchdog watchdog(source);
  AutomatonSetup setup{ source };
  apply(setup);
  std::string setterNote;
  const int setterFlag = TakeSetterErrors(messages, setterNote);
  vtkNew<vtkImageData> map;
  if (setup.HasMap)
  {
    int d[3];
    source->GetDimensions(d);
    if (d[0] >= 1 && d[1] >= 1 && static_cast<double>(d[0]) * d[1] < 1.0e7)
    {
      map->SetDimensions(d[0], d[1], 1);
      vtkNew<vtkFloatArray> p;
      p->SetName("p_hum");
      p->SetNumberOfTuples(static_cast<vtkIdType>(d[0]) * d[1]);
      p->FillValue(0.002f);
      p->SetValue(0, static_cast<float>(setup.MapValue));
      map->GetPointData()->AddArray(p);
      source->SetInputData(map);
    }
  }
  source->UpdateTimeStep(setup.Time);
  int expected[3];
  source->GetDimensions(expected);
  const int verdict =
    Judge(source->GetOutput(), expected, 1.0 + 1e-5, messages, watchdog.Fired, note);
  note = setterNote + note;
  return verdict | setterFlag;
}

int RunImageUpdate(
  const std::function<void(ImageSetup&)>& apply, std::string& note, std::string& setterNote)
{
  vtkNew<vtkNimbusImageCloudFilter> filter;
  MessageCatcher messages(filter);
  Watchdog watchdog(filter);
  ImageSetup setup{ filter };
  apply(setup);
  const int setterFlag = TakeSetterErrors(messages, setterNote);
  vtkNew<vtkImageData> image;
  const int nx = ToInt(setup.Nx), ny = ToInt(setup.Ny);
  image->SetDimensions(nx, ny, 1);
  if (nx >= 1 && ny >= 1 && static_cast<double>(nx) * ny <= 1.0e7)
  {
    // Two grey discs on a dark sea; a float image when one pixel is set to the case's value.
    const bool floats = setup.HasPixel;
    vtkSmartPointer<vtkDataArray> pixels = floats
      ? vtkSmartPointer<vtkDataArray>::Take(vtkFloatArray::New())
      : vtkSmartPointer<vtkDataArray>::Take(vtkUnsignedCharArray::New());
    pixels->SetName("gray");
    pixels->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny);
    for (int y = 0; y < ny; ++y)
    {
      for (int x = 0; x < nx; ++x)
      {
        const bool disc =
          std::hypot(x - 7.0, y - 7.0) < 5.0 || std::hypot(x - 17.0, y - 12.0) < 6.0;
        pixels->SetComponent(x + static_cast<vtkIdType>(nx) * y, 0, disc ? 200.0 : 20.0);
      }
    }
    if (floats)
    {
      pixels->SetComponent(
        std::min<vtkIdType>(7 + 7 * nx, pixels->GetNumberOfTuples() - 1), 0, setup.PixelValue);
    }
    image->GetPointData()->SetScalars(pixels);
  }
  filter->SetInputData(image);
  filter->Update();
  const int expected[3] = { nx, ny, filter->GetOutput()->GetDimensions()[2] };
  const int verdict = Judge(filter->GetOutput(), expected, std::numeric_limits<float>::max(),
    messages, watchdog.Fired, note);
  if (verdict == Valid && expected[2] < 2)
  {
    note = "a cloud of fewer than 2 layers";
    return Invalid | setterFlag;
  }
  if (verdict == Valid)
  {
    vtkImageData* map = filter->GetOpticalDepthMap();
    for (const char* name : { "optical_depth", "column_optical_depth" })
    {
      vtkDataArray* array = map->GetPointData()->GetArray(name);
      if (!array || array->GetNumberOfTuples() != static_cast<vtkIdType>(nx) * ny)
      {
        note = std::string("map array ") + name + " missing";
        return Invalid | setterFlag;
      }
      for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
      {
        const double v = array->GetComponent(i, 0);
        if (!(std::isfinite(v) && v >= 0.0))
        {
          note = std::string("map ") + name + " " + std::to_string(v);
          return Invalid | setterFlag;
        }
      }
    }
  }
  return verdict | setterFlag;
}

int RunImage(const std::function<void(ImageSetup&)>& apply, std::string& note)
{
  std::string setterNote;
  const int status = RunImageUpdate(apply, note, setterNote);
  note = setterNote + note;
  return status;
}

// --- the sweeps -------------------------------------------------------------------------------
struct Tally
{
  int Cases = 0;
  double Seconds = 0.0, Slowest = 0.0;
  std::map<std::string, int> Outcomes;
};

// What a run must end in beyond a clean outcome.
enum class Expect
{
  Anything,        // valid, refused or aborted
  RefusedByRun,    // an error from the update and empty outputs
  RefusedBySetter, // an error from a setter before the update (which then runs on)
};

// Checks one run's result against what it must end in.
void Check(const std::string& label, const ChildResult& result, Expect expect, Tally& tally)
{
  ++tally.Cases;
  tally.Seconds += result.Seconds;
  tally.Slowest = std::max(tally.Slowest, result.Seconds);
  ++tally.Outcomes[OutcomeName(result.Outcome)];
  std::cout << "  " << label << " -> " << OutcomeName(result.Outcome) << " ("
            << static_cast<int>(result.Seconds * 1000.0) << " ms): " << result.Text << "\n";
  EXPECT_TRUE(result.Outcome == Valid || result.Outcome == Refused || result.Outcome == Aborted)
    << label << ": " << OutcomeName(result.Outcome) << ": " << result.Text;
  if (expect == Expect::RefusedByRun)
  {
    EXPECT_EQ(result.Outcome, Refused) << label << " must be refused: " << result.Text;
  }
  if (expect == Expect::RefusedBySetter)
  {
    EXPECT_TRUE(result.SetterRefused)
      << label << " must be refused by its setter at once: " << result.Text;
  }
  // A run stopped by the watchdog must have stopped soon after it fired.
  EXPECT_LT(result.Seconds, AbortAfterSeconds + 3.0) << label << ": " << result.Text;
}

void PrintTally(const std::string& what, const Tally& tally)
{
  std::cout << what << ": " << tally.Cases << " cases in " << tally.Seconds << " s (slowest "
            << tally.Slowest << " s);";
  for (const auto& outcome : tally.Outcomes)
  {
    std::cout << " " << outcome.first << " " << outcome.second;
  }
  std::cout << "\n";
}

template <typename Setup>
void SweepEachProperty(const std::vector<Property<Setup>>& properties,
  int (*run)(const std::function<void(Setup&)>&, std::string&), const std::string& what)
{
  Tally tally;
  for (const Property<Setup>& property : properties)
  {
    for (const double value : ValuesFor(property.Integer, property.Typical))
    {
      const bool refuse = property.RefuseNonFinite && !std::isfinite(value);
      const ChildResult result = RunIsolated(
        [&](std::string& note)
        {
          // A finite setter must keep the previous value when it refuses one.
          double before = 0.0, after = 0.0;
          const int status = run(
            [&](Setup& setup)
            {
              before = property.Get ? property.Get(setup) : 0.0;
              property.Set(setup, value);
              after = property.Get ? property.Get(setup) : 0.0;
            },
            note);
          if (refuse && property.Get && !(before == after))
          {
            note = property.Name + " became " + Show(after) + " (was " + Show(before) +
              ") instead of keeping its value; " + note;
            return Invalid | (status & SetterRefusedFlag);
          }
          return status;
        });
      const std::string label = property.Name + " = " + Show(value);
      Check(label, result,
        !refuse          ? Expect::Anything
          : property.Get ? Expect::RefusedBySetter
                         : Expect::RefusedByRun,
        tally);
      if (refuse && property.Get)
      {
        // The error names the property and the value: "SetName(value): ...".
        const std::string named = "Set" + property.Name + "(" + Show(value) + ")";
        EXPECT_NE(result.Text.find(named), std::string::npos)
          << label << ": the setter's error does not name " << named << ": " << result.Text;
      }
    }
  }
  PrintTally(what, tally);
}

template <typename Setup>
void SweepRandomCombinations(const std::vector<Property<Setup>>& properties,
  int (*run)(const std::function<void(Setup&)>&, std::string&), const std::string& what,
  unsigned seed, int cases)
{
  std::mt19937 random(seed);
  Tally tally;
  for (int c = 0; c < cases; ++c)
  {
    // Two to four properties, each a random value of its kind.
    const int count = 2 + static_cast<int>(random() % 3);
    std::vector<std::pair<const Property<Setup>*, double>> settings;
    std::string label;
    bool mustRefuse = false, setterMustRefuse = false;
    for (int k = 0; k < count; ++k)
    {
      const Property<Setup>& property = properties[random() % properties.size()];
      const std::vector<double> values = ValuesFor(property.Integer, property.Typical);
      // Typical values half of the time, so that combinations also run.
      const double value = random() % 2 ? property.Typical : values[random() % values.size()];
      settings.emplace_back(&property, value);
      label += (k ? ", " : "") + property.Name + " = " + Show(value);
    }
    // Only the last setting of a property counts.
    std::map<std::string, double> last;
    for (const auto& setting : settings)
    {
      last[setting.first->Name] = setting.second;
    }
    // A finite setter refuses every non-finite value it is given (the previous value kept);
    // for the others the last one counts, and the run refuses it.
    for (const auto& setting : settings)
    {
      const Property<Setup>& property = *setting.first;
      if (property.Get)
      {
        setterMustRefuse =
          setterMustRefuse || (property.RefuseNonFinite && !std::isfinite(setting.second));
      }
      else
      {
        mustRefuse =
          mustRefuse || (property.RefuseNonFinite && !std::isfinite(last[property.Name]));
      }
    }
    const ChildResult result = RunIsolated(
      [&](std::string& note)
      {
        return run(
          [&](Setup& setup)
          {
            for (const auto& setting : settings)
            {
              setting.first->Set(setup, setting.second);
            }
          },
          note);
      });
    Check("[" + label + "]", result, mustRefuse ? Expect::RefusedByRun : Expect::Anything, tally);
    if (setterMustRefuse)
    {
      EXPECT_TRUE(result.SetterRefused)
        << "[" << label << "] must be refused by a setter at once: " << result.Text;
    }
  }
  PrintTally(what, tally);
}
}

TEST(ExtremeParameters, MetaballCloudSource)
{
  SweepEachProperty(MetaballProperties(), &RunMetaball, "metaball source, each property");
}

TEST(ExtremeParameters, CloudAutomatonSource)
{
  SweepEachProperty(AutomatonProperties(), &RunAutomaton, "automaton source, each property");
}

TEST(ExtremeParameters, ImageCloudFilter)
{
  SweepEachProperty(ImageProperties(), &RunImage, "image cloud filter, each property");
}

TEST(ExtremeParameters, RandomCombinations)
{
  SweepRandomCombinations(
    MetaballProperties(), &RunMetaball, "metaball source, random combinations", 20261128u, 60);
  SweepRandomCombinations(
    AutomatonProperties(), &RunAutomaton, "automaton source, random combinations", 1u, 60);
  SweepRandomCombinations(
    ImageProperties(), &RunImage, "image cloud filter, random combinations", 2u, 60);
}

// --- the reported cases, by name (also under the address-space limit) -------------------------
TEST(ExtremeParameters, ReportedCases)
{
  Tally tally;
  auto metaball = [&](const std::string& label,
                    std::function<void(vtkNimbusMetaballCloudSource*)> set, const char* expected)
  {
    const ChildResult result = RunIsolated([&](std::string& note)
      { return RunMetaball([&](MetaballSetup& s) { set(s.Source); }, note); });
    Check(label, result, Expect::RefusedByRun, tally);
    EXPECT_NE(result.Text.find(expected), std::string::npos) << label << ": " << result.Text;
  };
  metaball(
    "metaball Dimensions 3000^3",
    [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(3000, 3000, 3000); }, "memory budget");
  metaball(
    "metaball Dimensions (2^31-1)^3",
    [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(INT_MAX, INT_MAX, INT_MAX); },
    "64 bits");
  metaball(
    "metaball BallDensity 1e308", [](vtkNimbusMetaballCloudSource* s) { s->SetBallDensity(1e308); },
    "BallDensity");
  metaball(
    "metaball NumberOfLevels 1000",
    [](vtkNimbusMetaballCloudSource* s) { s->SetNumberOfLevels(1000); }, "NumberOfLevels");
  metaball(
    "metaball NumberOfLevels 60, BallCountFactor 1",
    [](vtkNimbusMetaballCloudSource* s)
    {
      s->SetDimensions(400, 400, 400);
      s->SetNumberOfLevels(60);
      s->SetBallCountFactor(1.0);
      s->SetRadiusScalePerLevel(1.0);
    },
    "updates");
  auto automaton = [&](const std::string& label, std::function<void(AutomatonSetup&)> set,
                     Expect expect, const char* expected)
  {
    const ChildResult result =
      RunIsolated([&](std::string& note) { return RunAutomaton(set, note); });
    Check(label, result, expect, tally);
    EXPECT_NE(result.Text.find(expected), std::string::npos) << label << ": " << result.Text;
  };
  // Refused by the setter at once, the previous radius (the default, 2.5 cells) kept: the run
  // then succeeds with it.
  automaton(
    "automaton SmoothingRadius NaN", [](AutomatonSetup& s) { s.Source->SetSmoothingRadius(NaN); },
    Expect::RefusedBySetter,
    "SetSmoothingRadius(nan): not a finite number; SmoothingRadius stays 2.5");
  automaton(
    "automaton time of a million steps, default grid",
    [](AutomatonSetup& s)
    {
      s.Source->SetDimensions(128, 128, 32);
      s.Source->SetNumberOfTimeSteps(1000000);
      s.Source->SetStepDuration(1.0); // a million steps, as before the defaults changed
      s.Time = 1.0e6;
    },
    Expect::RefusedByRun, "cell updates");
  PrintTally("reported cases", tally);
}

// --- abort and progress ------------------------------------------------------------------------
namespace
{
// Sets AbortExecute at the first progress event after `after` seconds; records the events.
struct AbortAfter
{
  AbortAfter(vtkAlgorithm* algorithm, double after)
    : Algorithm(algorithm)
    , After(after)
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(
      [](vtkObject*, unsigned long, void* clientData, void* callData)
      {
        auto* self = static_cast<AbortAfter*>(clientData);
        self->Progress.push_back(*static_cast<double*>(callData));
        if (self->After >= 0.0 && !self->Fired && Seconds(self->Start) >= self->After)
        {
          self->Fired = true;
          self->FiredAt = Clock::now();
          self->Algorithm->SetAbortExecute(1);
        }
      });
    algorithm->AddObserver(vtkCommand::ProgressEvent, this->Callback);
  }
  vtkAlgorithm* Algorithm;
  double After;
  Clock::time_point Start = Clock::now();
  Clock::time_point FiredAt;
  bool Fired = false;
  std::vector<double> Progress;
  vtkNew<vtkCallbackCommand> Callback;
};

// Runs `update` with an abort requested after 0.3 s: it must have fired, and Update must
// return within `bound` seconds of it.
void ExpectAbortStops(vtkAlgorithm* algorithm, const std::function<void()>& update,
  vtkImageData* output, const char* what, double bound = 0.5)
{
  AbortAfter abort(algorithm, 0.3);
  abort.Start = Clock::now();
  update();
  const double total = Seconds(abort.Start);
  ASSERT_TRUE(abort.Fired) << what << " finished in " << total << " s before the abort";
  ASSERT_GT(total, 0.3) << what;
  const double afterAbort = Seconds(abort.FiredAt);
  std::cout << what << ": aborted after " << total - afterAbort << " s, stopped " << afterAbort
            << " s later, " << abort.Progress.size() << " progress events\n";
  EXPECT_LT(afterAbort, bound) << what;
  EXPECT_EQ(output->GetNumberOfPoints(), 0) << what;
}
}

TEST(AbortAndProgress, MetaballCloudSource)
{
  // A single ball filling a 320^3 grid (33 million points per sampling), three levels.
  vtkNew<vtkNimbusMetaballCloudSource> source;
  source->SetDimensions(320, 320, 320);
  source->SetNumberOfLevels(3);
  source->SetBaseBallRadiusRange(1400, 1500);
  ExpectAbortStops(
    source, [&]() { source->Update(); }, source->GetOutput(), "metaball source");

  // Progress: a single long sampling reports several times, in order, up to 1.
  vtkNew<vtkNimbusMetaballCloudSource> one;
  one->SetDimensions(256, 256, 256);
  one->SetNumberOfLevels(0);
  one->AddBall(0, 0, 1800, 3000, 1);
  AbortAfter watch(one, -1.0);
  one->Update();
  std::cout << "metaball source, one sampling of 16.8 million points: " << watch.Progress.size()
            << " progress events\n";
  EXPECT_GE(watch.Progress.size(), 4u);
  EXPECT_TRUE(std::is_sorted(watch.Progress.begin(), watch.Progress.end()));
  EXPECT_EQ(watch.Progress.back(), 1.0);
}

TEST(AbortAndProgress, CloudAutomatonSource)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  source->SetDimensions(64, 64, 16);
  source->SetNumberOfTimeSteps(200000);
  ExpectAbortStops(
    source, [&]() { source->UpdateTimeStep(200000.0); }, source->GetOutput(), "automaton source");
  EXPECT_LT(source->GetNumberOfStepsComputed(), 200000);

  vtkNew<vtkNimbusCloudAutomatonSource> watched;
  watched->SetDimensions(32, 32, 8);
  watched->SetNumberOfTimeSteps(2000);
  AbortAfter watch(watched, -1.0);
  watched->UpdateTimeStep(2000.0);
  std::cout << "automaton source, 2000 steps: " << watch.Progress.size() << " progress events\n";
  EXPECT_GE(watch.Progress.size(), 100u);
  EXPECT_LE(watch.Progress.size(), 400u); // throttled, not one per step
  EXPECT_TRUE(std::is_sorted(watch.Progress.begin(), watch.Progress.end()));
  EXPECT_EQ(watch.Progress.back(), 1.0);
}

TEST(AbortAndProgress, ImageCloudFilter)
{
  // A bright, noisy image: about 1e9 grid-point updates per sampling at 400 x 400.
  auto noise = [](int n)
  {
    vtkSmartPointer<vtkImageData> image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(n, n, 1);
    vtkNew<vtkUnsignedCharArray> pixels;
    pixels->SetNumberOfTuples(static_cast<vtkIdType>(n) * n);
    for (vtkIdType i = 0; i < pixels->GetNumberOfTuples(); ++i)
    {
      pixels->SetValue(i, static_cast<unsigned char>(100 + (i * 7919) % 156));
    }
    image->GetPointData()->SetScalars(pixels);
    return image;
  };
  vtkSmartPointer<vtkImageData> large = noise(400);
  vtkNew<vtkNimbusImageCloudFilter> filter;
  filter->SetInputData(large);
  filter->SetIterations(30);
  MessageCatcher messages(filter);
  ExpectAbortStops(
    filter, [&]() { filter->Update(); }, filter->GetOutput(), "image cloud filter");
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();

  vtkSmartPointer<vtkImageData> small = noise(120);
  vtkNew<vtkNimbusImageCloudFilter> watched;
  watched->SetInputData(small);
  watched->SetIterations(3);
  AbortAfter watch(watched, -1.0);
  watched->Update();
  std::cout << "image cloud filter, 120 x 120, 4 samplings: " << watch.Progress.size()
            << " progress events\n";
  EXPECT_GE(watch.Progress.size(), 6u);
  EXPECT_TRUE(std::is_sorted(watch.Progress.begin(), watch.Progress.end()));
  EXPECT_EQ(watch.Progress.back(), 1.0);
}
