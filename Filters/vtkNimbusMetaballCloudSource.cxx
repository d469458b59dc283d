#include "vtkNimbusMetaballCloudSource.h"

#include "FiniteSetters.h"
#include "GridParameters.h"
#include "MemoryBudget.h"
#include "Metaballs.h"
#include "PieceExtent.h"
#include "Random.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusMetaballCloudSource);

struct vtkNimbusMetaballCloudSource::vtkInternals
{
  std::vector<nimbus::Metaball> UserBalls;
  // What RequestData was asked for: the density's extent (a piece of the whole, with its
  // ghost layers) and whether port 1 gets the metaballs (only piece 0 of a piece request).
  nimbus::GridExtent Extent{ { 0, -1, 0, -1, 0, -1 } };
  bool WithMetaballs = true;
};

namespace
{
// Grid geometry covering the bounds; an axis with one point sits at the bounds' centre.
nimbus::GridGeometry MakeGrid(const int dims[3], const double bounds[6])
{
  nimbus::GridGeometry grid;
  for (int a = 0; a < 3; ++a)
  {
    grid.Dimensions[a] = dims[a];
    const double length = bounds[2 * a + 1] - bounds[2 * a];
    if (dims[a] > 1)
    {
      grid.Origin[a] = bounds[2 * a];
      grid.Spacing[a] = length / (dims[a] - 1);
    }
    else
    {
      grid.Origin[a] = bounds[2 * a] + 0.5 * length;
      grid.Spacing[a] = length > 0.0 ? length : 1.0;
    }
  }
  return grid;
}

using nimbus::AllFinite;

// Valid ranges (see the class documentation).
constexpr double MaximumLength = 1.0e8;      // m: coordinates, radii, heights
constexpr double MaximumBallDensity = 1.0e6; // dimensionless; 1e7 balls x 1e6 << FLT_MAX
constexpr int MaximumNumberOfLevels = 100;
constexpr double MaximumBallCountFactor = 1.0e3;
constexpr double MaximumNumberOfBalls = 1.0e7;
// About a few minutes of work at ~1e9 simple updates per second.
constexpr double MaximumWork = 2.0e11;
constexpr double MiB = 1048576.0;

// Estimated triangles of an isosurface on the grid: a cloud's surface crosses about
// 6 points^(2/3) grid cells (a cube's faces), with about 2 triangles each, times 4 for a
// rough, grown surface. Only for the memory and work estimates.
double EstimatedTriangles(double points)
{
  return 48.0 * std::pow(points, 2.0 / 3.0);
}

std::string Number(double value)
{
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

// The isosurface's points (x, y, z each) and its triangles (three point ids each).
void SurfaceTriangles(
  vtkPolyData* surface, std::vector<double>& points, std::vector<std::int64_t>& triangles)
{
  points.resize(3 * static_cast<std::size_t>(surface->GetNumberOfPoints()));
  for (vtkIdType p = 0; p < surface->GetNumberOfPoints(); ++p)
  {
    surface->GetPoint(p, &points[3 * p]);
  }
  triangles.reserve(3 * static_cast<std::size_t>(surface->GetNumberOfPolys()));
  auto iterator = vtk::TakeSmartPointer(surface->GetPolys()->NewIterator());
  for (iterator->GoToFirstCell(); !iterator->IsDoneWithTraversal(); iterator->GoToNextCell())
  {
    vtkIdType size;
    const vtkIdType* ids;
    iterator->GetCurrentCell(size, ids);
    if (size == 3)
    {
      triangles.insert(triangles.end(), { ids[0], ids[1], ids[2] });
    }
  }
}

// Port 1: a vertex per ball at its centre, with its radius, density and growth level.
void FillMetaballOutput(const std::vector<nimbus::Metaball>& balls, vtkPolyData* metaballs)
{
  vtkNew<vtkPoints> centres;
  centres->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> radii;
  radii->SetName("radius");
  vtkNew<vtkDoubleArray> densities;
  densities->SetName("density");
  vtkNew<vtkIntArray> levels;
  levels->SetName("level");
  vtkNew<vtkCellArray> vertices;
  for (const auto& ball : balls)
  {
    const vtkIdType id = centres->InsertNextPoint(ball.Center.data());
    radii->InsertNextValue(ball.Radius);
    densities->InsertNextValue(ball.Density);
    levels->InsertNextValue(ball.Level);
    vertices->InsertNextCell(1, &id);
  }
  metaballs->SetPoints(centres);
  metaballs->SetVerts(vertices);
  metaballs->GetPointData()->AddArray(radii);
  metaballs->GetPointData()->AddArray(densities);
  metaballs->GetPointData()->AddArray(levels);
}
}

vtkNimbusMetaballCloudSource::vtkNimbusMetaballCloudSource()
  : Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
  this->Dimensions[0] = 96;
  this->Dimensions[1] = 96;
  this->Dimensions[2] = 64;
  const double bounds[6] = { -1500.0, 1500.0, -1500.0, 1500.0, 800.0, 2800.0 };
  std::copy(bounds, bounds + 6, this->Bounds);
  this->Seed = 1;
  this->NumberOfLevels = 3;
  this->NumberOfBaseBalls = 10;
  this->BaseBallRadiusRange[0] = 350.0;
  this->BaseBallRadiusRange[1] = 600.0;
  this->FootprintRadius = 700.0;
  this->TowerHeight = 600.0;
  this->BallsPerLevel = 60;
  this->BallCountFactor = 2.0;
  this->RadiusScalePerLevel = 0.5;
  this->BallDensity = 1.0;
  this->IsoValue = 0.5;
  this->FlatBase = true;
  this->BaseHeight = 1000.0;
  this->BaseTransitionThickness = 100.0;
  this->MemoryBudgetMiB = nimbus::DefaultMemoryBudgetMiB();
  this->MemoryBudgetRangeMiB[0] = 1.0;
  this->MemoryBudgetRangeMiB[1] = this->MemoryBudgetMiB;
}

