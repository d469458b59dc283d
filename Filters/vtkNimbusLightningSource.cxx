#include "vtkNimbusLightningSource.h"

#include "Lightning.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusLightningSource);

namespace
{
constexpr double kMaxPointSources = 1e7;
}

vtkNimbusLightningSource::vtkNimbusLightningSource()
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
}

namespace
{
nimbus::LightningFlashTimeline Timeline(vtkNimbusLightningSource* s)
{
  nimbus::LightningFlashTimeline t;
  t.LeaderDuration = s->GetLeaderDuration();
  t.NumberOfStrokes = s->GetNumberOfStrokes();
  t.InterstrokeInterval = s->GetInterstrokeInterval();
  t.SubsequentStrokeFactor = s->GetSubsequentStrokeFactor();
  t.StrokeDecaySeconds = s->GetStrokeDecaySeconds();
  return t;
}
}

int vtkNimbusLightningSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  const nimbus::LightningFlashTimeline timeline = Timeline(this);
  const bool valid = nimbus::CheckLightningFlashTimeline(timeline).empty() &&
    std::isfinite(this->FlashStartTime) && this->FlashStartTime >= 0.0 &&
    this->FlashStartTime <= 1e6;
  for (int port = 0; port < 2; ++port)
  {
    vtkInformation* outInfo = outputVector->GetInformationObject(port);
    outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
    if (!valid)
    {
      continue; // RequestData names the problem
    }
    const double end = this->FlashStartTime + nimbus::LightningFlashDuration(timeline);
    std::vector<double> times(this->NumberOfTimeSteps + 1);
    for (int i = 0; i <= this->NumberOfTimeSteps; ++i)
    {
      times[i] = end * i / this->NumberOfTimeSteps;
    }
    // Every stroke's peak is a frame of its own (the flicker is not missed).
    for (int k = 0; k < timeline.NumberOfStrokes; ++k)
    {
      times.push_back(
        this->FlashStartTime + timeline.LeaderDuration + k * timeline.InterstrokeInterval);
    }
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    const double range[2] = { 0.0, end };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkNimbusLightningSource::RequestData(
  vtkInformation* request, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* strokes = vtkPolyData::GetData(outputVector, 0);
  vtkPolyData* sources = vtkPolyData::GetData(outputVector, 1);
  strokes->Initialize();
  sources->Initialize();

  nimbus::LightningParameters p;
  p.Start = { { this->StartPoint[0], this->StartPoint[1], this->StartPoint[2] } };
  p.Direction = { { this->Direction[0], this->Direction[1], this->Direction[2] } };
  p.Length = this->Length;
  p.SegmentLength = this->SegmentLength;
  p.MeanAngleDegrees = this->MeanAngleDegrees;
  p.Straightness = this->Straightness;
  p.BranchProbability = this->BranchProbability;
  p.BranchLengthFactor = this->BranchLengthFactor;
  p.BranchIntensityFactor = this->BranchIntensityFactor;
  p.MaxBranchDepth = this->MaxBranchDepth;
  p.Intensity = this->Intensity;
  p.StopBelowHeight = this->GroundHeight;
  p.Seed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed));
  const nimbus::LightningFlashTimeline timeline = Timeline(this);
  std::string why = nimbus::CheckLightningParameters(p);
  if (why.empty())
  {
    why = nimbus::CheckLightningFlashTimeline(timeline);
  }
  if (why.empty() &&
    !(std::isfinite(this->FlashStartTime) && this->FlashStartTime >= 0.0 &&
      this->FlashStartTime <= 1e6))
  {
    why = "FlashStartTime must be in [0, 1e6] seconds";
  }
  if (why.empty() && !(std::isfinite(this->PointSourceSpacing) && this->PointSourceSpacing > 0.0))
  {
    why = "PointSourceSpacing must be > 0 (metres)";
  }
  if (why.empty() && std::isnan(this->GroundHeight))
  {
    why = "GroundHeight is NaN";
  }
  if (!why.empty())
  {
    vtkErrorMacro("Lightning: " << why << "; no output.");
    return 1;
  }
  std::vector<nimbus::LightningSegment> segments;
  try
  {
    segments = nimbus::GenerateLightning(p);
  }
  catch (const std::invalid_argument& e)
  {
    vtkErrorMacro("Lightning: " << e.what() << "; no output.");
    return 1;
  }
  this->UpdateProgress(0.5);

  // The requested time, from the port that asked (a downstream filter may want only the
  // point sources); a request without one: the return stroke's peak.
  int port = request->Has(vtkExecutive::FROM_OUTPUT_PORT())
    ? request->Get(vtkExecutive::FROM_OUTPUT_PORT())
    : 0;
  port = port == 1 ? 1 : 0;
  vtkInformation* outInfo = outputVector->GetInformationObject(port);
  double time = this->FlashStartTime + this->LeaderDuration;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    // Both outputs hold this time (whichever port asked).
    strokes->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
    sources->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
  }
  double farthest = 0.0, sourceCount = 0.0;
  for (const nimbus::LightningSegment& s : segments)
  {
    farthest = std::max(farthest, s.PathStart);
    sourceCount += std::ceil(s.Length() / this->PointSourceSpacing);
  }
  if (sourceCount > kMaxPointSources)
  {
    vtkErrorMacro("Lightning: PointSourceSpacing " << this->PointSourceSpacing << " m makes "
                                                   << sourceCount
                                                   << " point sources (at most 1e7); no output.");
    return 1;
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkFloatArray> intensity, peak, path;
  vtkNew<vtkIntArray> depth;
  intensity->SetName("intensity");
  peak->SetName("peak_intensity");
  depth->SetName("depth");
  path->SetName("path_length");
  std::vector<nimbus::LightningSegment> lit = segments;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    const nimbus::LightningSegment& s = segments[i];
    const double brightness =
      nimbus::LightningFlashBrightness(timeline, s, farthest, time - this->FlashStartTime);
    lit[i].Intensity = s.Intensity * brightness;
    const vtkIdType a = points->InsertNextPoint(s.A.data());
    const vtkIdType b = points->InsertNextPoint(s.B.data());
    const vtkIdType ids[2] = { a, b };
    lines->InsertNextCell(2, ids);
    intensity->InsertNextValue(static_cast<float>(lit[i].Intensity));
    peak->InsertNextValue(static_cast<float>(s.Intensity));
    depth->InsertNextValue(s.Depth);
    path->InsertNextValue(static_cast<float>(s.PathStart));
    path->InsertNextValue(static_cast<float>(s.PathStart + s.Length()));
  }
  strokes->SetPoints(points);
  strokes->SetLines(lines);
  strokes->GetCellData()->AddArray(intensity);
  strokes->GetCellData()->AddArray(peak);
  strokes->GetCellData()->AddArray(depth);
  strokes->GetCellData()->SetActiveScalars("intensity");
  strokes->GetPointData()->AddArray(path);

  const std::vector<nimbus::PointLight> lights =
    nimbus::LightningPointSources(lit, this->PointSourceSpacing);
  // The same sources at their segments' peak (the segments lit now, unscaled): the
  // brightness of each source is intensity / peak_intensity, as on the strokes.
  std::vector<nimbus::LightningSegment> litAtPeak;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    if (lit[i].Intensity != 0.0)
    {
      litAtPeak.push_back(segments[i]);
    }
  }
  const std::vector<nimbus::PointLight> peaks =
    nimbus::LightningPointSources(litAtPeak, this->PointSourceSpacing);
  vtkNew<vtkPoints> sourcePoints;
  sourcePoints->SetDataTypeToDouble();
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkDoubleArray> sourceIntensity, sourcePeak;
  sourceIntensity->SetName("intensity");
  sourcePeak->SetName("peak_intensity");
  const bool aligned = peaks.size() == lights.size();
  for (std::size_t i = 0; i < lights.size(); ++i)
  {
    const vtkIdType id = sourcePoints->InsertNextPoint(lights[i].Position.data());
    vertices->InsertNextCell(1, &id);
    sourceIntensity->InsertNextValue(lights[i].Intensity[0]);
    sourcePeak->InsertNextValue(aligned ? peaks[i].Intensity[0] : lights[i].Intensity[0]);
  }
  sources->SetPoints(sourcePoints);
  sources->SetVerts(vertices);
  sources->GetPointData()->AddArray(sourceIntensity);
  sources->GetPointData()->AddArray(sourcePeak);
  sources->GetPointData()->SetActiveScalars("intensity");
  this->UpdateProgress(1.0);
  return 1;
}

void vtkNimbusLightningSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "StartPoint: " << this->StartPoint[0] << " " << this->StartPoint[1] << " "
     << this->StartPoint[2] << "\n";
  os << indent << "Direction: " << this->Direction[0] << " " << this->Direction[1] << " "
     << this->Direction[2] << "\n";
  os << indent << "Length: " << this->Length << "\n";
  os << indent << "SegmentLength: " << this->SegmentLength << "\n";
  os << indent << "BranchProbability: " << this->BranchProbability << "\n";
  os << indent << "MaxBranchDepth: " << this->MaxBranchDepth << "\n";
  os << indent << "BranchIntensityFactor: " << this->BranchIntensityFactor << "\n";
  os << indent << "BranchLengthFactor: " << this->BranchLengthFactor << "\n";
  os << indent << "MeanAngleDegrees: " << this->MeanAngleDegrees << "\n";
  os << indent << "Straightness: " << this->Straightness << "\n";
  os << indent << "Intensity: " << this->Intensity << "\n";
  os << indent << "GroundHeight: " << this->GroundHeight << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "PointSourceSpacing: " << this->PointSourceSpacing << "\n";
  os << indent << "FlashStartTime: " << this->FlashStartTime << "\n";
  os << indent << "LeaderDuration: " << this->LeaderDuration << "\n";
  os << indent << "NumberOfStrokes: " << this->NumberOfStrokes << "\n";
  os << indent << "InterstrokeInterval: " << this->InterstrokeInterval << "\n";
  os << indent << "SubsequentStrokeFactor: " << this->SubsequentStrokeFactor << "\n";
  os << indent << "StrokeDecaySeconds: " << this->StrokeDecaySeconds << "\n";
  os << indent << "NumberOfTimeSteps: " << this->NumberOfTimeSteps << "\n";
}
