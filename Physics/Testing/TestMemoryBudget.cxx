// Memory budgets and value censuses (MemoryBudget.h).
#include "MemoryBudget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sys/resource.h>

namespace
{

TEST(MemoryBudget, CheckedProductDetectsOverflow)
{
  uint64_t product = 7;
  EXPECT_TRUE(nimbus::CheckedProduct({ 3000, 3000, 3000, 4 }, product));
  EXPECT_EQ(product, 108000000000ULL);
  product = 7;
  EXPECT_FALSE(nimbus::CheckedProduct({ 1ULL << 32, 1ULL << 32 }, product));
  EXPECT_EQ(product, 7u);
  EXPECT_FALSE(nimbus::CheckedProduct({ 2147483647, 2147483647, 2147483647 }, product));
  EXPECT_TRUE(nimbus::CheckedProduct({ 0, std::numeric_limits<uint64_t>::max(), 5 }, product));
  EXPECT_EQ(product, 0u);
  EXPECT_TRUE(nimbus::CheckedProduct({}, product));
  EXPECT_EQ(product, 1u);
}

TEST(MemoryBudget, MessagesNameSizeAndBudget)
{
  EXPECT_EQ(nimbus::OverBudgetMessage("x", 1024.0, 1024.0), "");
  const std::string message =
    nimbus::OverBudgetMessage("the grid", 3.0 * 1073741824.0, 1073741824.0);
  EXPECT_EQ(message, "the grid would need 3.0 GiB, more than the memory budget of 1.0 GiB");
  EXPECT_FALSE(nimbus::OverBudgetMessage("x", std::nan(""), 1e30).empty());
  EXPECT_FALSE(nimbus::OverBudgetMessage("x", HUGE_VAL, 1e30).empty());
  EXPECT_FALSE(nimbus::OverBudgetMessage("x", -1.0, 1e30).empty());
  EXPECT_EQ(nimbus::FormatBytes(512), "512 B");
  EXPECT_EQ(nimbus::FormatBytes(1536), "1.5 KiB");
}

TEST(MemoryBudget, DefaultRespectsAddressSpaceLimit)
{
  const uint64_t physical = nimbus::PhysicalMemoryBytes();
  EXPECT_GT(physical, 0u);
  EXPECT_LE(nimbus::DefaultMemoryBudgetBytes(), physical / 2);
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &saved), 0);
  rlimit limited = saved;
  limited.rlim_cur = 1ULL << 40; // 1 TiB: larger than this process uses, so safe to set
  if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < limited.rlim_cur)
  {
    GTEST_SKIP() << "hard address-space limit below 1 TiB";
  }
  ASSERT_EQ(setrlimit(RLIMIT_AS, &limited), 0);
  const uint64_t limit = nimbus::AddressSpaceLimitBytes();
  const uint64_t budget = nimbus::DefaultMemoryBudgetBytes();
  ASSERT_EQ(setrlimit(RLIMIT_AS, &saved), 0);
  EXPECT_EQ(limit, 1ULL << 40);
  EXPECT_LE(budget, (1ULL << 40) / 4 * 3);
}

TEST(MemoryBudget, CensusCountsEachKind)
{
  const float values[] = { 0.0f, -0.0f, 1.0f, -2.0f, std::nanf(""), INFINITY, -INFINITY, -1e-30f };
  const nimbus::ValueCensus census = nimbus::TakeCensus(values, 8);
  EXPECT_EQ(census.NaN, 1u);
  EXPECT_EQ(census.Infinite, 2u);
  EXPECT_EQ(census.Negative, 2u);
  EXPECT_FALSE(census.AllFiniteNonNegative());
  EXPECT_EQ(nimbus::DescribeCensus(census), "1 NaN, 2 infinite and 2 negative values");
  EXPECT_TRUE(nimbus::TakeCensus(values, 3).AllFiniteNonNegative());
  EXPECT_EQ(nimbus::DescribeCensus(nimbus::TakeCensus(values, 3)), "");
  const double one[] = { std::nan("") };
  EXPECT_EQ(nimbus::DescribeCensus(nimbus::TakeCensus(one, 1)), "1 NaN value");
}

} // namespace