vtkNimbusMetaballCloudSource::~vtkNimbusMetaballCloudSource() = default;

void vtkNimbusMetaballCloudSource::AddBall(
  double x, double y, double z, double radius, double density)
{
  nimbus::Metaball ball;
  ball.Center = { { x, y, z } };
  ball.Radius = radius;
  ball.Density = density;
  ball.Level = 0;
  this->Internals->UserBalls.push_back(ball);
  this->Modified();
}

void vtkNimbusMetaballCloudSource::RemoveAllBalls()
{
  if (!this->Internals->UserBalls.empty())
  {
    this->Internals->UserBalls.clear();
    this->Modified();
  }
}

int vtkNimbusMetaballCloudSource::GetNumberOfUserBalls() const
{
  return static_cast<int>(this->Internals->UserBalls.size());
}

vtkPolyData* vtkNimbusMetaballCloudSource::GetMetaballs()
{
  return vtkPolyData::SafeDownCast(this->GetOutputDataObject(1));
}

int vtkNimbusMetaballCloudSource::FillOutputPortInformation(int port, vtkInformation* info)
{
  if (port == 1)
  {
    info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkPolyData");
    return 1;
  }
  return this->Superclass::FillOutputPortInformation(port, info);
}

bool vtkNimbusMetaballCloudSource::CheckParameters()
{
  return this->CheckGridParameters() && this->CheckBallParameters() &&
    this->CheckShapeParameters() && this->CheckMemoryAndWork();
}

bool vtkNimbusMetaballCloudSource::CheckGridParameters()
{
  const std::string problem = nimbus::CheckGridParameters(
    this->MemoryBudgetMiB, this->Dimensions, this->Bounds, MaximumLength);
  if (!problem.empty())
  {
    vtkErrorMacro(<< problem);
    return false;
  }
  return true;
}

