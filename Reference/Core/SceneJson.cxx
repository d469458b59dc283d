#include "SceneJson.h"
#include "Math.h"
#include "SceneMigration.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace nimbus
{

namespace
{
// Insertion-ordered objects: SceneToJson's key order is the documented order.
using Json = nlohmann::ordered_json;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Limits on values that cannot be physical, so that every scene the reader accepts
// renders to finite pixels (docs/scene-format.md, "Limits"; 1e308 in any of these
// made nimbus-render write Inf and NaN pixels). Lengths and positions, m: 1e9 m is
// 2.6 times the distance to the Moon; a scene is at most an atmosphere wide.
constexpr double kMaxLengthMetres = 1.0e9;
// Radiometry, relative units (sun.illuminance is the luminance Y of the sun's
// irradiance; the scenes use 1, the real sun is 1.3e5 lx): radiance is at most
// illuminance x phase-function peak (< 1e5 /sr for g < 0.99) x ..., so 1e6 keeps
// every pixel more than 20 orders of magnitude below the float limit (3.4e38).
constexpr double kMaxRadiometric = 1.0e6;
// Planet radii, m: from a 100 km moon to Jupiter (7.1e7 m).
constexpr double kMinPlanetRadiusMetres = 1.0e5;
constexpr double kMaxPlanetRadiusMetres = 1.0e8;
// Air: Rayleigh scattering at sea level, 1/m: the Earth's is 1.35e-5 at 550 nm;
// 1e-3 (74 times as much) already makes a scale height 8 optical depths thick.
constexpr double kMaxRayleighPerMetre = 1.0e-3;
// Aerosols, 1/m: 1e-2 is a fog with a visibility of 390 m (Koschmieder: 3.9/beta).
constexpr double kMaxMiePerMetre = 1.0e-2;
// Scale heights, m: below 1 m exp(-h/H) overflows 1 km below sea level; above
// 1e6 m the air is uniform over any atmosphere the limits above allow.
constexpr double kMinScaleHeightMetres = 1.0;
constexpr double kMaxScaleHeightMetres = 1.0e6;
// Cloud extinction per unit density, 1/m: 1e3 is a mean free path of 1 mm per unit
// density; the reference renderers step in fractions of a grid spacing.
constexpr double kMaxExtinctionPerDensity = 1.0e3;
// Metaball cloud: densities and iso-values (dimensionless) and the total number of
// balls (the source's cost is per ball; 1e6 balls take minutes).
constexpr double kMaxBallDensity = 1.0e6;
constexpr double kMaxBallCount = 1.0e6;
// Version 3. Lights: a point light of intensity I (Y/sr) gives the irradiance I/d^2
// at distance d; 1e12 Y/sr gives the largest sun illuminance (1e6) at 1 km, and stays
// below 1e30 at 1 nm (the pixel limit is 3.4e38). The same bound per metre of a
// polyline channel. Temperatures: 500 K (dull red, hot smoke) to 100000 K.
constexpr double kMaxLightIntensity = 1.0e12;
constexpr double kMinLightTemperatureKelvin = 500.0;
constexpr double kMaxLightTemperatureKelvin = 100000.0;
// Lights and vertices a scene may hold: next-event estimation samples one light from
// a table of them (cost log N per sample); a lightning channel needs ~1000 vertices.
constexpr std::size_t kMaxLights = 1024;
constexpr std::size_t kMaxPolylineVertices = 100000;
// Emission coefficient per unit field value, Y/(sr m): 1e6 per metre of path keeps the
// pixels finite through 1e9 m of glowing medium (1e15 < 3.4e38).
constexpr double kMaxEmissionPerMetre = 1.0e6;
// Additional media: each one adds a density grid (memory) and a lookup per collision.
constexpr std::size_t kMaxAdditionalMedia = 16;
// Version 4. Occluders: each box is tested by every ray that reaches the bounding volume
// hierarchy's leaf holding it; meshes may hold many triangles each (their limit is the
// glue's, SceneAssets.h).
constexpr std::size_t kMaxOccluders = 4096;
// A mesh's scale (metres per file unit): from nanometres to the length limit; smaller
// scales would make every triangle's area underflow.
constexpr double kMinMeshScale = 1.0e-9;
/// Deepest nesting of arrays and objects a scene file may have. A scene needs 5
/// (scene.medium.density.parameters.Bounds); deeper files are refused before
/// they cost memory or time.
constexpr std::size_t kMaxSceneNesting = 64;

[[noreturn]] void Fail(const std::string& path, const std::string& what)
{
  throw std::invalid_argument(path + ": " + what);
}

std::string Join(const std::vector<std::string>& words)
{
  std::string s;
  for (const auto& w : words)
  {
    s += (s.empty() ? "" : ", ") + w;
  }
  return s;
}

/// A number for a message: JSON's shortest round-trip form, without a trailing ".0".
std::string FormatNumber(double x)
{
  if (std::isnan(x))
  {
    return "nan";
  }
  if (std::isinf(x))
  {
    return x > 0 ? "inf" : "-inf";
  }
  std::string text = Json(x).dump();
  if (text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0)
  {
    text.resize(text.size() - 2); // messages say 90, not 90.0
  }
  return text;
}

/// What a value is, for "expected X, got Y" messages.
std::string Describe(const Json& v)
{
  if (v.is_number())
  {
    return v.dump();
  }
  std::string text = v.dump();
  if (text.size() > 40)
  {
    text = text.substr(0, 37) + "...";
  }
  if (v.is_string())
  {
    return "the string " + text;
  }
  if (v.is_null())
  {
    return "null";
  }
  return std::string(
           v.is_boolean() ? "the boolean " : (v.is_array() ? "the array " : "the object ")) +
    text;
}

//------------------------------------------------------------------------------
// Scalar readers.

struct Range
{
  double Low = -kInf;
  double High = kInf;
  bool LowOpen = false;
  bool HighOpen = false;

  bool Contains(double x) const
  {
    return std::isfinite(x) && (LowOpen ? x > Low : x >= Low) && (HighOpen ? x < High : x <= High);
  }
  std::string Text() const
  {
    const bool hasLow = std::isfinite(Low), hasHigh = std::isfinite(High);
    if (hasLow && hasHigh)
    {
      return std::string("in ") + (LowOpen ? "(" : "[") + FormatNumber(Low) + ", " +
        FormatNumber(High) + (HighOpen ? ")" : "]");
    }
    if (hasLow)
    {
      return (LowOpen ? "> " : ">= ") + FormatNumber(Low);
    }
    if (hasHigh)
    {
      return (HighOpen ? "< " : "<= ") + FormatNumber(High);
    }
    return "";
  }
};

Range Finite()
{
  return Range{};
}
Range AtLeast(double low)
{
  return Range{ low, kInf, false, false };
}
Range Closed(double low, double high)
{
  return Range{ low, high, false, false };
}
Range Open(double low, double high)
{
  return Range{ low, high, true, true };
}
Range Coordinate()
{
  return Closed(-kMaxLengthMetres, kMaxLengthMetres);
}

std::string NumberNoun(const Range& range)
{
  const std::string text = range.Text();
  return text.empty() ? "a finite number" : "a number " + text;
}

double ReadNumber(const Json& v, const std::string& path, const Range& range)
{
  if (!v.is_number())
  {
    Fail(path, "expected " + NumberNoun(range) + ", got " + Describe(v));
  }
  const double x = v.get<double>();
  if (!range.Contains(x))
  {
    Fail(path, "expected " + NumberNoun(range) + ", got " + FormatNumber(x));
  }
  return x;
}

long long ReadInteger(const Json& v, const std::string& path, long long low, long long high)
{
  const std::string noun =
    "an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]";
  if (!v.is_number())
  {
    Fail(path, "expected " + noun + ", got " + Describe(v));
  }
  if (v.is_number_integer() || v.is_number_unsigned())
  {
    // Out of long long range (huge unsigned) falls through to the double test.
    if (v.is_number_integer() && !v.is_number_unsigned())
    {
      const long long n = v.get<long long>();
      if (n < low || n > high)
      {
        Fail(path, "expected " + noun + ", got " + std::to_string(n));
      }
      return n;
    }
    const auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(high) || static_cast<long long>(u) < low)
    {
      Fail(path, "expected " + noun + ", got " + std::to_string(u));
    }
    return static_cast<long long>(u);
  }
  const double x = v.get<double>();
  if (!(std::isfinite(x) && x == std::floor(x) && x >= static_cast<double>(low) &&
        x <= static_cast<double>(high)))
  {
    Fail(path, "expected " + noun + ", got " + FormatNumber(x));
  }
  return static_cast<long long>(x);
}

bool ReadBool(const Json& v, const std::string& path)
{
  if (!v.is_boolean())
  {
    Fail(path, "expected true or false, got " + Describe(v));
  }
  return v.get<bool>();
}

std::string ReadString(const Json& v, const std::string& path, bool allowEmpty = true)
{
  if (!v.is_string())
  {
    Fail(path, "expected a string, got " + Describe(v));
  }
  std::string s = v.get<std::string>();
  if (!allowEmpty && s.empty())
  {
    Fail(path, "expected a non-empty string");
  }
  return s;
}

std::string ReadEnum(const Json& v, const std::string& path, const std::vector<std::string>& known)
{
  if (!v.is_string())
  {
    Fail(path, "expected one of " + Join(known) + " (a string), got " + Describe(v));
  }
  const std::string s = v.get<std::string>();
  if (std::find(known.begin(), known.end(), s) == known.end())
  {
    Fail(path, "unknown value \"" + s + "\" (known: " + Join(known) + ")");
  }
  return s;
}

/// An array of exactly `count` numbers, each in `range`.
std::vector<double> ReadNumbers(
  const Json& v, const std::string& path, std::size_t count, const Range& range)
{
  const std::string noun = "an array of " + std::to_string(count) + " numbers";
  if (!v.is_array())
  {
    Fail(path, "expected " + noun + ", got " + Describe(v));
  }
  if (v.size() != count)
  {
    Fail(path,
      "expected " + noun + ", got " + std::to_string(v.size()) + " element" +
        (v.size() == 1 ? "" : "s"));
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < count; ++i)
  {
    values.push_back(ReadNumber(v[i], path + "[" + std::to_string(i) + "]", range));
  }
  return values;
}

std::array<double, 3> ReadVector3(
  const Json& v, const std::string& path, const Range& range = Finite())
{
  const std::vector<double> x = ReadNumbers(v, path, 3, range);
  return { { x[0], x[1], x[2] } };
}

/// v times a power of two (exact) that brings its largest component into [1, 2):
/// lengths and cross products of any finite vector then neither overflow nor
/// underflow. A zero vector stays zero.
std::array<double, 3> ScaledToOrderOne(const std::array<double, 3>& v)
{
  const double largest = std::max({ std::abs(v[0]), std::abs(v[1]), std::abs(v[2]) });
  if (!(largest > 0.0) || !std::isfinite(largest))
  {
    return v;
  }
  const int exponent = std::ilogb(largest);
  return { { std::ldexp(v[0], -exponent), std::ldexp(v[1], -exponent),
    std::ldexp(v[2], -exponent) } };
}

//------------------------------------------------------------------------------
/// An object whose keys are all known; missing optional keys keep the defaults.
class ObjectReader
{
public:
  ObjectReader(const Json& object, std::string path, std::vector<std::string> known)
    : Object(object)
    , Path(std::move(path))
    , Known(std::move(known))
  {
    if (!this->Object.is_object())
    {
      Fail(this->Path, "expected an object, got " + Describe(this->Object));
    }
    for (const auto& item : this->Object.items())
    {
      if (std::find(this->Known.begin(), this->Known.end(), item.key()) == this->Known.end())
      {
        Fail(this->Key(item.key()), "unknown key (known: " + Join(this->Known) + ")");
      }
    }
  }

  std::string Key(const std::string& key) const { return this->Path + "." + key; }
  const std::string& GetPath() const { return this->Path; }
  bool Has(const std::string& key) const { return this->Object.contains(key); }
  const Json& operator[](const std::string& key) const { return this->Object.at(key); }
  const Json& Require(const std::string& key) const
  {
    if (!this->Has(key))
    {
      Fail(this->Path, "missing required key \"" + key + "\"");
    }
    return this->Object.at(key);
  }

  void Number(const std::string& key, double& target, const Range& range) const
  {
    if (this->Has(key))
    {
      target = ReadNumber(this->Object.at(key), this->Key(key), range);
    }
  }
  void RequiredNumber(const std::string& key, double& target, const Range& range) const
  {
    target = ReadNumber(this->Require(key), this->Key(key), range);
  }
  void Integer(const std::string& key, int& target, int low, int high) const
  {
    if (this->Has(key))
    {
      target = static_cast<int>(ReadInteger(this->Object.at(key), this->Key(key), low, high));
    }
  }
  void Bool(const std::string& key, bool& target) const
  {
    if (this->Has(key))
    {
      target = ReadBool(this->Object.at(key), this->Key(key));
    }
  }
  void Vector3(const std::string& key, std::array<double, 3>& target) const
  {
    if (this->Has(key))
    {
      target = ReadVector3(this->Object.at(key), this->Key(key));
    }
  }

private:
  const Json& Object;
  std::string Path;
  std::vector<std::string> Known;
};

//------------------------------------------------------------------------------
// Metaball cloud parameters: the vtkNimbusMetaballCloudSource properties.

enum class ParameterKind
{
  Integer,
  Real,
  Bool
};

struct ParameterSpec
{
  const char* Name;
  std::size_t Count;
  ParameterKind Kind;
  Range Values;     // per component
  long long IntLow; // for Integer
  long long IntHigh;
};

const std::vector<ParameterSpec>& MetaballParameters()
{
  // Limits follow vtkNimbusMetaballCloudSource::CheckParameters, plus upper bounds
  // that keep a scene renderable (grid size, growth levels, ball counts, lengths
  // within kMaxLengthMetres, densities within kMaxBallDensity).
  // The source's lengths, coordinates and heights are bounded by 1e8 m
  // (vtkNimbusMetaballCloudSource's MaximumLength), tighter than the scene's 1e9 m.
  const double maxMetaballLength = 1.0e8;
  const Range length = Range{ 0.0, maxMetaballLength, true, false };
  const Range lengthOrZero = Closed(0.0, maxMetaballLength);
  const Range coordinate = Closed(-maxMetaballLength, maxMetaballLength);
  static const std::vector<ParameterSpec> specs = {
    { "Dimensions", 3, ParameterKind::Integer, Finite(), 1, 2048 },
    { "Bounds", 6, ParameterKind::Real, coordinate, 0, 0 },
    { "Seed", 1, ParameterKind::Integer, Finite(), std::numeric_limits<std::int32_t>::min(),
      std::numeric_limits<std::int32_t>::max() },
    { "NumberOfLevels", 1, ParameterKind::Integer, Finite(), 0, 10 },
    { "NumberOfBaseBalls", 1, ParameterKind::Integer, Finite(), 1, 100000 },
    { "BaseBallRadiusRange", 2, ParameterKind::Real, length, 0, 0 },
    { "FootprintRadius", 1, ParameterKind::Real, lengthOrZero, 0, 0 },
    { "TowerHeight", 1, ParameterKind::Real, lengthOrZero, 0, 0 },
    { "BallsPerLevel", 1, ParameterKind::Integer, Finite(), 0, 1000000 },
    // Ball counts grow by this factor per level (their total is checked below).
    { "BallCountFactor", 1, ParameterKind::Real, Range{ 0.0, 1000.0, true, false }, 0, 0 },
    // Growth balls are no larger than their parents (the source's range).
    { "RadiusScalePerLevel", 1, ParameterKind::Real, Range{ 0.0, 1.0, true, false }, 0, 0 },
    { "BallDensity", 1, ParameterKind::Real, Closed(0.0, kMaxBallDensity), 0, 0 },
    { "IsoValue", 1, ParameterKind::Real, Closed(-kMaxBallDensity, kMaxBallDensity), 0, 0 },
    { "FlatBase", 1, ParameterKind::Bool, Finite(), 0, 0 },
    { "BaseHeight", 1, ParameterKind::Real, coordinate, 0, 0 },
    { "BaseTransitionThickness", 1, ParameterKind::Real, lengthOrZero, 0, 0 },
  };
  return specs;
}

std::vector<std::string> MetaballParameterNames()
{
  std::vector<std::string> names;
  for (const auto& spec : MetaballParameters())
  {
    names.emplace_back(spec.Name);
  }
  return names;
}

double ReadParameterComponent(const Json& v, const std::string& path, const ParameterSpec& spec)
{
  switch (spec.Kind)
  {
    case ParameterKind::Integer:
      return static_cast<double>(ReadInteger(v, path, spec.IntLow, spec.IntHigh));
    case ParameterKind::Bool:
      if (v.is_number() && (v.get<double>() == 0.0 || v.get<double>() == 1.0))
      {
        return v.get<double>();
      }
      return ReadBool(v, path) ? 1.0 : 0.0;
    case ParameterKind::Real:
      break;
  }
  return ReadNumber(v, path, spec.Values);
}

std::vector<double> ReadParameter(const Json& v, const std::string& path, const ParameterSpec& spec)
{
  std::vector<double> values;
  if (v.is_array())
  {
    if (v.size() != spec.Count)
    {
      Fail(path,
        "expected " + std::to_string(spec.Count) + " value" + (spec.Count == 1 ? "" : "s") +
          ", got " + std::to_string(v.size()));
    }
    for (std::size_t i = 0; i < v.size(); ++i)
    {
      values.push_back(ReadParameterComponent(v[i], path + "[" + std::to_string(i) + "]", spec));
    }
  }
  else if (spec.Count == 1)
  {
    values.push_back(ReadParameterComponent(v, path, spec));
  }
  else
  {
    Fail(
      path, "expected an array of " + std::to_string(spec.Count) + " numbers, got " + Describe(v));
  }

  const std::string name = spec.Name;
  if (name == "Bounds")
  {
    static const char* axes[] = { "x", "y", "z" };
    for (int a = 0; a < 3; ++a)
    {
      if (!(values[2 * a] < values[2 * a + 1]))
      {
        Fail(path,
          std::string("expected min < max on every axis, axis ") + axes[a] + " has (" +
            FormatNumber(values[2 * a]) + ", " + FormatNumber(values[2 * a + 1]) + ")");
      }
    }
  }
  else if (name == "BaseBallRadiusRange" && !(values[0] <= values[1]))
  {
    Fail(path,
      "expected min <= max, got (" + FormatNumber(values[0]) + ", " + FormatNumber(values[1]) +
        ")");
  }
  else if (name == "Dimensions" && values[0] * values[1] * values[2] > 1073741824.0)
  {
    Fail(path,
      "too many grid points (" + FormatNumber(values[0] * values[1] * values[2]) + " > 2^30)");
  }
  return values;
}

std::vector<std::pair<std::string, std::vector<double>>> ReadMetaballParameters(
  const Json& v, const std::string& path)
{
  const std::vector<std::string> names = MetaballParameterNames();
  if (!v.is_object())
  {
    Fail(path, "expected an object of vtkNimbusMetaballCloudSource properties, got " + Describe(v));
  }
  for (const auto& item : v.items())
  {
    if (std::find(names.begin(), names.end(), item.key()) == names.end())
    {
      Fail(
        path + "." + item.key(), "unknown metaball_cloud parameter (known: " + Join(names) + ")");
    }
  }
  // Stored in the source's property order: the canonical form does not depend on
  // the order in the text.
  std::vector<std::pair<std::string, std::vector<double>>> parameters;
  for (const auto& spec : MetaballParameters())
  {
    if (v.contains(spec.Name))
    {
      parameters.emplace_back(
        spec.Name, ReadParameter(v.at(spec.Name), path + "." + spec.Name, spec));
    }
  }
  // The number of balls the source makes: the base balls, then BallsPerLevel times
  // BallCountFactor^(level - 1) at each growth level (the source's defaults where
  // a parameter is not given: 10, 3 levels, 60, 2).
  double baseBalls = 10.0, levels = 3.0, perLevel = 60.0, factor = 2.0;
  for (const auto& p : parameters)
  {
    const double x = p.second[0];
    baseBalls = p.first == "NumberOfBaseBalls" ? x : baseBalls;
    levels = p.first == "NumberOfLevels" ? x : levels;
    perLevel = p.first == "BallsPerLevel" ? x : perLevel;
    factor = p.first == "BallCountFactor" ? x : factor;
  }
  double total = baseBalls, count = perLevel;
  for (int level = 1; level <= static_cast<int>(levels); ++level, count *= factor)
  {
    total += count;
  }
  if (!(total <= kMaxBallCount))
  {
    Fail(path,
      "too many metaballs: NumberOfBaseBalls + BallsPerLevel x BallCountFactor^(level - 1) "
      "over NumberOfLevels levels makes " +
        FormatNumber(total) + ", more than " + FormatNumber(kMaxBallCount));
  }
  return parameters;
}

//------------------------------------------------------------------------------
// Sections.

const std::vector<std::string> kPhaseTypes = { "isotropic", "rayleigh", "henyey_greenstein",
  "cornette_shanks" };
const std::vector<std::string> kDensityTypes = { "file", "metaball_cloud" };
const std::vector<std::string> kBackgroundTypes = { "black", "constant", "atmosphere" };

std::array<double, 3> Subtract(const std::array<double, 3>& a, const std::array<double, 3>& b)
{
  return { { a[0] - b[0], a[1] - b[1], a[2] - b[2] } };
}

CameraDescription ReadCamera(const Json& v, const std::string& path)
{
  const ObjectReader r(
    v, path, { "position", "focal_point", "view_up", "view_angle", "width", "height" });
  CameraDescription c;
  // Each coordinate is read and range-checked before the view direction is formed,
  // so a huge coordinate is named as such (and their difference cannot overflow).
  c.Position = ReadVector3(r.Require("position"), r.Key("position"), Coordinate());
  c.FocalPoint = ReadVector3(r.Require("focal_point"), r.Key("focal_point"), Coordinate());
  r.Vector3("view_up", c.ViewUp);
  r.Number("view_angle", c.ViewAngle, Open(0.0, 180.0));
  r.Integer("width", c.Width, 1, 16384);
  r.Integer("height", c.Height, 1, 16384);

  const std::array<double, 3> view = ScaledToOrderOne(Subtract(c.FocalPoint, c.Position));
  const double viewLength = Length(view);
  if (!(viewLength > 0.0))
  {
    Fail(r.Key("focal_point"), "must differ from camera.position");
  }
  const std::array<double, 3> up = ScaledToOrderOne(c.ViewUp);
  const std::array<double, 3> cross{ { view[1] * up[2] - view[2] * up[1],
    view[2] * up[0] - view[0] * up[2], view[0] * up[1] - view[1] * up[0] } };
  if (!(Length(cross) > 1e-6 * viewLength * Length(up)) || !std::isfinite(Length(cross)))
  {
    Fail(r.Key("view_up"), "must be non-zero and not parallel to the view direction");
  }
  return c;
}

/// A file's path as the description stores it: relative ones resolved against `base`
/// (the current directory when empty), absolute and lexically normalised.
std::string ResolvedPath(const std::string& given, const std::string& base)
{
  namespace fs = std::filesystem;
  fs::path p(given);
  if (p.is_relative())
  {
    p = (base.empty() ? fs::current_path() : fs::absolute(fs::path(base))) / p;
  }
  return p.lexically_normal().string();
}

/// A non-empty file path whose extension (any case) is one of `extensions`, resolved.
std::string ReadFilePath(const Json& v, const std::string& path, const std::string& base,
  const std::vector<std::string>& extensions, const std::string& noun)
{
  const std::string given = ReadString(v, path, false);
  std::string extension = std::filesystem::path(given).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::find(extensions.begin(), extensions.end(), extension) == extensions.end())
  {
    std::string list;
    for (std::size_t i = 0; i < extensions.size(); ++i)
    {
      list += (i == 0 ? "" : (i + 1 == extensions.size() ? " or " : ", ")) + extensions[i];
    }
    Fail(path, "expected " + noun + " file (" + list + "), got " + Describe(v));
  }
  return ResolvedPath(given, base);
}

