#include "MemoryBudget.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <sys/resource.h>
#include <unistd.h>

namespace nimbus
{

uint64_t PhysicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0)
  {
    return 0;
  }
  return static_cast<uint64_t>(pages) * static_cast<uint64_t>(pageSize);
}

uint64_t AddressSpaceLimitBytes()
{
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY)
  {
    return std::numeric_limits<uint64_t>::max();
  }
  return static_cast<uint64_t>(limit.rlim_cur);
}

uint64_t DefaultMemoryBudgetBytes()
{
  const uint64_t physical = PhysicalMemoryBytes();
  uint64_t budget = physical > 0 ? physical / 2 : (uint64_t(4) << 30);
  const uint64_t addressSpace = AddressSpaceLimitBytes();
  if (addressSpace != std::numeric_limits<uint64_t>::max())
  {
    budget = std::min(budget, addressSpace / 4 * 3);
  }
  return budget;
}

double DefaultMemoryBudgetMiB()
{
  return std::floor(static_cast<double>(DefaultMemoryBudgetBytes()) / (1024.0 * 1024.0));
}

bool CheckedProduct(std::initializer_list<uint64_t> factors, uint64_t& product)
{
  uint64_t result = 1;
  for (const uint64_t factor : factors)
  {
    if (factor != 0 && result > std::numeric_limits<uint64_t>::max() / factor)
    {
      return false;
    }
    result *= factor;
  }
  product = result;
  return true;
}

std::string FormatBytes(double bytes)
{
  if (!std::isfinite(bytes))
  {
    return "an unbounded amount of memory";
  }
  static const char* const units[] = { "B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB" };
  int unit = 0;
  while (std::abs(bytes) >= 1024.0 && unit < 6)
  {
    bytes /= 1024.0;
    ++unit;
  }
  char text[64];
  std::snprintf(text, sizeof(text), unit == 0 ? "%.0f %s" : "%.1f %s", bytes, units[unit]);
  return text;
}

std::string OverBudgetMessage(const std::string& what, double bytes, double budgetBytes)
{
  if (std::isfinite(bytes) && bytes >= 0.0 && bytes <= budgetBytes)
  {
    return std::string();
  }
  return what + " would need " + FormatBytes(bytes) + ", more than the memory budget of " +
    FormatBytes(budgetBytes);
}

std::string DescribeCensus(const ValueCensus& census)
{
  std::string parts[3];
  int n = 0;
  if (census.NaN)
  {
    parts[n++] = std::to_string(census.NaN) + " NaN";
  }
  if (census.Infinite)
  {
    parts[n++] = std::to_string(census.Infinite) + " infinite";
  }
  if (census.Negative)
  {
    parts[n++] = std::to_string(census.Negative) + " negative";
  }
  if (n == 0)
  {
    return std::string();
  }
  std::string text = parts[0];
  for (int i = 1; i < n; ++i)
  {
    text += (i == n - 1) ? " and " : ", ";
    text += parts[i];
  }
  const std::size_t total = census.NaN + census.Infinite + census.Negative;
  return text + (total == 1 ? " value" : " values");
}

} // namespace nimbus
