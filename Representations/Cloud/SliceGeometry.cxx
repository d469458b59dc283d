#include "SliceGeometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nimbus
{

SliceAxis ComputeSliceAxis(const Vector3& view, const Vector3& toSun, double a)
{
  const Vector3 v = Normalized(view);
  const Vector3 l = Normalized(toSun);
  if (!std::isfinite(a))
  {
    throw std::invalid_argument("slice angle ratio a must be finite");
  }
  a = std::clamp(a, 0.01, 100.0);
  const Vector3 away = { { -l[0], -l[1], -l[2] } }; // direction sunlight travels
  SliceAxis axis;
  // Sun behind the camera (dot(V, L) < 0): moving away from the sun moves away
  // from the eye -> front to back along +V. Otherwise back to front along -V.
  axis.BackToFront = Dot(v, l) >= 0.0;
  const Vector3 e = axis.BackToFront ? Vector3{ { -v[0], -v[1], -v[2] } } : v;
  // Angle between e and -L is in [0, pi/2] by the choice of sign.
  const double c = std::clamp(Dot(e, away), -1.0, 1.0);
  const double total = std::acos(c);
  axis.ThetaView = total / (1.0 + a); // theta_e : theta_s = 1 : a
  axis.ThetaSun = total - axis.ThetaView;
  if (total < 1e-9)
  {
    axis.Normal = away; // view (anti-)parallel to the sun: both slices coincide
  }
  else
  {
    // slerp(e -> away, t) with t = ThetaView / total.
    const double s = std::sin(total);
    const double we = std::sin(total - axis.ThetaView) / s;
    const double wa = std::sin(axis.ThetaView) / s;
    axis.Normal = Normalized(
      { { we * e[0] + wa * away[0], we * e[1] + wa * away[1], we * e[2] + wa * away[2] } });
  }
  axis.SunCosine = Dot(axis.Normal, away);
  return axis;
}

std::array<double, 2> ProjectedRange(const std::vector<Vector3>& corners, const Vector3& n)
{
  std::array<double, 2> range{ { std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() } };
  for (const Vector3& corner : corners)
  {
    const double d = Dot(corner, n);
    range[0] = std::min(range[0], d);
    range[1] = std::max(range[1], d);
  }
  return range;
}

SlicePlanes MakeSlicePlanes(double dMin, double dMax, int count)
{
  if (count < 1 || !std::isfinite(dMin) || !std::isfinite(dMax) || dMax < dMin)
  {
    throw std::invalid_argument("slice planes need count >= 1 and a finite range");
  }
  SlicePlanes planes;
  planes.Spacing = (dMax - dMin) / count;
  planes.Offsets.resize(count);
  for (int i = 0; i < count; ++i)
  {
    planes.Offsets[i] = dMin + (i + 0.5) * planes.Spacing;
  }
  return planes;
}

std::vector<Vector3> SlicePolygon(const std::vector<Vector3>& corners, const Vector3& n, double d)
{
  std::vector<Vector3> points;
  if (corners.size() != 8)
  {
    throw std::invalid_argument("SlicePolygon needs the 8 corners of a box");
  }
  for (int c = 0; c < 8; ++c)
  {
    for (int bit : { 1, 2, 4 })
    {
      if (c & bit)
      {
        continue;
      }
      const Vector3& a = corners[c];
      const Vector3& b = corners[c | bit];
      const double da = Dot(a, n) - d, db = Dot(b, n) - d;
      if ((da < 0.0 && db < 0.0) || (da > 0.0 && db > 0.0))
      {
        continue;
      }
      const double t = da == db ? 0.0 : da / (da - db);
      points.push_back(
        { { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) } });
    }
  }
  return points;
}

std::vector<Vector3> SlabPoints(
  const std::vector<Vector3>& corners, const Vector3& n, double d, double halfWidth)
{
  std::vector<Vector3> points = SlicePolygon(corners, n, d - halfWidth);
  const std::vector<Vector3> far = SlicePolygon(corners, n, d + halfWidth);
  points.insert(points.end(), far.begin(), far.end());
  for (const Vector3& corner : corners)
  {
    if (std::abs(Dot(corner, n) - d) <= halfWidth)
    {
      points.push_back(corner);
    }
  }
  return points;
}