DensitySourceDescription ReadDensity(
  const Json& v, const std::string& path, const std::string& base)
{
  const ObjectReader r(v, path, { "type", "path", "array", "parameters" });
  DensitySourceDescription d;
  d.Type = ReadEnum(r.Require("type"), r.Key("type"), kDensityTypes);
  if (r.Has("array"))
  {
    d.ArrayName = ReadString(r["array"], r.Key("array"), false);
  }
  if (d.Type == "file")
  {
    d.Path = ResolvedPath(ReadString(r.Require("path"), r.Key("path"), false), base);
    if (r.Has("parameters") && !(r["parameters"].is_object() && r["parameters"].empty()))
    {
      Fail(r.Key("parameters"), "only used by type \"metaball_cloud\" (this density is \"file\")");
    }
  }
  else // metaball_cloud
  {
    if (r.Has("path") && !(r["path"].is_string() && r["path"].get<std::string>().empty()))
    {
      Fail(r.Key("path"), "only used by type \"file\" (this density is \"metaball_cloud\")");
    }
    if (d.ArrayName != "density")
    {
      Fail(r.Key("array"),
        "a metaball_cloud's array is always \"density\", got \"" + d.ArrayName + "\"");
    }
    if (r.Has("parameters"))
    {
      d.Parameters = ReadMetaballParameters(r["parameters"], r.Key("parameters"));
    }
  }
  return d;
}