bool vtkNimbusMetaballCloudSource::CheckBallParameters()
{
  const double scalars[] = { this->FootprintRadius, this->TowerHeight, this->BallCountFactor,
    this->RadiusScalePerLevel, this->BallDensity, this->IsoValue, this->BaseHeight,
    this->BaseTransitionThickness, this->BaseBallRadiusRange[0], this->BaseBallRadiusRange[1] };
  if (!AllFinite(scalars, static_cast<int>(sizeof(scalars) / sizeof(scalars[0]))))
  {
    vtkErrorMacro(<< "A parameter is NaN or infinite; every radius, height, factor, density "
                     "and the iso-value must be finite.");
    return false;
  }
  if (this->NumberOfLevels < 0 || this->BallsPerLevel < 0)
  {
    vtkErrorMacro(<< "NumberOfLevels and BallsPerLevel must be >= 0.");
    return false;
  }
  if (this->NumberOfLevels > MaximumNumberOfLevels)
  {
    vtkErrorMacro(<< "NumberOfLevels is " << this->NumberOfLevels << "; at most "
                  << MaximumNumberOfLevels
                  << " growth levels are allowed (each level shrinks the balls by "
                     "RadiusScalePerLevel; a handful of levels reaches the grid spacing).");
    return false;
  }
  const auto& userBalls = this->Internals->UserBalls;
  if (userBalls.empty())
  {
    if (this->NumberOfBaseBalls < 1)
    {
      vtkErrorMacro(<< "No balls: NumberOfBaseBalls is " << this->NumberOfBaseBalls
                    << " and no ball was added with AddBall.");
      return false;
    }
    if (!(this->BaseBallRadiusRange[0] > 0.0) ||
      this->BaseBallRadiusRange[1] < this->BaseBallRadiusRange[0] ||
      this->BaseBallRadiusRange[1] > MaximumLength)
    {
      vtkErrorMacro(<< "BaseBallRadiusRange must satisfy 0 < min <= max <= " << MaximumLength
                    << " m, got (" << this->BaseBallRadiusRange[0] << ", "
                    << this->BaseBallRadiusRange[1] << ").");
      return false;
    }
  }
  for (const auto& ball : userBalls)
  {
    const double values[] = { ball.Center[0], ball.Center[1], ball.Center[2], ball.Radius,
      ball.Density };
    if (!AllFinite(values, 5) || !(ball.Radius > 0.0) || ball.Density < 0.0 ||
      ball.Radius > MaximumLength || ball.Density > MaximumBallDensity ||
      std::abs(ball.Center[0]) > MaximumLength || std::abs(ball.Center[1]) > MaximumLength ||
      std::abs(ball.Center[2]) > MaximumLength)
    {
      vtkErrorMacro(<< "AddBall: every ball needs a finite centre within +-" << MaximumLength
                    << " m, a radius in (0, " << MaximumLength << "] m and a density in [0, "
                    << MaximumBallDensity << "]; got centre (" << ball.Center[0] << ", "
                    << ball.Center[1] << ", " << ball.Center[2] << "), radius " << ball.Radius
                    << ", density " << ball.Density << ".");
      return false;
    }
  }
  return true;
}

bool vtkNimbusMetaballCloudSource::CheckShapeParameters()
{
  if (this->BallDensity < 0.0 || this->FootprintRadius < 0.0 || this->TowerHeight < 0.0 ||
    this->BaseTransitionThickness < 0.0)
  {
    vtkErrorMacro(<< "BallDensity, FootprintRadius, TowerHeight and BaseTransitionThickness "
                     "must be >= 0.");
    return false;
  }
  if (this->BallDensity > MaximumBallDensity)
  {
    vtkErrorMacro(<< "BallDensity is " << this->BallDensity << "; at most " << MaximumBallDensity
                  << " (the density is dimensionless, 1 for a typical cloud; larger values "
                     "would overflow the float output where balls overlap).");
    return false;
  }
  if (this->FootprintRadius > MaximumLength || this->TowerHeight > MaximumLength ||
    this->BaseTransitionThickness > MaximumLength || std::abs(this->BaseHeight) > MaximumLength)
  {
    vtkErrorMacro(<< "FootprintRadius, TowerHeight, BaseTransitionThickness and |BaseHeight| "
                     "must be at most "
                  << MaximumLength << " m.");
    return false;
  }
  if (!(this->RadiusScalePerLevel > 0.0) || !(this->BallCountFactor > 0.0))
  {
    vtkErrorMacro(<< "RadiusScalePerLevel and BallCountFactor must be > 0.");
    return false;
  }
  if (this->RadiusScalePerLevel > 1.0 || this->BallCountFactor > MaximumBallCountFactor)
  {
    vtkErrorMacro(<< "RadiusScalePerLevel must be in (0, 1] (growth balls are smaller than "
                     "the basic shape's) and BallCountFactor in (0, "
                  << MaximumBallCountFactor << "]; got " << this->RadiusScalePerLevel << " and "
                  << this->BallCountFactor << ".");
    return false;
  }
  return true;
}

