#include "DensityResample.h"

namespace nimbus
{
bool DensityResamplePlan::Downsamples() const
{
  return this->Factors[0] > 1 || this->Factors[1] > 1 || this->Factors[2] > 1;
}

std::size_t DensityResamplePlan::InputSize() const
{
  return static_cast<std::size_t>(this->InputDimensions[0]) * this->InputDimensions[1] *
    this->InputDimensions[2];
}

std::size_t DensityResamplePlan::OutputSize() const
{
  return static_cast<std::size_t>(this->OutputDimensions[0]) * this->OutputDimensions[1] *
    this->OutputDimensions[2];
}

DensityResamplePlan PlanDensityResample(const std::array<int, 3>& dimensions, int maximumSize)
{
  const int limit = std::max(maximumSize, 1);
  DensityResamplePlan plan;
  for (int k = 0; k < 3; ++k)
  {
    const int n = std::max(dimensions[k], 0);
    plan.InputDimensions[k] = n;
    plan.Factors[k] = std::max((n + limit - 1) / limit, 1);
    plan.OutputDimensions[k] = (n + plan.Factors[k] - 1) / plan.Factors[k];
  }
  return plan;
}

bool IsTextureReadyDensity(const float* values, std::size_t count)
{
  for (std::size_t i = 0; i < count; ++i)
  {
    if (!std::isfinite(values[i]) || std::signbit(values[i]) || values[i] > kMaximumDensity)
    {
      return false;
    }
  }
  return true;
}
} // namespace nimbus