PhaseComponentDescription ReadPhaseComponent(const Json& v, const std::string& path)
{
  const ObjectReader r(v, path, { "type", "g", "weight" });
  PhaseComponentDescription c;
  c.Type = ReadEnum(r.Require("type"), r.Key("type"), kPhaseTypes);
  if (c.Type == "henyey_greenstein" || c.Type == "cornette_shanks")
  {
    r.RequiredNumber("g", c.G, Closed(-1.0, 1.0));
  }
  else
  {
    r.Number("g", c.G, Closed(-1.0, 1.0)); // ignored by isotropic and rayleigh
  }
  // Relative (normalised over the components); bounded so that their sum is finite.
  r.Number("weight", c.Weight, Closed(0.0, kMaxRadiometric));
  return c;
}

std::vector<PhaseComponentDescription> ReadPhase(const Json& phase, const std::string& phasePath)
{
  std::vector<PhaseComponentDescription> components;
  if (phase.is_object())
  {
    components.push_back(ReadPhaseComponent(phase, phasePath));
  }
  else if (phase.is_array())
  {
    if (phase.empty())
    {
      Fail(phasePath, "expected at least one phase component, got an empty array");
    }
    for (std::size_t i = 0; i < phase.size(); ++i)
    {
      components.push_back(ReadPhaseComponent(phase[i], phasePath + "[" + std::to_string(i) + "]"));
    }
  }
  else
  {
    Fail(
      phasePath, "expected a phase component (object) or an array of them, got " + Describe(phase));
  }
  double total = 0.0;
  for (const auto& c : components)
  {
    total += c.Weight;
  }
  if (!(total > 0.0) || !std::isfinite(total))
  {
    Fail(phasePath, "the weights must not all be zero");
  }
  return components;
}