bool vtkNimbusMetaballCloudSource::CheckMemoryAndWork()
{
  // --- memory and work, estimated before anything is allocated --------------------------------
  const int* d = this->Dimensions;
  const auto& userBalls = this->Internals->UserBalls;
  std::uint64_t points = 0;
  if (!nimbus::CheckedProduct({ static_cast<std::uint64_t>(d[0]), static_cast<std::uint64_t>(d[1]),
                                static_cast<std::uint64_t>(d[2]) },
        points))
  {
    vtkErrorMacro(<< "Dimensions (" << d[0] << ", " << d[1] << ", " << d[2]
                  << ") have more grid points than 64 bits can count.");
    return false;
  }
  const nimbus::GridGeometry grid = MakeGrid(this->Dimensions, this->Bounds);
  const double pointCount = static_cast<double>(points);
  const int levels = this->NumberOfLevels;
  double radiusMax = this->BaseBallRadiusRange[1];
  double balls = userBalls.empty() ? this->NumberOfBaseBalls : userBalls.size();
  if (!userBalls.empty())
  {
    radiusMax = 0.0;
    for (const auto& ball : userBalls)
    {
      radiusMax = std::max(radiusMax, ball.Radius);
    }
  }
  // Sampling passes: one per growth level and the final one; each visits every ball's box.
  double sampleWork = balls * nimbus::MetaballBoxPoints(radiusMax, grid); // balls so far
  double work = pointCount + sampleWork;
  const double triangles = levels > 0 ? EstimatedTriangles(pointCount) : 0.0;
  double levelCount = this->BallsPerLevel;
  double radius = radiusMax;
  for (int level = 1; level <= levels; ++level)
  {
    // Growth: flying edges over the grid and the gradient of every ball at every triangle.
    work += pointCount + triangles * (balls + 1.0);
    radius *= this->RadiusScalePerLevel;
    balls += levelCount;
    sampleWork += levelCount * nimbus::MetaballBoxPoints(radius, grid);
    work += pointCount + sampleWork;
    levelCount *= this->BallCountFactor;
    if (!(balls <= MaximumNumberOfBalls))
    {
      break;
    }
  }
  if (!(balls <= MaximumNumberOfBalls))
  {
    vtkErrorMacro(<< "The growth would place " << Number(balls) << " metaballs or more ("
                  << this->BallsPerLevel << " at the first level, times " << this->BallCountFactor
                  << " per level, " << levels << " levels), more than the limit of "
                  << Number(MaximumNumberOfBalls)
                  << "; lower NumberOfLevels, BallsPerLevel or BallCountFactor.");
    return false;
  }
  // Bytes: the density (float) and its output copy, flying edges' edge cases (1 byte per
  // point) and row metadata (6 ids per x row), the isosurface (about 100 bytes per
  // triangle with its points and our copies), the balls (48 bytes) and their output
  // polydata (about 60 bytes).
  const double rows = static_cast<double>(d[1]) * d[2];
  const double bytes =
    pointCount * 9.0 + (levels > 0 ? rows * 48.0 + triangles * 100.0 : 0.0) + balls * 108.0;
  std::ostringstream what;
  what << "the metaball cloud (" << d[0] << " x " << d[1] << " x " << d[2] << " points, "
       << Number(balls) << " balls)";
  const std::string overBudget =
    nimbus::OverBudgetMessage(what.str(), bytes, this->MemoryBudgetMiB * MiB);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< overBudget
                  << " (MemoryBudgetMiB); lower Dimensions, NumberOfLevels or BallsPerLevel, or "
                     "raise MemoryBudgetMiB.");
    return false;
  }
  if (!(work <= MaximumWork))
  {
    vtkErrorMacro(<< "The metaball cloud would need about " << Number(work)
                  << " grid-point and ball updates (" << d[0] << " x " << d[1] << " x " << d[2]
                  << " points, " << levels << " growth levels, " << Number(balls)
                  << " balls), more than the limit of " << Number(MaximumWork)
                  << " (minutes of work); lower Dimensions, NumberOfLevels, BallsPerLevel or "
                     "the ball radii.");
    return false;
  }
  return true;
}

int vtkNimbusMetaballCloudSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  // Invalid parameters give an empty extent; RequestData reports the error once.
  int extent[6] = { 0, -1, 0, -1, 0, -1 };
  double origin[3] = { 0.0, 0.0, 0.0 };
  double spacing[3] = { 1.0, 1.0, 1.0 };
  const int* d = this->Dimensions;
  if (d[0] >= 1 && d[1] >= 1 && d[2] >= 1 && AllFinite(this->Bounds, 6))
  {
    const nimbus::GridGeometry grid = MakeGrid(this->Dimensions, this->Bounds);
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a + 1] = d[a] - 1;
      origin[a] = grid.Origin[a];
      spacing[a] = grid.Spacing[a];
    }
  }
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  // Pieces: the growth runs on the whole grid, the final sampling on the requested extent.
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

int vtkNimbusMetaballCloudSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* image = vtkImageData::GetData(outputVector, 0);
  vtkPolyData* metaballs = vtkPolyData::GetData(outputVector, 1);
  image->Initialize();
  metaballs->Initialize();
  if (!this->CheckParameters())
  {
    return 1; // empty outputs; the error has been reported
  }
  int extent[6];
  const bool anyPoint = nimbus::RequestedExtent(outputVector->GetInformationObject(0), extent);
  std::copy(extent, extent + 6, this->Internals->Extent.begin());
  if (!anyPoint)
  {
    this->Internals->Extent = { { 0, -1, 0, -1, 0, -1 } };
  }
  vtkInformation* ballInfo = outputVector->GetInformationObject(1);
  this->Internals->WithMetaballs =
    !ballInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) ||
    ballInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) == 0;
  // The budget above is an estimate: whatever still goes wrong ends here, not in ParaView.
  try
  {
    return this->Generate(image, metaballs);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "Out of memory while generating the metaball cloud; lower Dimensions, "
                     "NumberOfLevels or BallsPerLevel, or MemoryBudgetMiB.");
  }
  catch (const std::length_error& error)
  {
    vtkErrorMacro(<< "The metaball cloud is too large (" << error.what()
                  << "); lower Dimensions, NumberOfLevels or BallsPerLevel.");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< "Cannot generate the metaball cloud: " << error.what());
  }
  image->Initialize();
  metaballs->Initialize();
  return 1;
}

int vtkNimbusMetaballCloudSource::Generate(vtkImageData* image, vtkPolyData* metaballs)
{
  // Progress: growth levels and the final sampling share [0, 1]; each reports inside too.
  const int totalSteps = this->NumberOfLevels + 1;
  double stepStart = 0.0;
  const nimbus::ProgressCallback progress = [this, &stepStart, totalSteps](double fraction)
  {
    this->UpdateProgress((stepStart + std::clamp(fraction, 0.0, 1.0)) / totalSteps);
    return !this->CheckAbort();
  };
  auto aborted = [image, metaballs]()
  {
    image->Initialize();
    metaballs->Initialize();
    return 1;
  };

  const nimbus::GridGeometry grid = MakeGrid(this->Dimensions, this->Bounds);
  nimbus::Random random(static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed)));
  std::vector<nimbus::Metaball> balls = this->MakeBasicShape(random);
  std::vector<float> density;
  if (!this->GrowBalls(grid, random, stepStart, progress, balls, density))
  {
    return aborted();
  }

  // Final density on the requested extent only (the whole grid, or a piece with its ghost
  // layers): SampleMetaballs gives every point the same sum as the whole grid's sampling.
  stepStart = this->NumberOfLevels;
  this->UpdateProgress(stepStart / totalSteps);
  const nimbus::GridExtent& extent = this->Internals->Extent;
  const bool anyPoint = extent[0] <= extent[1];
  if (anyPoint && !nimbus::SampleMetaballs(balls, grid, extent, density, progress))
  {
    return aborted();
  }
  if (!anyPoint)
  {
    density.clear();
  }
  if (this->FlatBase && anyPoint)
  {
    nimbus::ApplyCloudBase(grid, extent, this->BaseHeight, this->BaseTransitionThickness, density);
  }
  if (!this->FillDensityOutput(grid, density, image))
  {
    return aborted();
  }

  // Port 1: the metaballs themselves (once: on piece 0 of a piece request).
  if (this->Internals->WithMetaballs)
  {
    FillMetaballOutput(balls, metaballs);
  }
  this->UpdateProgress(1.0);
  return 1;
}

