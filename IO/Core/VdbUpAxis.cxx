// VdbUpAxis: the up axis of a .vdb file and the turn into the up frame (see VdbUpAxis.h).
#include "VdbUpAxis.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace nimbus
{
namespace vdb
{
namespace
{

std::string Lower(const std::string& s)
{
  std::string out = s;
  std::transform(out.begin(), out.end(), out.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

/// A metadata key without case, blanks, '_' and '-': "up_axis", "UpAxis", "up-axis" -> "upaxis".
std::string KeyForm(const std::string& key)
{
  std::string out;
  for (unsigned char c : key)
  {
    if (!std::isspace(c) && c != '_' && c != '-')
    {
      out += static_cast<char>(std::tolower(c));
    }
  }
  return out;
}

/// A text read from a file, fit for a message: at most 80 characters, control bytes as '?'.
std::string Shown(const std::string& s)
{
  std::string out;
  for (size_t i = 0; i < s.size() && i < 80; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    out += (c < 32 || c == 127) ? '?' : static_cast<char>(c);
  }
  return s.size() > 80 ? out + "..." : out;
}

const std::string* FindKey(
  const std::map<std::string, std::string>& strings, const std::string& keyForm)
{
  for (const auto& entry : strings)
  {
    if (KeyForm(entry.first) == keyForm)
    {
      return &entry.second;
    }
  }
  return nullptr;
}

bool NamesHoudini(const std::string& creator)
{
  return Lower(creator).find("houdini") != std::string::npos;
}

} // namespace

bool ParseUpAxis(const std::string& text, UpAxis& axis)
{
  std::string s;
  for (unsigned char c : text)
  {
    if (!std::isspace(c))
    {
      s += static_cast<char>(std::tolower(c));
    }
  }
  // "y_up", "y-up", "yup" (COLLADA's Y_UP): the suffix says nothing more.
  for (const char* suffix : { "_up", "-up", "up" })
  {
    const size_t n = std::strlen(suffix);
    if (s.size() > n && s.compare(s.size() - n, n, suffix) == 0)
    {
      s.resize(s.size() - n);
      break;
    }
  }
  if (s == "x" || s == "+x")
  {
    axis = UpAxis::PositiveX;
    return true;
  }
  if (s == "y" || s == "+y")
  {
    axis = UpAxis::PositiveY;
    return true;
  }
  if (s == "z" || s == "+z")
  {
    axis = UpAxis::PositiveZ;
    return true;
  }
  if (s == "-y")
  {
    axis = UpAxis::NegativeY;
    return true;
  }
  return false;
}

UpAxisChoice ChooseUpAxis(int requested, const std::map<std::string, std::string>& fileStrings,
  const std::vector<std::string>& gridCreators)
{
  UpAxisChoice choice;
  if (IsUpAxis(requested))
  {
    choice.Axis = static_cast<UpAxis>(requested);
    choice.Source = UpAxisName(choice.Axis) + " (chosen)";
    return choice;
  }
  if (const std::string* value = FindKey(fileStrings, "upaxis"))
  {
    UpAxis axis;
    if (ParseUpAxis(*value, axis))
    {
      choice.Axis = axis;
      choice.Source = UpAxisName(axis) + " (file metadata up_axis = '" + Shown(*value) + "')";
      return choice;
    }
    choice.Warning = "the file's metadata up_axis = '" + Shown(*value) +
      "' is not one of +X, +Y, +Z, -Y (or X, Y, Z): ignored; set UpAxis to choose";
  }
  if (const std::string* creator = FindKey(fileStrings, "creator"))
  {
    if (NamesHoudini(*creator))
    {
      choice.Axis = UpAxis::PositiveY;
      choice.Source = "+Y (creator '" + Shown(*creator) + "')";
      return choice;
    }
  }
  for (const auto& creator : gridCreators)
  {
    if (NamesHoudini(creator))
    {
      choice.Axis = UpAxis::PositiveY;
      choice.Source = "+Y (grid creator '" + Shown(creator) + "')";
      return choice;
    }
  }
  choice.Axis = UpAxis::PositiveZ;
  choice.Source = "+Z (default)";
  return choice;
}

UpTurn::UpTurn(UpAxis axis, const TransformInfo& reference)
  : UpAxisValue(axis)
  , R(WorldToUpFrame(axis))
{
  this->IsIdentity = axis == UpAxis::PositiveZ;
  if (this->IsIdentity)
  {
    return;
  }
  // M = R D (D column-major: D[r][c] = Direction[3 c + r]); a signed permutation when every
  // row has one entry of magnitude 1 and the columns differ.
  const double tolerance = 1e-9;
  std::array<bool, 3> taken{ { false, false, false } };
  bool permutation = true;
  for (int a = 0; a < 3 && permutation; ++a)
  {
    int found = -1;
    for (int c = 0; c < 3; ++c)
    {
      double m = 0.0;
      for (int b = 0; b < 3; ++b)
      {
        m += this->R[a][b] * reference.Direction[3 * c + b];
      }
      if (std::abs(std::abs(m) - 1.0) <= tolerance)
      {
        if (found >= 0)
        {
          permutation = false;
        }
        found = c;
        this->Sign[a] = m > 0.0 ? 1 : -1;
      }
      else if (!(std::abs(m) <= tolerance))
      {
        permutation = false;
      }
    }
    if (found < 0 || taken[found])
    {
      permutation = false;
    }
    else
    {
      taken[found] = true;
      this->Perm[a] = found;
    }
  }
  this->Reindex = permutation;
  if (!permutation)
  {
    this->Perm = { { 0, 1, 2 } };
    this->Sign = { { 1, 1, 1 } };
  }
}

IndexBox UpTurn::TurnBox(const IndexBox& fileBox) const
{
  if (!this->Reindex || fileBox.Empty())
  {
    return fileBox;
  }
  IndexBox box;
  for (int a = 0; a < 3; ++a)
  {
    const int c = this->Perm[a];
    box.Min[a] = this->Sign[a] > 0 ? fileBox.Min[c] : -fileBox.Max[c];
    box.Max[a] = this->Sign[a] > 0 ? fileBox.Max[c] : -fileBox.Min[c];
  }
  return box;
}

IndexBox UpTurn::FileBox(const IndexBox& turnedBox) const
{
  if (!this->Reindex || turnedBox.Empty())
  {
    return turnedBox;
  }
  IndexBox box;
  for (int a = 0; a < 3; ++a)
  {
    const int c = this->Perm[a];
    box.Min[c] = this->Sign[a] > 0 ? turnedBox.Min[a] : -turnedBox.Max[a];
    box.Max[c] = this->Sign[a] > 0 ? turnedBox.Max[a] : -turnedBox.Min[a];
  }
  return box;
}

TransformInfo UpTurn::TurnTransform(const TransformInfo& t) const
{
  if (this->IsIdentity)
  {
    return t;
  }
  TransformInfo out = t;
  // R has one entry +-1 per row: each turned coordinate is one world coordinate, exactly.
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      if (this->R[a][b] != 0)
      {
        out.Origin[a] = this->R[a][b] > 0 ? t.Origin[b] : -t.Origin[b];
      }
    }
  }
  if (this->Reindex)
  {
    for (int a = 0; a < 3; ++a)
    {
      out.Spacing[a] = t.Spacing[this->Perm[a]];
    }
    out.Direction = { { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };
    if (t.Rotated)
    {
      out.Note += std::string(out.Note.empty() ? "" : "; ") + "turned " +
        UpAxisName(this->UpAxisValue) +
        " up by re-indexing the voxels: the image's direction matrix is the identity";
    }
    out.Rotated = false;
    return out;
  }
  // General direction D: direction R D, columns turned one by one.
  for (int c = 0; c < 3; ++c)
  {
    for (int a = 0; a < 3; ++a)
    {
      double m = 0.0;
      for (int b = 0; b < 3; ++b)
      {
        if (this->R[a][b] != 0)
        {
          m = this->R[a][b] > 0 ? t.Direction[3 * c + b] : -t.Direction[3 * c + b];
        }
      }
      out.Direction[3 * c + a] = m;
    }
  }
  out.Rotated = true;
  return out;
}

std::array<float, 3> UpTurn::TurnVector(const std::array<float, 3>& v) const
{
  std::array<float, 3> out{ { v[0], v[1], v[2] } };
  if (this->IsIdentity)
  {
    return out;
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      if (this->R[a][b] != 0)
      {
        out[a] = this->R[a][b] > 0 ? v[b] : -v[b];
      }
    }
  }
  return out;
}

void UpTurn::TurnValues(const IndexBox& fileBox, const float* in, int components, float* out) const
{
  if (fileBox.Empty())
  {
    return;
  }
  const uint64_t count = fileBox.VoxelCount();
  const bool rotate = components == 3 && !this->IsIdentity;
  auto put = [&](const float* from, float* to)
  {
    if (rotate)
    {
      const auto v = this->TurnVector({ { from[0], from[1], from[2] } });
      to[0] = v[0];
      to[1] = v[1];
      to[2] = v[2];
    }
    else
    {
      for (int c = 0; c < components; ++c)
      {
        to[c] = from[c];
      }
    }
  };
  if (!this->Reindex)
  {
    if (!rotate && in == out)
    {
      return;
    }
    for (uint64_t i = 0; i < count; ++i)
    {
      put(in + i * components, out + i * components);
    }
    return;
  }
  // Turned point q reads file point p with p[Perm[a]] = Sign[a] q[a]: a step along turned
  // axis a is a step of Sign[a] along file axis Perm[a].
  std::array<int64_t, 3> fileDims{};
  for (int c = 0; c < 3; ++c)
  {
    fileDims[c] = fileBox.Max[c] - fileBox.Min[c] + 1;
  }
  const std::array<int64_t, 3> fileStride{ { 1, fileDims[0], fileDims[0] * fileDims[1] } };
  const IndexBox turned = this->TurnBox(fileBox);
  std::array<int64_t, 3> step{};
  std::array<int64_t, 3> dims{};
  int64_t start = 0;
  for (int a = 0; a < 3; ++a)
  {
    const int c = this->Perm[a];
    step[a] = this->Sign[a] * fileStride[c];
    dims[a] = fileDims[c];
    start += (this->Sign[a] * turned.Min[a] - fileBox.Min[c]) * fileStride[c];
  }
  const int64_t nc = components;
  float* to = out;
  for (int64_t k = 0; k < dims[2]; ++k)
  {
    for (int64_t j = 0; j < dims[1]; ++j)
    {
      const int64_t row = start + k * step[2] + j * step[1];
      for (int64_t i = 0; i < dims[0]; ++i, to += nc)
      {
        put(in + (row + i * step[0]) * nc, to);
      }
    }
  }
}

} // namespace vdb
} // namespace nimbus