const std::vector<std::string> kEmissionSources = { "from_density", "array", "blackbody" };

/// Version 3: medium.emission and media[i].emission.
EmissionDescription ReadEmission(
  const Json& v, const std::string& path, const DensitySourceDescription& density)
{
  const ObjectReader r(v, path, { "source", "array", "radiance_per_metre", "temperature_kelvin" });
  EmissionDescription e;
  e.Enabled = true;
  e.Source = ReadEnum(r.Require("source"), r.Key("source"), kEmissionSources);
  if (e.Source == "array" || e.Source == "blackbody")
  {
    if (density.Type != "file")
    {
      Fail(r.Key("source"),
        "\"" + e.Source +
          "\" reads another point-data array of the density's .vti, so it needs a "
          "\"file\" density (this density is \"" +
          density.Type + "\"; use \"from_density\")");
    }
    e.ArrayName = ReadString(r.Require("array"), r.Key("array"), false);
  }
  else if (r.Has("array"))
  {
    Fail(r.Key("array"),
      "only used by sources \"array\" and \"blackbody\" (this emission is \"from_density\")");
  }
  r.RequiredNumber("radiance_per_metre", e.RadiancePerMetre, Closed(0.0, kMaxEmissionPerMetre));
  r.Number("temperature_kelvin", e.TemperatureKelvin,
    Closed(kMinLightTemperatureKelvin, kMaxLightTemperatureKelvin));
  return e;
}

/// A key that only version `needed` knows, in an older file: the same error as any
/// unknown key, saying which version it needs.
void RefuseNewerKey(const Json& v, const std::string& path, const std::string& key, int version,
  int needed, const std::vector<std::string>& known)
{
  if (version < needed && v.is_object() && v.contains(key))
  {
    Fail(path + "." + key,
      "unknown key (known: " + Join(known) + "); \"" + key + "\" needs format version " +
        std::to_string(needed) + " (\"nimbus_scene\": " + std::to_string(needed) +
        "), this file is version " + std::to_string(version));
  }
}

void RefuseVersion3Key(const Json& v, const std::string& path, const std::string& key, int version,
  const std::vector<std::string>& known)
{
  RefuseNewerKey(v, path, key, version, 3, known);
}

/// What the main medium and an additional one share: density, extinction, albedo,
/// phase and (version 3) emission.
template <class Medium>
void ReadMediumOptics(const ObjectReader& r, const std::string& base, Medium& m)
{
  m.Density = ReadDensity(r.Require("density"), r.Key("density"), base);
  r.RequiredNumber(
    "extinction_per_density", m.ExtinctionPerDensity, Closed(0.0, kMaxExtinctionPerDensity));
  r.Number("single_scattering_albedo", m.SingleScatteringAlbedo, Closed(0.0, 1.0));
  if (r.Has("phase"))
  {
    m.Phase = ReadPhase(r["phase"], r.Key("phase"));
  }
  if (r.Has("emission"))
  {
    m.Emission = ReadEmission(r["emission"], r.Key("emission"), m.Density);
  }
}

MediumDescription ReadMedium(
  const Json& v, const std::string& path, const std::string& base, int version)
{
  std::vector<std::string> known = { "density", "extinction_per_density",
    "single_scattering_albedo", "phase", "multiple_scattering_constant" };
  RefuseVersion3Key(v, path, "emission", version, known);
  if (version >= 3)
  {
    known.push_back("emission");
  }
  const ObjectReader r(v, path, known);
  MediumDescription m;
  ReadMediumOptics(r, base, m);
  r.Number("multiple_scattering_constant", m.MultipleScatteringConstant, Closed(0.0, 100.0));
  return m;
}

AdditionalMediumDescription ReadAdditionalMedium(
  const Json& v, const std::string& path, const std::string& base)
{
  const ObjectReader r(v, path,
    { "density", "extinction_per_density", "single_scattering_albedo", "phase", "emission" });
  AdditionalMediumDescription m;
  ReadMediumOptics(r, base, m);
  return m;
}

/// An array of at most `limit` elements.
void RequireArray(const Json& v, const std::string& path, std::size_t limit, const char* what)
{
  if (!v.is_array())
  {
    Fail(path, std::string("expected an array of ") + what + ", got " + Describe(v));
  }
  if (v.size() > limit)
  {
    Fail(path,
      "expected at most " + std::to_string(limit) + " " + what + ", got " +
        std::to_string(v.size()));
  }
}

