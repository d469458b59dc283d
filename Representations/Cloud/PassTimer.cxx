#include "PassTimer.h"

#include "vtkOpenGLRenderTimer.h"

#include <iomanip>
#include <sstream>

namespace nimbus
{
PassTimer::PassTimer() = default;
PassTimer::~PassTimer() = default;

void PassTimer::BeginFrame(bool enabled)
{
  this->Enabled = enabled && vtkOpenGLRenderTimer::IsSupported();
  this->Running = false;
  this->Used = 0;
}

void PassTimer::Begin(const std::string& name)
{
  if (!this->Enabled)
  {
    return;
  }
  this->End();
  if (this->Used == this->Queries.size())
  {
    this->Queries.emplace_back(name, std::make_unique<vtkOpenGLRenderTimer>());
  }
  auto& query = this->Queries[this->Used++];
  query.first = name;
  query.second->Reset();
  query.second->Start();
  this->Running = true;
}

void PassTimer::End()
{
  if (this->Enabled && this->Running)
  {
    this->Queries[this->Used - 1].second->Stop();
    this->Running = false;
  }
}

void PassTimer::Collect()
{
  if (!this->Enabled)
  {
    return;
  }
  this->End();
  this->Times.clear();
  for (std::size_t q = 0; q < this->Used; ++q)
  {
    const auto& query = this->Queries[q];
    const double seconds = query.second->GetElapsedSeconds(); // waits for the result
    bool found = false;
    for (auto& time : this->Times)
    {
      if (time.first == query.first)
      {
        time.second += seconds;
        found = true;
      }
    }
    if (!found)
    {
      this->Times.emplace_back(query.first, seconds);
    }
  }
}

std::string PassTimer::Report() const
{
  std::ostringstream text;
  text << std::setprecision(4);
  for (const auto& time : this->Times)
  {
    text << time.first << " " << time.second << "; ";
  }
  return text.str();
}

void PassTimer::Release()
{
  for (auto& query : this->Queries)
  {
    query.second->ReleaseGraphicsResources();
  }
  this->Queries.clear();
  this->Used = 0;
  this->Running = false;
}
}
