#include "HaarWavelet.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{
namespace
{
constexpr double kInverseSqrt2 = 0.70710678118654752440;

bool PowerOfTwo(int n)
{
  return n >= 1 && (n & (n - 1)) == 0;
}

void CheckPadded(const std::vector<double>& data, const std::array<int, 3>& padded)
{
  for (int n : padded)
  {
    if (!PowerOfTwo(n))
    {
      throw std::invalid_argument("nimbus::Haar: padded dimensions must be powers of two");
    }
  }
  if (data.size() != static_cast<std::size_t>(padded[0]) * padded[1] * padded[2])
  {
    throw std::invalid_argument("nimbus::Haar: data size does not match the dimensions");
  }
}

/// The full 1-D transform (or its inverse) of the n values at base + i stride.
void Transform1D(double* base, std::size_t stride, int n, bool inverse, std::vector<double>& tmp)
{
  tmp.resize(n);
  if (!inverse)
  {
    for (int length = n; length >= 2; length /= 2)
    {
      const int half = length / 2;
      for (int i = 0; i < half; ++i)
      {
        const double a = base[(2 * i) * stride], b = base[(2 * i + 1) * stride];
        tmp[i] = (a + b) * kInverseSqrt2;
        tmp[half + i] = (a - b) * kInverseSqrt2;
      }
      for (int i = 0; i < length; ++i)
      {
        base[i * stride] = tmp[i];
      }
    }
  }
  else
  {
    for (int length = 2; length <= n; length *= 2)
    {
      const int half = length / 2;
      for (int i = 0; i < half; ++i)
      {
        const double s = base[i * stride], d = base[(half + i) * stride];
        tmp[2 * i] = (s + d) * kInverseSqrt2;
        tmp[2 * i + 1] = (s - d) * kInverseSqrt2;
      }
      for (int i = 0; i < length; ++i)
      {
        base[i * stride] = tmp[i];
      }
    }
  }
}

void Transform3D(std::vector<double>& data, const std::array<int, 3>& p, bool inverse)
{
  CheckPadded(data, p);
  const std::size_t nx = p[0], ny = p[1], nz = p[2];
  std::vector<double> tmp;
  // Axis order x, y, z forward; z, y, x inverse (each axis's transform commutes with the
  // others', so the order only matters for rounding).
  for (int step = 0; step < 3; ++step)
  {
    const int axis = inverse ? 2 - step : step;
    if (axis == 0)
    {
      for (std::size_t k = 0; k < nz; ++k)
        for (std::size_t j = 0; j < ny; ++j)
          Transform1D(&data[nx * (j + ny * k)], 1, p[0], inverse, tmp);
    }
    else if (axis == 1)
    {
      for (std::size_t k = 0; k < nz; ++k)
        for (std::size_t i = 0; i < nx; ++i)
          Transform1D(&data[i + nx * ny * k], nx, p[1], inverse, tmp);
    }
    else
    {
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t i = 0; i < nx; ++i)
          Transform1D(&data[i + nx * j], nx * ny, p[2], inverse, tmp);
    }
  }
}
} // namespace

std::array<int, 3> HaarPaddedDimensions(const std::array<int, 3>& dimensions)
{
  std::array<int, 3> padded{};
  double total = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    if (dimensions[a] < 1)
    {
      throw std::invalid_argument("nimbus::HaarPaddedDimensions: dimensions must be >= 1");
    }
    int n = 1;
    while (n < dimensions[a])
    {
      n *= 2;
    }
    padded[a] = n;
    total *= n;
  }
  if (total > 2147483648.0)
  {
    throw std::invalid_argument("nimbus::HaarPaddedDimensions: more than 2^31 values");
  }
  return padded;
}

void HaarForward(std::vector<double>& data, const std::array<int, 3>& padded)
{
  Transform3D(data, padded, false);
}

void HaarInverse(std::vector<double>& data, const std::array<int, 3>& padded)
{
  Transform3D(data, padded, true);
}

double SparseHaarField::AmbientPerPoint() const
{
  const std::size_t n = this->PaddedSize();
  return n ? this->DroppedNorm / std::sqrt(static_cast<double>(n)) : 0.0;
}