/// A metaball parameter's value as the source will use it: the given one, else the
/// source's default (vtkNimbusMetaballCloudSource; docs/scene-format.md).
std::vector<double> EffectiveMetaballParameter(
  const DensitySourceDescription& d, const std::string& name)
{
  for (const auto& p : d.Parameters)
  {
    if (p.first == name)
    {
      return p.second;
    }
  }
  if (name == "Dimensions")
  {
    return { 96.0, 96.0, 64.0 };
  }
  return { -1500.0, 1500.0, -1500.0, 1500.0, 800.0, 2800.0 }; // Bounds
}

/// Every medium is on the main medium's grid. Between two metaball clouds that is known
/// here (the grid is their Dimensions and Bounds); a file's grid is checked by the
/// renderer (RenderContext), which reads it.
void RequireSameMetaballGrid(const DensitySourceDescription& main,
  const DensitySourceDescription& extra, const std::string& path)
{
  if (main.Type != "metaball_cloud" || extra.Type != "metaball_cloud")
  {
    return;
  }
  for (const char* name : { "Dimensions", "Bounds" })
  {
    const std::vector<double> a = EffectiveMetaballParameter(main, name);
    const std::vector<double> b = EffectiveMetaballParameter(extra, name);
    if (a != b)
    {
      std::string mine, theirs;
      for (std::size_t k = 0; k < a.size(); ++k)
      {
        mine += (k ? ", " : "") + FormatNumber(a[k]);
      }
      for (std::size_t k = 0; k < b.size(); ++k)
      {
        theirs += (k ? ", " : "") + FormatNumber(b[k]);
      }
      Fail(path + ".density.parameters." + name,
        std::string("every medium must be on the main medium's grid: medium.density's ") + name +
          " is [" + mine + "], this one's [" + theirs + "]");
    }
  }
}

const std::vector<std::string> kLightTypes3 = { "point", "polyline" };
const std::vector<std::string> kLightTypes = { "point", "polyline", "spot" };
// Light maps: images vtkImageReader2Factory reads and SceneAssets.cxx decodes.
const std::vector<std::string> kLightMapExtensions = { ".png", ".pgm", ".ppm", ".pnm" };
const std::vector<std::string> kMeshExtensions = { ".ply", ".obj" };

/// Version 4: a spot light's keys (the type already read).
void ReadSpot(const Json& v, const std::string& path, const std::string& base, LightDescription& l)
{
  const ObjectReader r(v, path,
    { "type", "position", "direction", "cone_angle_degrees", "edge_degrees", "intensity",
      "temperature_kelvin", "light_map" });
  l.Position = ReadVector3(r.Require("position"), r.Key("position"), Coordinate());
  l.Direction = ReadVector3(r.Require("direction"), r.Key("direction"));
  if (!(Length(ScaledToOrderOne(l.Direction)) > 0.0))
  {
    Fail(r.Key("direction"), "must be a non-zero vector (the beam's axis, away from the light)");
  }
  const Json& cone = r.Require("cone_angle_degrees");
  if (cone.is_number() && cone.get<double>() >= 90.0)
  {
    Fail(r.Key("cone_angle_degrees"),
      "expected a number in (0, 90), got " + FormatNumber(cone.get<double>()) +
        " (a cone of 90 degrees or more lights every direction: use a \"point\" light)");
  }
  l.ConeAngleDegrees = ReadNumber(cone, r.Key("cone_angle_degrees"), Open(0.0, 90.0));
  r.Number("edge_degrees", l.EdgeDegrees, Closed(0.0, 90.0));
  if (!(l.EdgeDegrees <= l.ConeAngleDegrees))
  {
    Fail(r.Key("edge_degrees"),
      "expected a number in [0, cone_angle_degrees] = [0, " + FormatNumber(l.ConeAngleDegrees) +
        "] (the soft edge lies inside the cone), got " + FormatNumber(l.EdgeDegrees));
  }
  r.RequiredNumber("intensity", l.Intensity, Closed(0.0, kMaxLightIntensity));
  r.Number("temperature_kelvin", l.TemperatureKelvin,
    Closed(kMinLightTemperatureKelvin, kMaxLightTemperatureKelvin));
  if (r.Has("light_map"))
  {
    l.LightMap.Path =
      ReadFilePath(r["light_map"], r.Key("light_map"), base, kLightMapExtensions, "an image");
  }
}

LightDescription ReadLight(
  const Json& v, const std::string& path, const std::string& base, int version)
{
  if (!v.is_object())
  {
    Fail(path, "expected an object, got " + Describe(v));
  }
  LightDescription l;
  const std::vector<std::string>& types = version >= 4 ? kLightTypes : kLightTypes3;
  if (!v.contains("type"))
  {
    Fail(path, "missing required key \"type\" (known: " + Join(types) + ")");
  }
  if (version < 4 && v.at("type") == "spot")
  {
    Fail(path + ".type",
      "unknown value \"spot\" (known: " + Join(types) +
        "); \"spot\" needs format version 4 (\"nimbus_scene\": 4), this file is version " +
        std::to_string(version));
  }
  l.Type = ReadEnum(v.at("type"), path + ".type", types);
  const Range temperature = Closed(kMinLightTemperatureKelvin, kMaxLightTemperatureKelvin);
  const Range intensity = Closed(0.0, kMaxLightIntensity);
  if (l.Type == "point")
  {
    const ObjectReader r(v, path, { "type", "position", "intensity", "temperature_kelvin" });
    l.Position = ReadVector3(r.Require("position"), r.Key("position"), Coordinate());
    r.RequiredNumber("intensity", l.Intensity, intensity);
    r.Number("temperature_kelvin", l.TemperatureKelvin, temperature);
    return l;
  }
  if (l.Type == "spot")
  {
    ReadSpot(v, path, base, l);
    return l;
  }
  const ObjectReader r(
    v, path, { "type", "vertices", "intensity_per_metre", "temperature_kelvin" });
  const Json& vertices = r.Require("vertices");
  const std::string verticesPath = r.Key("vertices");
  RequireArray(vertices, verticesPath, kMaxPolylineVertices, "vertices ([x, y, z], m)");
  if (vertices.size() < 2)
  {
    Fail(verticesPath, "expected at least 2 vertices, got " + std::to_string(vertices.size()));
  }
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    l.Vertices.push_back(
      ReadVector3(vertices[i], verticesPath + "[" + std::to_string(i) + "]", Coordinate()));
    if (i > 0 && l.Vertices[i] == l.Vertices[i - 1])
    {
      Fail(verticesPath + "[" + std::to_string(i) + "]",
        "a segment of zero length: the same point as vertex " + std::to_string(i - 1) +
          " (drop one of them)");
    }
  }
  r.RequiredNumber("intensity_per_metre", l.IntensityPerMetre, intensity);
  r.Number("temperature_kelvin", l.TemperatureKelvin, temperature);
  return l;
}

const std::vector<std::string> kOccluderTypes = { "box", "mesh" };

/// Version 4: one occluder (an opaque Lambertian box or mesh).
OccluderDescription ReadOccluder(const Json& v, const std::string& path, const std::string& base)
{
  if (!v.is_object())
  {
    Fail(path, "expected an object, got " + Describe(v));
  }
  OccluderDescription o;
  if (!v.contains("type"))
  {
    Fail(path, "missing required key \"type\" (known: " + Join(kOccluderTypes) + ")");
  }
  o.Type = ReadEnum(v.at("type"), path + ".type", kOccluderTypes);
  if (o.Type == "box")
  {
    const ObjectReader r(v, path, { "type", "min", "max", "albedo" });
    o.Min = ReadVector3(r.Require("min"), r.Key("min"), Coordinate());
    o.Max = ReadVector3(r.Require("max"), r.Key("max"), Coordinate());
    static const char* axes[] = { "x", "y", "z" };
    for (int a = 0; a < 3; ++a)
    {
      if (!(o.Min[a] <= o.Max[a]))
      {
        Fail(r.Key("max"),
          std::string("expected max >= min on every axis, axis ") + axes[a] + " has min " +
            FormatNumber(o.Min[a]) + " and max " + FormatNumber(o.Max[a]));
      }
    }
    r.Number("albedo", o.Albedo, Closed(0.0, 1.0));
    return o;
  }
  const ObjectReader r(v, path, { "type", "path", "albedo", "translate", "scale" });
  o.Path = ReadFilePath(r.Require("path"), r.Key("path"), base, kMeshExtensions, "a mesh");
  r.Number("albedo", o.Albedo, Closed(0.0, 1.0));
  if (r.Has("translate"))
  {
    o.Translate = ReadVector3(r["translate"], r.Key("translate"), Coordinate());
  }
  // A metre per nanometre to a gigametre per unit: areas of ~1e-18 m^2 and more.
  r.Number("scale", o.Scale, Closed(kMinMeshScale, kMaxLengthMetres));
  return o;
}