ShadowFrame ComputeShadowFrame(
  const std::vector<Vector3>& corners, const Vector3& toSun, double margin)
{
  const Vector3 l = Normalized(toSun);
  // Any axis not parallel to L seeds the basis.
  const Vector3 seed =
    std::abs(l[2]) < 0.9 ? Vector3{ { 0.0, 0.0, 1.0 } } : Vector3{ { 1.0, 0.0, 0.0 } };
  ShadowFrame frame;
  frame.U = Normalized(Cross(seed, l));
  frame.W = Cross(l, frame.U);
  double uMin = std::numeric_limits<double>::infinity(), uMax = -uMin, wMin = uMin, wMax = -uMin;
  for (const Vector3& corner : corners)
  {
    const double u = Dot(corner, frame.U), w = Dot(corner, frame.W);
    uMin = std::min(uMin, u);
    uMax = std::max(uMax, u);
    wMin = std::min(wMin, w);
    wMax = std::max(wMax, w);
  }
  const double extent = std::max({ uMax - uMin, wMax - wMin, 1e-12 });
  const double pad = margin * extent;
  uMin -= pad;
  uMax += pad;
  wMin -= pad;
  wMax += pad;
  frame.Width = std::max(uMax - uMin, 1e-12);
  frame.Height = std::max(wMax - wMin, 1e-12);
  for (int k = 0; k < 3; ++k)
  {
    frame.Origin[k] = uMin * frame.U[k] + wMin * frame.W[k];
  }
  return frame;
}

bool ScreenRectangle(const std::vector<Vector3>& polygon, const double worldToNdc[16], int width,
  int height, int rect[4])
{
  double lo[2] = { 1e30, 1e30 }, hi[2] = { -1e30, -1e30 };
  for (const auto& point : polygon)
  {
    const double p[4] = { point[0], point[1], point[2], 1.0 };
    double q[4];
    for (int r = 0; r < 4; ++r)
    {
      const double* row = worldToNdc + 4 * r;
      q[r] = row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + row[3] * p[3];
    }
    if (q[3] <= 1e-9)
    {
      return false;
    }
    for (int k = 0; k < 2; ++k)
    {
      lo[k] = std::min(lo[k], q[k] / q[3]);
      hi[k] = std::max(hi[k], q[k] / q[3]);
    }
  }
  const int x0 = std::clamp(static_cast<int>(std::floor((lo[0] + 1) * 0.5 * width)) - 1, 0, width);
  const int y0 =
    std::clamp(static_cast<int>(std::floor((lo[1] + 1) * 0.5 * height)) - 1, 0, height);
  const int x1 = std::clamp(static_cast<int>(std::ceil((hi[0] + 1) * 0.5 * width)) + 1, 0, width);
  const int y1 = std::clamp(static_cast<int>(std::ceil((hi[1] + 1) * 0.5 * height)) + 1, 0, height);
  rect[0] = x0;
  rect[1] = y0;
  rect[2] = std::max(x1 - x0, 0);
  rect[3] = std::max(y1 - y0, 0);
  return true;
}

// Texels (x, y, width, height) of the size x size shadow surface covering the
// polygon's projection along the sun, with a texel of margin.
void ShadowRectangle(
  const std::vector<Vector3>& polygon, const ShadowFrame& frame, int size, int rect[4])
{
  double lo[2] = { 1e30, 1e30 }, hi[2] = { -1e30, -1e30 };
  for (const auto& point : polygon)
  {
    const Vector3 q = { { point[0] - frame.Origin[0], point[1] - frame.Origin[1],
      point[2] - frame.Origin[2] } };
    const double st[2] = { Dot(q, frame.U) / frame.Width * size,
      Dot(q, frame.W) / frame.Height * size };
    for (int k = 0; k < 2; ++k)
    {
      lo[k] = std::min(lo[k], st[k]);
      hi[k] = std::max(hi[k], st[k]);
    }
  }
  const int x0 = std::clamp(static_cast<int>(std::floor(lo[0])) - 1, 0, size);
  const int y0 = std::clamp(static_cast<int>(std::floor(lo[1])) - 1, 0, size);
  const int x1 = std::clamp(static_cast<int>(std::ceil(hi[0])) + 1, 0, size);
  const int y1 = std::clamp(static_cast<int>(std::ceil(hi[1])) + 1, 0, size);
  rect[0] = x0;
  rect[1] = y0;
  rect[2] = std::max(x1 - x0, 0);
  rect[3] = std::max(y1 - y0, 0);
}

// The GL state the passes change, restored (in reverse order) when the frame ends.

} // namespace nimbus