std::vector<nimbus::Metaball> vtkNimbusMetaballCloudSource::MakeBasicShape(nimbus::Random& random)
{
  // Basic shape: the balls added with AddBall, else NumberOfBaseBalls placed at random.
  std::vector<nimbus::Metaball> balls = this->Internals->UserBalls;
  if (balls.empty())
  {
    nimbus::BasicShapeParameters shape;
    shape.NumberOfBalls = this->NumberOfBaseBalls;
    shape.RadiusMin = this->BaseBallRadiusRange[0];
    shape.RadiusMax = this->BaseBallRadiusRange[1];
    shape.Density = this->BallDensity;
    shape.Center = { { 0.5 * (this->Bounds[0] + this->Bounds[1]),
      0.5 * (this->Bounds[2] + this->Bounds[3]), 0.0 } };
    shape.FootprintRadius = this->FootprintRadius;
    shape.BaseHeight = this->BaseHeight;
    shape.TowerHeight = this->TowerHeight;
    balls = nimbus::MakeBasicShape(shape, random);
  }
  return balls;
}

bool vtkNimbusMetaballCloudSource::GrowBalls(const nimbus::GridGeometry& grid,
  nimbus::Random& random, double& stepStart, const std::function<bool(double)>& progress,
  std::vector<nimbus::Metaball>& balls, std::vector<float>& density)
{
  // Fractal growth (004 §4): isosurface -> balls on its triangles -> repeat.
  const int totalSteps = this->NumberOfLevels + 1;
  vtkNew<vtkImageData> field;
  field->SetDimensions(grid.Dimensions.data());
  field->SetOrigin(grid.Origin.data());
  field->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> fieldArray;
  fieldArray->SetName("density");
  field->GetPointData()->SetScalars(fieldArray);
  double radiusScale = 1.0;
  double ballCount = this->BallsPerLevel;
  // Growth radii scale from the basic shape's radius range.
  double radiusMin = this->BaseBallRadiusRange[0];
  double radiusMax = this->BaseBallRadiusRange[1];
  if (!this->Internals->UserBalls.empty())
  {
    radiusMin = radiusMax = this->Internals->UserBalls.front().Radius;
    for (const auto& ball : this->Internals->UserBalls)
    {
      radiusMin = std::min(radiusMin, ball.Radius);
      radiusMax = std::max(radiusMax, ball.Radius);
    }
  }
  for (int level = 1; level <= this->NumberOfLevels; ++level)
  {
    stepStart = level - 1;
    this->UpdateProgress(stepStart / totalSteps);
    if (this->CheckAbort())
    {
      return false;
    }
    // Sampling, flying edges and the growth share the level's part of the progress.
    auto part = [&progress](double from, double to)
    { return [&progress, from, to](double f) { return progress(from + (to - from) * f); }; };
    if (!nimbus::SampleMetaballs(balls, grid, density, part(0.0, 0.5)))
    {
      return false;
    }
    fieldArray->SetArray(density.data(), static_cast<vtkIdType>(density.size()), 1);
    fieldArray->Modified();

    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputData(field);
    contour->SetValue(0, this->IsoValue);
    contour->ComputeNormalsOff();
    contour->ComputeGradientsOff();
    contour->ComputeScalarsOff();
    contour->Update();
    if (!progress(0.7))
    {
      return false;
    }
    std::vector<double> points;
    std::vector<std::int64_t> triangles;
    SurfaceTriangles(contour->GetOutput(), points, triangles);

    radiusScale *= this->RadiusScalePerLevel;
    nimbus::GrowthParameters growth;
    growth.NumberOfBalls = static_cast<int>(std::lround(ballCount));
    growth.RadiusMin = radiusMin * radiusScale;
    growth.RadiusMax = radiusMax * radiusScale;
    growth.Density = this->BallDensity;
    growth.Level = level;
    bool stopped = false;
    auto growthProgress = part(0.7, 1.0);
    const std::vector<nimbus::Metaball> grown =
      nimbus::GrowOnSurface(balls, points, triangles, growth, random,
        [&growthProgress, &stopped](double f)
        {
          stopped = !growthProgress(f);
          return !stopped;
        });
    if (stopped)
    {
      return false;
    }
    if (grown.empty())
    {
      vtkWarningMacro(<< "Growth level " << level << ": the isosurface at IsoValue "
                      << this->IsoValue << " has no upward-facing triangle; no balls added.");
    }
    balls.insert(balls.end(), grown.begin(), grown.end());
    ballCount *= this->BallCountFactor;
  }
  fieldArray->SetArray(nullptr, 0, 1);
  return true;
}