SunParameters ReadSun(const Json& v, const std::string& path)
{
  const ObjectReader r(v, path,
    { "azimuth_degrees", "elevation_degrees", "direction", "illuminance", "temperature_kelvin" });
  SunParameters s;
  if (r.Has("direction"))
  {
    if (r.Has("azimuth_degrees") || r.Has("elevation_degrees"))
    {
      Fail(r.Key("direction"),
        "give either direction or azimuth_degrees and elevation_degrees, not both");
    }
    const std::array<double, 3> d =
      ScaledToOrderOne(ReadVector3(r["direction"], r.Key("direction")));
    const double horizontal = std::hypot(d[0], d[1]);
    if (!(Length(d) > 0.0))
    {
      Fail(r.Key("direction"), "must be a non-zero vector (toward the sun)");
    }
    s.ElevationDegrees = std::atan2(d[2], horizontal) / kDegree;
    double azimuth = horizontal > 0.0 ? std::atan2(d[0], d[1]) / kDegree : 0.0;
    if (azimuth < 0.0)
    {
      azimuth += 360.0;
    }
    if (azimuth >= 360.0)
    {
      azimuth -= 360.0;
    }
    s.AzimuthDegrees = azimuth + 0.0; // no -0
  }
  else
  {
    r.RequiredNumber("elevation_degrees", s.ElevationDegrees, Closed(-90.0, 90.0));
    r.RequiredNumber("azimuth_degrees", s.AzimuthDegrees, Closed(-360.0, 360.0));
  }
  r.Number("illuminance", s.Illuminance, Closed(0.0, kMaxRadiometric));
  r.Number("temperature_kelvin", s.TemperatureKelvin, Closed(1000.0, 100000.0));
  return s;
}

SceneAtmosphere ReadAtmosphere(const Json& v, const std::string& path)
{
  const ObjectReader r(v, path,
    { "enabled", "scene_altitude_metres", "earth_radius_metres", "top_radius_metres",
      "rayleigh_scattering_per_metre", "rayleigh_scale_height_metres", "mie_scattering_per_metre",
      "mie_scale_height_metres", "mie_albedo", "mie_g" });
  SceneAtmosphere a;
  r.Bool("enabled", a.Enabled);
  r.Number("scene_altitude_metres", a.SceneAltitudeMetres, AtLeast(0.0));
  const Range planet = Closed(kMinPlanetRadiusMetres, kMaxPlanetRadiusMetres);
  const Range scaleHeight = Closed(kMinScaleHeightMetres, kMaxScaleHeightMetres);
  r.Number("earth_radius_metres", a.EarthRadiusMetres, planet);
  r.Number("top_radius_metres", a.TopRadiusMetres, planet);
  r.Number("rayleigh_scattering_per_metre", a.RayleighScatteringPerMetre,
    Closed(0.0, kMaxRayleighPerMetre));
  r.Number("rayleigh_scale_height_metres", a.RayleighScaleHeightMetres, scaleHeight);
  r.Number("mie_scattering_per_metre", a.MieScatteringPerMetre, Closed(0.0, kMaxMiePerMetre));
  r.Number("mie_scale_height_metres", a.MieScaleHeightMetres, scaleHeight);
  r.Number("mie_albedo", a.MieAlbedo, Range{ 0.0, 1.0, true, false });
  r.Number("mie_g", a.MieG, Open(-1.0, 1.0));
  if (!(a.TopRadiusMetres > a.EarthRadiusMetres))
  {
    Fail(r.Key("top_radius_metres"),
      "must be greater than earth_radius_metres (" + FormatNumber(a.EarthRadiusMetres) + "), got " +
        FormatNumber(a.TopRadiusMetres));
  }
  if (!(a.SceneAltitudeMetres < a.TopRadiusMetres - a.EarthRadiusMetres))
  {
    Fail(r.Key("scene_altitude_metres"),
      "must be below the top of the atmosphere (" +
        FormatNumber(a.TopRadiusMetres - a.EarthRadiusMetres) + " m), got " +
        FormatNumber(a.SceneAltitudeMetres));
  }
  return a;
}

GroundDescription ReadGround(const Json& v, const std::string& path)
{
  const ObjectReader r(v, path, { "enabled", "height", "albedo" });
  GroundDescription g;
  r.Bool("enabled", g.Enabled);
  r.Number("height", g.Height, Coordinate());
  r.Number("albedo", g.Albedo, Closed(0.0, 1.0));
  return g;
}

BackgroundDescription ReadBackground(const Json& v, const std::string& path)
{
  const ObjectReader r(v, path, { "type", "radiance" });
  BackgroundDescription b;
  if (r.Has("type"))
  {
    b.Type = ReadEnum(r["type"], r.Key("type"), kBackgroundTypes);
  }
  r.Number("radiance", b.Radiance, Closed(0.0, kMaxRadiometric));
  return b;
}

//------------------------------------------------------------------------------
/// Rejects duplicate keys (the JSON library would silently keep one) and nesting
/// deeper than kMaxSceneNesting, and keeps track of where the parser is, to name
/// the key path of a syntax error. Each level holds only its own key or index (the
/// path is joined when a message needs it), so memory is linear in the depth.
class ParseTracker
{
public:
  bool operator()(int depth, Json::parse_event_t event, Json& parsed)
  {
    using Event = Json::parse_event_t;
    switch (event)
    {
      case Event::object_start:
      case Event::array_start:
        if (this->Stack.size() >= kMaxSceneNesting || depth > static_cast<int>(kMaxSceneNesting))
        {
          Fail(this->CurrentPath(),
            "arrays and objects nested deeper than " + std::to_string(kMaxSceneNesting) +
              " levels (a scene needs 5)");
        }
        this->Stack.push_back(Frame{ event == Event::array_start, 0, {}, {} });
        break;
      case Event::key:
      {
        Frame& frame = this->Stack.back();
        frame.Key = parsed.get<std::string>();
        if (!frame.Keys.insert(frame.Key).second)
        {
          Fail(this->CurrentPath(), "duplicate key");
        }
        break;
      }
      case Event::object_end:
      case Event::array_end:
        this->Stack.pop_back();
        this->AfterValue();
        break;
      case Event::value:
        this->AfterValue();
        break;
    }
    return true;
  }

  /// The path of the value being parsed now.
  std::string CurrentPath() const
  {
    std::string path = "scene";
    for (std::size_t level = 0; level < this->Stack.size(); ++level)
    {
      const Frame& frame = this->Stack[level];
      const bool innermost = level + 1 == this->Stack.size();
      if (frame.IsArray)
      {
        // An enclosing array's current element is the one being parsed (Index).
        path += "[" + std::to_string(frame.Index) + "]";
      }
      else if (!frame.Key.empty() || !innermost)
      {
        path += "." + frame.Key;
      }
    }
    return path;
  }

private:
  struct Frame
  {
    bool IsArray;
    std::size_t Index;
    std::set<std::string> Keys;
    std::string Key;
  };

  void AfterValue()
  {
    if (this->Stack.empty())
    {
      return;
    }
    Frame& frame = this->Stack.back();
    if (frame.IsArray)
    {
      ++frame.Index;
    }
    else
    {
      frame.Key.clear(); // between members: an error there belongs to the object
    }
  }

  std::vector<Frame> Stack;
};

