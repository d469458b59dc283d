#include "vtkNimbusMetaballCloudSource.h"

#include "Metaballs.h"
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
#include <vector>

vtkStandardNewMacro(vtkNimbusMetaballCloudSource);

struct vtkNimbusMetaballCloudSource::vtkInternals
{
  std::vector<nimbus::Metaball> UserBalls;
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

bool AllFinite(const double* values, int count)
{
  for (int i = 0; i < count; ++i)
  {
    if (!std::isfinite(values[i]))
    {
      return false;
    }
  }
  return true;
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
  const int* d = this->Dimensions;
  if (d[0] < 1 || d[1] < 1 || d[2] < 1)
  {
    vtkErrorMacro(<< "Dimensions must be >= 1 along every axis, got (" << d[0] << ", " << d[1]
                  << ", " << d[2] << ").");
    return false;
  }
  if (!AllFinite(this->Bounds, 6))
  {
    vtkErrorMacro(<< "Bounds must be finite numbers.");
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(this->Bounds[2 * a] < this->Bounds[2 * a + 1]))
    {
      vtkErrorMacro(<< "Bounds must satisfy min < max on every axis; axis " << a << " has ("
                    << this->Bounds[2 * a] << ", " << this->Bounds[2 * a + 1] << ").");
      return false;
    }
  }
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
      this->BaseBallRadiusRange[1] < this->BaseBallRadiusRange[0])
    {
      vtkErrorMacro(<< "BaseBallRadiusRange must satisfy 0 < min <= max, got ("
                    << this->BaseBallRadiusRange[0] << ", " << this->BaseBallRadiusRange[1]
                    << ").");
      return false;
    }
  }
  for (const auto& ball : userBalls)
  {
    const double values[] = { ball.Center[0], ball.Center[1], ball.Center[2], ball.Radius,
      ball.Density };
    if (!AllFinite(values, 5) || !(ball.Radius > 0.0) || ball.Density < 0.0)
    {
      vtkErrorMacro(<< "AddBall: every ball needs a finite centre, a radius > 0 and a density "
                       ">= 0; got centre ("
                    << ball.Center[0] << ", " << ball.Center[1] << ", " << ball.Center[2]
                    << "), radius " << ball.Radius << ", density " << ball.Density << ".");
      return false;
    }
  }
  if (this->BallDensity < 0.0 || this->FootprintRadius < 0.0 || this->TowerHeight < 0.0 ||
    this->BaseTransitionThickness < 0.0)
  {
    vtkErrorMacro(<< "BallDensity, FootprintRadius, TowerHeight and BaseTransitionThickness "
                     "must be >= 0.");
    return false;
  }
  if (!(this->RadiusScalePerLevel > 0.0) || !(this->BallCountFactor > 0.0))
  {
    vtkErrorMacro(<< "RadiusScalePerLevel and BallCountFactor must be > 0.");
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

  const nimbus::GridGeometry grid = MakeGrid(this->Dimensions, this->Bounds);
  nimbus::Random random(static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed)));

  // Basic shape.
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

  // Fractal growth (004 §4): isosurface -> balls on its triangles -> repeat.
  std::vector<float> density;
  vtkNew<vtkImageData> field;
  field->SetDimensions(grid.Dimensions.data());
  field->SetOrigin(grid.Origin.data());
  field->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> fieldArray;
  fieldArray->SetName("density");
  field->GetPointData()->SetScalars(fieldArray);
  const int totalSteps = this->NumberOfLevels + 1;
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
    this->UpdateProgress(static_cast<double>(level - 1) / totalSteps);
    if (this->CheckAbort())
    {
      break;
    }
    nimbus::SampleMetaballs(balls, grid, density);
    fieldArray->SetArray(density.data(), static_cast<vtkIdType>(density.size()), 1);
    fieldArray->Modified();

    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputData(field);
    contour->SetValue(0, this->IsoValue);
    contour->ComputeNormalsOff();
    contour->ComputeGradientsOff();
    contour->ComputeScalarsOff();
    contour->Update();
    vtkPolyData* surface = contour->GetOutput();

    std::vector<double> points(3 * static_cast<std::size_t>(surface->GetNumberOfPoints()));
    for (vtkIdType p = 0; p < surface->GetNumberOfPoints(); ++p)
    {
      surface->GetPoint(p, &points[3 * p]);
    }
    std::vector<std::int64_t> triangles;
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

    radiusScale *= this->RadiusScalePerLevel;
    nimbus::GrowthParameters growth;
    growth.NumberOfBalls = static_cast<int>(std::lround(ballCount));
    growth.RadiusMin = radiusMin * radiusScale;
    growth.RadiusMax = radiusMax * radiusScale;
    growth.Density = this->BallDensity;
    growth.Level = level;
    const std::vector<nimbus::Metaball> grown =
      nimbus::GrowOnSurface(balls, points, triangles, growth, random);
    if (grown.empty())
    {
      vtkWarningMacro(<< "Growth level " << level << ": the isosurface at IsoValue "
                      << this->IsoValue << " has no upward-facing triangle; no balls added.");
    }
    balls.insert(balls.end(), grown.begin(), grown.end());
    ballCount *= this->BallCountFactor;
  }
  fieldArray->SetArray(nullptr, 0, 1);

  // Final density on the output grid.
  this->UpdateProgress(static_cast<double>(this->NumberOfLevels) / totalSteps);
  nimbus::SampleMetaballs(balls, grid, density);
  if (this->FlatBase)
  {
    nimbus::ApplyCloudBase(grid, this->BaseHeight, this->BaseTransitionThickness, density);
  }

  int extent[6] = { 0, grid.Dimensions[0] - 1, 0, grid.Dimensions[1] - 1, 0,
    grid.Dimensions[2] - 1 };
  image->SetExtent(extent);
  image->SetOrigin(grid.Origin.data());
  image->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> densityArray;
  densityArray->SetName("density");
  densityArray->SetNumberOfTuples(static_cast<vtkIdType>(density.size()));
  std::copy(density.begin(), density.end(), densityArray->GetPointer(0));
  image->GetPointData()->SetScalars(densityArray);

  // Port 1: the metaballs themselves.
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

  this->UpdateProgress(1.0);
  return 1;
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
}
