// Precomputed lightning (003 §4-§7): the basis intensities of the cloud lit by a unit
// point light at every node of the virtual-light grid, Haar-compressed, and the relight
// of any stroke from them as weighted sums. Plain C++, no VTK.
//
// Basis (003 §6): for virtual light l, the in-scattered radiance J_l(x, w) of the cloud
// lit by a grey point light of unit intensity at node l, all orders including the
// light's first scattering (SolveMultipleScattering, DiscreteDirections with
// PointLightFirstScattering; 003 Eq. 1 with n_dir directions). J is kept as degree-1
// spherical harmonics, 4 fields per light (c_00, c_1-1, c_10, c_11 of the file comment
// of MultipleScattering.h) instead of the paper's n_dir directional samples: the paper's
// own suggestion (§9) for memory, and the form the mapper reads. Each field is
// compressed with the 3-D Haar codec (HaarWavelet.h) keeping the coefficients with
// |B| > Threshold x (the largest |B| of the whole basis): 003 Eq. 5's absolute xi, given
// relative to the basis's scale. (Relative to each field's own largest coefficient was
// measured worse: the faint fields of far lights kept coefficients that barely count
// after the weighted sum; BenchLightning prints both.)
//
// Three lights per solve: the solver carries R, G and B through the same sweeps and the
// cloud's optics are grey, so light 3t + c is put in channel c of solve t.
//
// Relight (003 Eqs. 6-10): the stroke's point sources go to the virtual lights with
// trilinear weights (DistributeToVirtualLights: e_l per colour channel), then per SH
// field and channel H = sum_l e_l B_l in the wavelet domain (Eq. 9), one inverse
// transform (Eq. 8), and the ambient term sum_l e_l gamma_l / sqrt N added to the c_00
// field only (Eq. 10 with HaarWavelet.h's L2-preserving constant; a constant has no
// direction, so the degree-1 fields get none).
//
// Cost: the precompute solves one cloud per virtual light (lights in parallel, one
// thread each); memory of the basis: 4 x (kept coefficients) x 8 bytes per light,
// against 4 x N x 4 bytes uncompressed (N cloud grid points).
#ifndef nimbus_LightningBasis_h
#define nimbus_LightningBasis_h

#include "NimbusPhysicsExport.h" // for export macro

#include "HaarWavelet.h"
#include "Lightning.h"
#include "MultipleScattering.h"

#include <functional>
#include <string>
#include <vector>

namespace nimbus
{

struct NIMBUSPHYSICS_EXPORT LightningBasisOptions
{
  int NumberOfDirections = 26; // n_dir of 003 (its default)
  /// Scattering orders before the geometric tail. 16: 1e-4 of a 64-order solve for a
  /// light below and one inside the seed's cloud (measured), at about half the time of 32.
  int Orders = 16;
  double Threshold = 1e-3;        // xi relative to the basis's largest coefficient, >= 0
  int Threads = 0;                // 0: hardware concurrency; results do not depend on it
  double MemoryBudgetBytes = 0.0; // > 0: refuse (std::length_error) a basis that needs more
  /// Include the lights' first scattering in the basis (003's b_il). Off: the basis
  /// holds orders >= 2 only, for a renderer that computes the first scattering of the
  /// actual point sources itself (smoother fields: they compress and relight better).
  bool IncludeFirstScattering = true;
};

struct NIMBUSPHYSICS_EXPORT LightningBasis
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } }; // the cloud grid's
  VirtualLightGrid Lights;
  std::vector<SparseHaarField> Fields; // light l, SH coefficient b: Fields[4 l + b]
  double Seconds = 0.0;                // precompute wall time

  std::size_t NumberOfPoints() const
  {
    return static_cast<std::size_t>(this->Dimensions[0]) * this->Dimensions[1] *
      this->Dimensions[2];
  }
  /// Bytes of the basis stored as floats without compression (4 SH fields per light).
  double UncompressedBytes() const
  {
    return 4.0 * this->NumberOfPoints() * this->Lights.NumberOfNodes() * sizeof(float);
  }
  /// Bytes held by the compressed fields (indices and values).
  double CompressedBytes() const;
};

/// Bytes the precompute needs at most (the uncompressed worst case of the kept fields
/// plus one solver's scratch per thread), to compare with a budget before starting.
NIMBUSPHYSICS_EXPORT double EstimateLightningBasisBytes(const ExtinctionGrid& cloud,
  const VirtualLightGrid& lights, const LightningBasisOptions& options);

/// The basis (see the file comment). `progress(fraction)` is called on the calling
/// thread; it may throw to stop (the exception propagates). Throws std::invalid_argument
/// for a bad cloud, optics or options (the solver's message), a grid with no nodes or a
/// negative or NaN threshold; std::length_error when MemoryBudgetBytes is set and
/// EstimateLightningBasisBytes exceeds it.
NIMBUSPHYSICS_EXPORT LightningBasis PrecomputeLightningBasis(const ExtinctionGrid& cloud,
  const CloudOptics& optics, const VirtualLightGrid& lights, const LightningBasisOptions& options,
  const std::function<void(double)>& progress = nullptr);

/// J of the cloud lit by the virtual lights' intensities e (one RGB per node, e.g.
/// DistributeToVirtualLights of a stroke's point sources): the field the solver would
/// return (12 floats per point), from the basis alone (003 Eqs. 8-10). Throws
/// std::invalid_argument when e does not have one entry per node or is not finite.
NIMBUSPHYSICS_EXPORT MultipleScatteringField RelightLightning(
  const LightningBasis& basis, const std::vector<Rgb>& e);

/// A fingerprint (32 hex digits: two 64-bit FNV-1a hashes) of everything the basis
/// depends on: the cloud's extinction values and placement, the optics, the virtual
/// lights' nodes and the options that change the result (directions, orders,
/// threshold, first scattering; not threads or budget). The disk cache's key.
NIMBUSPHYSICS_EXPORT std::string LightningBasisFingerprint(const ExtinctionGrid& cloud,
  const CloudOptics& optics, const VirtualLightGrid& lights, const LightningBasisOptions& options);

/// Writes the basis with its fingerprint to `path` (binary, little-endian as the machine
/// writes it; written to `path`.partial and renamed, so a reader never sees half a
/// file). Throws std::runtime_error naming the path when it cannot be written.
NIMBUSPHYSICS_EXPORT void WriteLightningBasis(
  const LightningBasis& basis, const std::string& fingerprint, const std::string& path);

/// Reads a basis written by WriteLightningBasis. False, with the reason in `why`, when
/// the file is missing, holds another fingerprint or format version, or is damaged
/// (sizes that do not add up, indices out of range, non-finite values); `basis` is then
/// unchanged.
NIMBUSPHYSICS_EXPORT bool ReadLightningBasis(
  const std::string& path, const std::string& fingerprint, LightningBasis& basis, std::string& why);

} // namespace nimbus

#endif