std::string WithoutJsonPrefix(const std::string& what)
{
  // "[json.exception.parse_error.101] parse error at line 1, ..." -> "parse error at ..."
  const auto end = what.find("] ");
  return what.rfind("[json.exception.", 0) == 0 && end != std::string::npos ? what.substr(end + 2)
                                                                            : what;
}

//------------------------------------------------------------------------------
// Writing.

Json Vector3Json(const std::array<double, 3>& v)
{
  return Json::array({ v[0], v[1], v[2] });
}

Json ParameterJson(const std::string& name, const std::vector<double>& values)
{
  ParameterKind kind = ParameterKind::Real;
  std::size_t count = 0;
  for (const auto& spec : MetaballParameters())
  {
    if (name == spec.Name)
    {
      kind = spec.Kind;
      count = spec.Count;
    }
  }
  auto component = [kind](double x) -> Json
  {
    if (kind == ParameterKind::Bool && (x == 0.0 || x == 1.0))
    {
      return Json(x != 0.0);
    }
    if (kind == ParameterKind::Integer && std::isfinite(x) && x == std::floor(x) &&
      std::abs(x) < 9.0e15)
    {
      return Json(static_cast<long long>(x));
    }
    return Json(x);
  };
  if (count == 1 && values.size() == 1)
  {
    return component(values[0]);
  }
  Json array = Json::array();
  for (double x : values)
  {
    array.push_back(component(x));
  }
  return array;
}

Json DensityJson(const DensitySourceDescription& d)
{
  Json density;
  density["type"] = d.Type;
  density["path"] = d.Path;
  density["array"] = d.ArrayName;
  density["parameters"] = Json::object();
  // Canonical order: the source's property order, then any others as stored.
  std::vector<std::pair<std::string, std::vector<double>>> parameters = d.Parameters;
  const std::vector<std::string> names = MetaballParameterNames();
  auto rank = [&names](const std::string& name)
  { return std::find(names.begin(), names.end(), name) - names.begin(); };
  std::stable_sort(parameters.begin(), parameters.end(),
    [&rank](const auto& a, const auto& b) { return rank(a.first) < rank(b.first); });
  for (const auto& p : parameters)
  {
    density["parameters"][p.first] = ParameterJson(p.first, p.second);
  }
  return density;
}

Json PhaseJson(const std::vector<PhaseComponentDescription>& phase)
{
  Json array = Json::array();
  for (const auto& p : phase)
  {
    Json component;
    component["type"] = p.Type;
    component["g"] = p.G;
    component["weight"] = p.Weight;
    array.push_back(component);
  }
  return array;
}

Json EmissionJson(const EmissionDescription& e)
{
  Json emission;
  emission["source"] = e.Source;
  if (e.Source == "array" || e.Source == "blackbody")
  {
    emission["array"] = e.ArrayName;
  }
  emission["radiance_per_metre"] = e.RadiancePerMetre;
  emission["temperature_kelvin"] = e.TemperatureKelvin;
  return emission;
}

Json ToJson(const SceneDescription& s)
{
  Json j;
  j["nimbus_scene"] = SceneDescription::kFormatVersion;
  j["name"] = s.Name;
  j["description"] = s.Description;

  const CameraDescription& c = s.Camera;
  j["camera"] = Json::object();
  j["camera"]["position"] = Vector3Json(c.Position);
  j["camera"]["focal_point"] = Vector3Json(c.FocalPoint);
  j["camera"]["view_up"] = Vector3Json(c.ViewUp);
  j["camera"]["view_angle"] = c.ViewAngle;
  j["camera"]["width"] = c.Width;
  j["camera"]["height"] = c.Height;

  const MediumDescription& m = s.Medium;
  j["medium"]["density"] = DensityJson(m.Density);
  j["medium"]["extinction_per_density"] = m.ExtinctionPerDensity;
  j["medium"]["single_scattering_albedo"] = m.SingleScatteringAlbedo;
  if (m.MultipleScatteringConstant != 0.0)
  {
    j["medium"]["multiple_scattering_constant"] = m.MultipleScatteringConstant;
  }
  j["medium"]["phase"] = PhaseJson(m.Phase);
  if (m.Emission.Enabled)
  {
    j["medium"]["emission"] = EmissionJson(m.Emission);
  }

  j["sun"]["azimuth_degrees"] = s.Sun.AzimuthDegrees;
  j["sun"]["elevation_degrees"] = s.Sun.ElevationDegrees;
  j["sun"]["illuminance"] = s.Sun.Illuminance;
  j["sun"]["temperature_kelvin"] = s.Sun.TemperatureKelvin;

  const SceneAtmosphere& a = s.Atmosphere;
  j["atmosphere"]["enabled"] = a.Enabled;
  j["atmosphere"]["scene_altitude_metres"] = a.SceneAltitudeMetres;
  j["atmosphere"]["earth_radius_metres"] = a.EarthRadiusMetres;
  j["atmosphere"]["top_radius_metres"] = a.TopRadiusMetres;
  j["atmosphere"]["rayleigh_scattering_per_metre"] = a.RayleighScatteringPerMetre;
  j["atmosphere"]["rayleigh_scale_height_metres"] = a.RayleighScaleHeightMetres;
  j["atmosphere"]["mie_scattering_per_metre"] = a.MieScatteringPerMetre;
  j["atmosphere"]["mie_scale_height_metres"] = a.MieScaleHeightMetres;
  j["atmosphere"]["mie_albedo"] = a.MieAlbedo;
  j["atmosphere"]["mie_g"] = a.MieG;

  j["ground"]["enabled"] = s.Ground.Enabled;
  j["ground"]["height"] = s.Ground.Height;
  j["ground"]["albedo"] = s.Ground.Albedo;

  j["background"]["type"] = s.Background.Type;
  j["background"]["radiance"] = s.Background.Radiance;

  j["spectral_samples"] = s.SpectralSamples;

  // Version 3's keys only when used: a scene without them reads as a version-2 file
  // would (and its canonical text differs from version 2's only in the version).
  if (!s.Lights.empty())
  {
    j["lights"] = Json::array();
  }
  for (const LightDescription& l : s.Lights)
  {
    Json light;
    light["type"] = l.Type;
    if (l.Type == "point")
    {
      light["position"] = Vector3Json(l.Position);
      light["intensity"] = l.Intensity;
    }
    else if (l.Type == "spot")
    {
      light["position"] = Vector3Json(l.Position);
      light["direction"] = Vector3Json(l.Direction);
      light["cone_angle_degrees"] = l.ConeAngleDegrees;
      light["edge_degrees"] = l.EdgeDegrees;
      light["intensity"] = l.Intensity;
    }
    else
    {
      light["vertices"] = Json::array();
      for (const auto& vertex : l.Vertices)
      {
        light["vertices"].push_back(Vector3Json(vertex));
      }
      light["intensity_per_metre"] = l.IntensityPerMetre;
    }
    light["temperature_kelvin"] = l.TemperatureKelvin;
    if (l.Type == "spot" && !l.LightMap.Path.empty())
    {
      light["light_map"] = l.LightMap.Path;
    }
    j["lights"].push_back(light);
  }
  if (!s.Media.empty())
  {
    j["media"] = Json::array();
  }
  for (const AdditionalMediumDescription& extra : s.Media)
  {
    Json medium;
    medium["density"] = DensityJson(extra.Density);
    medium["extinction_per_density"] = extra.ExtinctionPerDensity;
    medium["single_scattering_albedo"] = extra.SingleScatteringAlbedo;
    medium["phase"] = PhaseJson(extra.Phase);
    if (extra.Emission.Enabled)
    {
      medium["emission"] = EmissionJson(extra.Emission);
    }
    j["media"].push_back(medium);
  }
  // Version 4's occluders, only when there are some.
  if (!s.Occluders.empty())
  {
    j["occluders"] = Json::array();
  }
  for (const OccluderDescription& o : s.Occluders)
  {
    Json occluder;
    occluder["type"] = o.Type;
    if (o.Type == "mesh")
    {
      occluder["path"] = o.Path;
      occluder["albedo"] = o.Albedo;
      occluder["translate"] = Vector3Json(o.Translate);
      occluder["scale"] = o.Scale;
    }
    else
    {
      occluder["min"] = Vector3Json(o.Min);
      occluder["max"] = Vector3Json(o.Max);
      occluder["albedo"] = o.Albedo;
    }
    j["occluders"].push_back(occluder);
  }
  return j;
}

