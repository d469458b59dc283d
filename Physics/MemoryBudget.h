// Memory budgets and value checks for sizes and data that come from users.
//
// Every allocation whose size a user controls (grid dimensions, image sizes, file
// headers) is estimated first and compared with a budget, so that a bad input ends
// in a clear message instead of std::bad_alloc, an abort inside VTK, or swapping.
// The default budget is half of the physical memory, and never more than three
// quarters of the process's address-space limit (`ulimit -v`), so that tests run
// under a limit see the message, not the crash.
//
// Plain C++, no VTK; the VTK classes expose the budget as a property.
#ifndef NimbusMemoryBudget_h
#define NimbusMemoryBudget_h

#include "NimbusPhysicsExport.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>

namespace nimbus
{

/// Physical memory of this machine in bytes; 0 when unknown.
NIMBUSPHYSICS_EXPORT uint64_t PhysicalMemoryBytes();

/// The address-space limit of this process (RLIMIT_AS) in bytes; UINT64_MAX when none.
NIMBUSPHYSICS_EXPORT uint64_t AddressSpaceLimitBytes();

/// The default memory budget in bytes: half of the physical memory (4 GiB when that is
/// unknown), at most three quarters of the address-space limit.
NIMBUSPHYSICS_EXPORT uint64_t DefaultMemoryBudgetBytes();

/// The default budget in MiB, for VTK properties (`MemoryBudgetMiB`).
NIMBUSPHYSICS_EXPORT double DefaultMemoryBudgetMiB();

/// The product of the factors; false (and `product` untouched) on overflow of 64 bits.
NIMBUSPHYSICS_EXPORT bool CheckedProduct(
  std::initializer_list<uint64_t> factors, uint64_t& product);

/// Bytes in words: "512 B", "3.2 MiB", "17.5 GiB".
NIMBUSPHYSICS_EXPORT std::string FormatBytes(double bytes);

/// Empty when `bytes` fits in `budgetBytes`; otherwise the message to show, e.g.
/// "the output (3000x3000x3000 floats) would need 100.6 GiB, more than the memory
/// budget of 11.7 GiB". `what` names the thing being allocated. A non-finite or
/// negative size is always over budget.
NIMBUSPHYSICS_EXPORT std::string OverBudgetMessage(
  const std::string& what, double bytes, double budgetBytes);

/// How many values of an array are NaN, infinite or negative.
struct ValueCensus
{
  std::size_t NaN = 0;
  std::size_t Infinite = 0;
  std::size_t Negative = 0; // finite and < 0 (-0 is not negative)
  bool AllFiniteNonNegative() const { return NaN == 0 && Infinite == 0 && Negative == 0; }
};

template <typename T>
ValueCensus TakeCensus(const T* values, std::size_t count)
{
  ValueCensus census;
  for (std::size_t i = 0; i < count; ++i)
  {
    const double v = static_cast<double>(values[i]);
    if (std::isnan(v))
    {
      ++census.NaN;
    }
    else if (std::isinf(v))
    {
      ++census.Infinite;
    }
    else if (v < 0.0)
    {
      ++census.Negative;
    }
  }
  return census;
}

/// "3 NaN, 1 infinite and 12 negative values" (only the non-zero parts); empty when
/// the census is clean.
NIMBUSPHYSICS_EXPORT std::string DescribeCensus(const ValueCensus& census);

} // namespace nimbus

#endif
