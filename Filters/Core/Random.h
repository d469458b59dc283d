// Deterministic random numbers for Nimbus generators.
//
// std::mt19937_64's sequence is fixed by the C++ standard, but the standard
// distributions are not (libstdc++ and libc++ differ), so the conversion to
// [0, 1) is done here: the top 53 bits scaled by 2^-53. Same seed -> same
// numbers on every platform and compiler.
#ifndef NimbusRandom_h
#define NimbusRandom_h

#include <cstdint>
#include <random>

namespace nimbus
{

class Random
{
public:
  explicit Random(std::uint64_t seed)
    : Engine(seed)
  {
  }

  /// Uniform in [0, 1).
  double Uniform() { return static_cast<double>(this->Engine() >> 11) * 0x1.0p-53; }

  /// Uniform in [low, high).
  double Uniform(double low, double high) { return low + (high - low) * this->Uniform(); }

private:
  std::mt19937_64 Engine;
};

} // namespace nimbus

#endif