/// 2-space indent; arrays of scalars on one line ("position": [0.0, -6000.0, 1500.0]).
void WritePretty(const Json& v, int indent, std::string& out)
{
  const std::string inner(static_cast<std::size_t>(indent + 2), ' ');
  if (v.is_object() && !v.empty())
  {
    out += "{\n";
    std::size_t i = 0;
    for (const auto& item : v.items())
    {
      out += inner + Json(item.key()).dump() + ": ";
      WritePretty(item.value(), indent + 2, out);
      out += ++i < v.size() ? ",\n" : "\n";
    }
    out += std::string(static_cast<std::size_t>(indent), ' ') + "}";
  }
  else if (v.is_array() &&
    std::any_of(v.begin(), v.end(), [](const Json& x) { return x.is_structured(); }))
  {
    out += "[\n";
    for (std::size_t i = 0; i < v.size(); ++i)
    {
      out += inner;
      WritePretty(v[i], indent + 2, out);
      out += i + 1 < v.size() ? ",\n" : "\n";
    }
    out += std::string(static_cast<std::size_t>(indent), ' ') + "]";
  }
  else if (v.is_array())
  {
    out += "[";
    for (std::size_t i = 0; i < v.size(); ++i)
    {
      out += (i ? ", " : "") + v[i].dump();
    }
    out += "]";
  }
  else
  {
    out += v.dump(); // scalars, {} and []
  }
}

} // namespace

//------------------------------------------------------------------------------
namespace
{
SceneDescription ReadScene(
  const Json& root, const std::string& path, const std::string& baseDirectory, int version)
{
  std::vector<std::string> known = { "nimbus_scene", "name", "description", "camera", "medium",
    "sun", "atmosphere", "ground", "background", "spectral_samples" };
  RefuseVersion3Key(root, path, "lights", version, known);
  RefuseVersion3Key(root, path, "media", version, known);
  if (version >= 3)
  {
    known.push_back("lights");
    known.push_back("media");
  }
  RefuseNewerKey(root, path, "occluders", version, 4, known);
  if (version >= 4)
  {
    known.push_back("occluders");
  }
  const ObjectReader r(root, path, known);
  SceneDescription s;
  if (r.Has("name"))
  {
    s.Name = ReadString(r["name"], r.Key("name"));
  }
  if (r.Has("description"))
  {
    s.Description = ReadString(r["description"], r.Key("description"));
  }
  s.Camera = ReadCamera(r.Require("camera"), r.Key("camera"));
  s.Medium = ReadMedium(r.Require("medium"), r.Key("medium"), baseDirectory, version);
  s.Sun = ReadSun(r.Require("sun"), r.Key("sun"));
  if (r.Has("atmosphere"))
  {
    s.Atmosphere = ReadAtmosphere(r["atmosphere"], r.Key("atmosphere"));
  }
  if (r.Has("ground"))
  {
    s.Ground = ReadGround(r["ground"], r.Key("ground"));
  }
  if (r.Has("background"))
  {
    s.Background = ReadBackground(r["background"], r.Key("background"));
  }
  r.Integer("spectral_samples", s.SpectralSamples, 3, 256);
  if (r.Has("lights"))
  {
    RequireArray(r["lights"], r.Key("lights"), kMaxLights, "lights");
    for (std::size_t i = 0; i < r["lights"].size(); ++i)
    {
      s.Lights.push_back(ReadLight(
        r["lights"][i], r.Key("lights") + "[" + std::to_string(i) + "]", baseDirectory, version));
    }
  }
  if (r.Has("media"))
  {
    RequireArray(r["media"], r.Key("media"), kMaxAdditionalMedia, "media");
    for (std::size_t i = 0; i < r["media"].size(); ++i)
    {
      const std::string mediumPath = r.Key("media") + "[" + std::to_string(i) + "]";
      s.Media.push_back(ReadAdditionalMedium(r["media"][i], mediumPath, baseDirectory));
      RequireSameMetaballGrid(s.Medium.Density, s.Media.back().Density, mediumPath);
    }
  }
  if (r.Has("occluders"))
  {
    RequireArray(r["occluders"], r.Key("occluders"), kMaxOccluders, "occluders");
    for (std::size_t i = 0; i < r["occluders"].size(); ++i)
    {
      s.Occluders.push_back(ReadOccluder(
        r["occluders"][i], r.Key("occluders") + "[" + std::to_string(i) + "]", baseDirectory));
    }
  }

  if (s.Background.Type == "atmosphere" && !s.Atmosphere.Enabled)
  {
    Fail(r.Key("background.type"),
      "\"atmosphere\" needs atmosphere.enabled = true (use "
      "\"black\" or \"constant\" without an atmosphere)");
  }
  return s;
}

} // namespace

SceneDescription ParseScene(const std::string& jsonText, const std::string& baseDirectory)
{
  Json root;
  ParseTracker tracker;
  try
  {
    root = Json::parse(jsonText, std::ref(tracker));
  }
  catch (const nlohmann::json::exception& error)
  {
    Fail(tracker.CurrentPath(), "invalid JSON: " + WithoutJsonPrefix(error.what()));
  }

  const std::string path = "scene";
  if (!root.is_object())
  {
    Fail(path, "expected an object, got " + Describe(root));
  }
  // The version first: a newer file may have keys this reader does not know.
  const std::string versions = "versions " + std::to_string(kFirstSceneFormatVersion) + " to " +
    std::to_string(SceneDescription::kFormatVersion);
  if (!root.contains("nimbus_scene"))
  {
    Fail(path,
      "missing required key \"nimbus_scene\" (the format version; this build reads " + versions +
        ")");
  }
  const Json& version = root.at("nimbus_scene");
  if (!(version.is_number_integer() || version.is_number_unsigned()))
  {
    Fail(path + ".nimbus_scene",
      "expected the format version, an integer (this build reads " + versions + "), got " +
        Describe(version));
  }
  const std::string number = version.dump();
  if (number != "1" && number != "2" && number != "3" &&
    number != std::to_string(SceneDescription::kFormatVersion))
  {
    Fail(path + ".nimbus_scene",
      "unsupported format version " + number + "; this build of Nimbus reads " + versions);
  }
  if (number == "1")
  {
    MigrateSceneVersion1(root);
    try
    {
      return ReadScene(root, path, baseDirectory, 1);
    }
    catch (const std::invalid_argument& error)
    {
      throw std::invalid_argument(InSceneVersion1Words(error.what()));
    }
  }
  return ReadScene(root, path, baseDirectory, std::stoi(number));
}

SceneDescription LoadScene(const std::string& path)
{
  std::error_code ignored;
  std::ifstream file(path, std::ios::binary);
  if (!file || std::filesystem::is_directory(path, ignored))
  {
    throw std::runtime_error(path + ": cannot read the scene file");
  }
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad())
  {
    throw std::runtime_error(path + ": error while reading the scene file");
  }
  const std::filesystem::path directory =
    std::filesystem::absolute(std::filesystem::path(path)).parent_path();
  try
  {
    return ParseScene(text.str(), directory.string());
  }
  catch (const std::invalid_argument& error)
  {
    throw std::invalid_argument(path + ": " + error.what());
  }
}

std::string SceneToJson(const SceneDescription& scene)
{
  std::string text;
  WritePretty(ToJson(scene), 0, text);
  return text + "\n";
}

std::string SceneHash(const SceneDescription& scene)
{
  std::uint64_t hash = 14695981039346656037ull; // FNV-1a 64 offset basis
  for (const unsigned char byte : SceneToJson(scene))
  {
    hash ^= byte;
    hash *= 1099511628211ull; // FNV prime
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

} // namespace nimbus