SparseHaarField CompressHaar(
  const std::vector<float>& values, const std::array<int, 3>& dimensions, double threshold)
{
  if (!(threshold >= 0.0) || !std::isfinite(threshold))
  {
    throw std::invalid_argument("nimbus::CompressHaar: the threshold must be finite and >= 0");
  }
  SparseHaarField field;
  field.Dimensions = dimensions;
  field.Padded = HaarPaddedDimensions(dimensions);
  const std::size_t nx = dimensions[0], ny = dimensions[1], nz = dimensions[2];
  if (values.size() != nx * ny * nz)
  {
    throw std::invalid_argument("nimbus::CompressHaar: values do not match the dimensions");
  }
  const std::size_t px = field.Padded[0], py = field.Padded[1], pz = field.Padded[2];
  std::vector<double> data(px * py * pz);
  for (std::size_t k = 0; k < pz; ++k)
  {
    for (std::size_t j = 0; j < py; ++j)
    {
      for (std::size_t i = 0; i < px; ++i)
      {
        // Constant continuation past the last value on each axis.
        const std::size_t si = std::min(i, nx - 1), sj = std::min(j, ny - 1),
                          sk = std::min(k, nz - 1);
        const float v = values[si + nx * (sj + ny * sk)];
        if (!std::isfinite(v))
        {
          throw std::invalid_argument("nimbus::CompressHaar: a value is not finite");
        }
        data[i + px * (j + py * k)] = v;
      }
    }
  }
  HaarForward(data, field.Padded);
  double dropped = 0.0;
  for (std::size_t i = 0; i < data.size(); ++i)
  {
    if (std::abs(data[i]) > threshold)
    {
      field.Index.push_back(static_cast<std::uint32_t>(i));
      field.Value.push_back(static_cast<float>(data[i]));
    }
    else
    {
      dropped += data[i] * data[i];
    }
  }
  field.DroppedNorm = std::sqrt(dropped);
  return field;
}

void DropHaarCoefficients(SparseHaarField& field, double threshold)
{
  if (!(threshold >= 0.0) || !std::isfinite(threshold))
  {
    throw std::invalid_argument(
      "nimbus::DropHaarCoefficients: the threshold must be finite and >= 0");
  }
  double dropped = field.DroppedNorm * field.DroppedNorm;
  std::size_t kept = 0;
  for (std::size_t n = 0; n < field.Index.size(); ++n)
  {
    const double v = field.Value[n];
    if (std::abs(v) > threshold)
    {
      field.Index[kept] = field.Index[n];
      field.Value[kept] = field.Value[n];
      ++kept;
    }
    else
    {
      dropped += v * v;
    }
  }
  field.Index.resize(kept);
  field.Value.resize(kept);
  field.DroppedNorm = std::sqrt(dropped);
}

void AccumulateHaar(const SparseHaarField& field, double weight, std::vector<double>& coefficients)
{
  if (coefficients.empty())
  {
    coefficients.assign(field.PaddedSize(), 0.0);
  }
  if (coefficients.size() != field.PaddedSize())
  {
    throw std::invalid_argument("nimbus::AccumulateHaar: coefficient array of the wrong size");
  }
  for (std::size_t n = 0; n < field.Index.size(); ++n)
  {
    coefficients[field.Index[n]] += weight * field.Value[n]; // 003 Eq. 9
  }
}

std::vector<double> ReconstructHaar(std::vector<double> coefficients,
  const std::array<int, 3>& dimensions, const std::array<int, 3>& padded)
{
  HaarInverse(coefficients, padded); // 003 Eq. 8
  const std::size_t nx = dimensions[0], ny = dimensions[1], nz = dimensions[2];
  const std::size_t px = padded[0], py = padded[1];
  if (nx > static_cast<std::size_t>(padded[0]) || ny > py ||
    nz > static_cast<std::size_t>(padded[2]))
  {
    throw std::invalid_argument("nimbus::ReconstructHaar: dimensions exceed the padded ones");
  }
  std::vector<double> out(nx * ny * nz);
  for (std::size_t k = 0; k < nz; ++k)
  {
    for (std::size_t j = 0; j < ny; ++j)
    {
      for (std::size_t i = 0; i < nx; ++i)
      {
        out[i + nx * (j + ny * k)] = coefficients[i + px * (j + py * k)];
      }
    }
  }
  return out;
}

} // namespace nimbus
