// The Haar wavelet compression of 003 §6 (Eq. 5) and the weighted sums of §7 (Eqs. 8-9)
// for 3-D fields on the cloud's grid. Plain C++, no VTK.
//
// Transform: the orthonormal 3-D Haar transform in its standard decomposition (Stollnitz,
// DeRose & Salesin 1995, 003's [21]): the full 1-D transform along every x line, then
// every y line, then every z line, where one 1-D level maps pairs (a, b) to
// ((a + b)/sqrt 2, (a - b)/sqrt 2). Each axis is padded to a power of two by repeating
// its last value (a constant continuation costs no detail coefficients). Being
// orthonormal, it keeps sums of squares (Parseval): dropping coefficients of magnitude
// <= xi (003 §6) changes the field by exactly the root of the sum of their squares in
// the L2 norm, the paper's gamma.
//
// gamma as an ambient term (003 Eq. 10): the paper adds gamma_l, weighted by e_l, to
// every grid point; the L2 norm of a constant c over N points is c sqrt N, so the
// constant whose norm equals the dropped part's is gamma / sqrt N. AmbientPerPoint
// returns that (the paper's literal gamma at every point would add sqrt N times the
// energy that was dropped).
#ifndef nimbus_HaarWavelet_h
#define nimbus_HaarWavelet_h

#include "NimbusPhysicsExport.h" // for export macro

#include <array>
#include <cstdint>
#include <vector>

namespace nimbus
{

/// Each dimension rounded up to a power of two (>= 1). Throws std::invalid_argument for
/// dimensions < 1 or a padded size over 2^31 values.
NIMBUSPHYSICS_EXPORT std::array<int, 3> HaarPaddedDimensions(const std::array<int, 3>& dimensions);

/// In place on a padded field (x fastest): forward and inverse transforms. Throws
/// std::invalid_argument unless data.size() is the product of `padded` and every entry
/// of `padded` is a power of two.
NIMBUSPHYSICS_EXPORT void HaarForward(std::vector<double>& data, const std::array<int, 3>& padded);
NIMBUSPHYSICS_EXPORT void HaarInverse(std::vector<double>& data, const std::array<int, 3>& padded);

/// One field's kept coefficients (003 §6): indices into the padded coefficient array
/// and values, sorted by index; the root of the sum of squares of the dropped ones.
struct NIMBUSPHYSICS_EXPORT SparseHaarField
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  std::array<int, 3> Padded{ { 0, 0, 0 } };
  std::vector<std::uint32_t> Index;
  std::vector<float> Value;
  double DroppedNorm = 0.0; // 003's gamma

  std::size_t PaddedSize() const
  {
    return static_cast<std::size_t>(this->Padded[0]) * this->Padded[1] * this->Padded[2];
  }
  /// Bytes held (indices and values).
  std::size_t Bytes() const { return this->Index.size() * (sizeof(std::uint32_t) + sizeof(float)); }
  /// The constant per point whose L2 norm over the padded grid is DroppedNorm.
  double AmbientPerPoint() const;
};

/// Transforms `values` (Dimensions, x fastest) and keeps the coefficients with
/// |B| > threshold (xi >= 0; 0 keeps every non-zero one). Throws std::invalid_argument
/// for a size mismatch, non-finite values or a negative or NaN threshold.
NIMBUSPHYSICS_EXPORT SparseHaarField CompressHaar(
  const std::vector<float>& values, const std::array<int, 3>& dimensions, double threshold);

/// Drops the kept coefficients with |B| <= threshold from `field`, adding their squares
/// to DroppedNorm (the same field CompressHaar gives at that threshold, without a second
/// transform). Throws std::invalid_argument for a negative or NaN threshold.
NIMBUSPHYSICS_EXPORT void DropHaarCoefficients(SparseHaarField& field, double threshold);

/// H += weight B (003 Eq. 9) into a dense padded coefficient array (resized and zeroed
/// when empty).
NIMBUSPHYSICS_EXPORT void AccumulateHaar(
  const SparseHaarField& field, double weight, std::vector<double>& coefficients);

/// The field from dense coefficients (003 Eq. 8: the inverse transform), cropped to
/// `dimensions`.
NIMBUSPHYSICS_EXPORT std::vector<double> ReconstructHaar(std::vector<double> coefficients,
  const std::array<int, 3>& dimensions, const std::array<int, 3>& padded);

} // namespace nimbus

#endif