bool vtkNimbusMetaballCloudSource::FillDensityOutput(
  const nimbus::GridGeometry& grid, const std::vector<float>& density, vtkImageData* image)
{
  const nimbus::GridExtent& extent = this->Internals->Extent;
  int outputExtent[6];
  std::copy(extent.begin(), extent.end(), outputExtent);
  image->SetExtent(outputExtent);
  image->SetOrigin(grid.Origin.data());
  image->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> densityArray;
  densityArray->SetName("density");
  densityArray->SetNumberOfTuples(static_cast<vtkIdType>(density.size()));
  std::copy(density.begin(), density.end(), densityArray->GetPointer(0));
  image->GetPointData()->SetScalars(densityArray);
  // Checked ranges keep every sum finite; check anyway (cheap next to the sampling).
  const nimbus::ValueCensus census = nimbus::TakeCensus(density.data(), density.size());
  if (!census.AllFiniteNonNegative())
  {
    vtkErrorMacro(<< "The density has " << nimbus::DescribeCensus(census)
                  << "; the output is withheld. Lower BallDensity or the number of balls.");
    return false;
  }
  return true;
}

void vtkNimbusMetaballCloudSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " "
     << this->Dimensions[2] << "\n";
  os << indent << "Bounds:";
  for (double b : this->Bounds)
  {
    os << " " << b;
  }
  os << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NumberOfLevels: " << this->NumberOfLevels << "\n";
  os << indent << "NumberOfBaseBalls: " << this->NumberOfBaseBalls << "\n";
  os << indent << "BaseBallRadiusRange: " << this->BaseBallRadiusRange[0] << " "
     << this->BaseBallRadiusRange[1] << "\n";
  os << indent << "FootprintRadius: " << this->FootprintRadius << "\n";
  os << indent << "TowerHeight: " << this->TowerHeight << "\n";
  os << indent << "BallsPerLevel: " << this->BallsPerLevel << "\n";
  os << indent << "BallCountFactor: " << this->BallCountFactor << "\n";
  os << indent << "RadiusScalePerLevel: " << this->RadiusScalePerLevel << "\n";
  os << indent << "BallDensity: " << this->BallDensity << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "FlatBase: " << (this->FlatBase ? "On" : "Off") << "\n";
  os << indent << "BaseHeight: " << this->BaseHeight << "\n";
  os << indent << "BaseTransitionThickness: " << this->BaseTransitionThickness << "\n";
  os << indent << "NumberOfUserBalls: " << this->GetNumberOfUserBalls() << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
}
