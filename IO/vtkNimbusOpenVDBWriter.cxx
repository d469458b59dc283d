#include "vtkNimbusOpenVDBWriter.h"

#include "FiniteSetters.h"

#include "VdbGrids.h"

#include "vtkAbstractArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkErrorCode.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include <cerrno>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace vdb = nimbus::vdb;

vtkStandardNewMacro(vtkNimbusOpenVDBWriter);

// Setters with a range refuse NaN and infinity at once (the value is kept) and clamp
// finite values (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusOpenVDBWriter, Tolerance);

vtkNimbusOpenVDBWriter::vtkNimbusOpenVDBWriter() = default;

vtkNimbusOpenVDBWriter::~vtkNimbusOpenVDBWriter()
{
  this->SetFileName(nullptr);
}

int vtkNimbusOpenVDBWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

vtkImageData* vtkNimbusOpenVDBWriter::GetInput()
{
  return vtkImageData::SafeDownCast(this->Superclass::GetInput());
}

namespace
{
// Float values of `array` (its own buffer for a vtkFloatArray, else a converted copy kept
// in `storage`).
const float* FloatValues(
  vtkDataArray* array, std::vector<std::unique_ptr<std::vector<float>>>& storage)
{
  if (auto* f = vtkFloatArray::SafeDownCast(array))
  {
    return f->GetPointer(0);
  }
  const vtkIdType n = array->GetNumberOfValues();
  storage.push_back(std::unique_ptr<std::vector<float>>(new std::vector<float>(n)));
  std::vector<float>& values = *storage.back();
  const int nc = array->GetNumberOfComponents();
  for (vtkIdType t = 0; t < array->GetNumberOfTuples(); ++t)
  {
    for (int c = 0; c < nc; ++c)
    {
      values[t * nc + c] = static_cast<float>(array->GetComponent(t, c));
    }
  }
  return values.data();
}

// Where the point and the cell grids sit: index boxes and index-to-world transforms.
struct GridPlacement
{
  vdb::TransformInfo PointTransform, CellTransform;
  vdb::IndexBox PointBox, CellBox;
};

GridPlacement PlaceGrids(vtkImageData* input)
{
  GridPlacement placement;
  int extent[6];
  input->GetExtent(extent);
  vdb::TransformInfo& pointTransform = placement.PointTransform;
  const double* origin = input->GetOrigin();
  const double* spacing = input->GetSpacing();
  const double* d = input->GetDirectionMatrix()->GetData(); // row-major
  for (int c = 0; c < 3; ++c)
  {
    pointTransform.Origin[c] = origin[c];
    pointTransform.Spacing[c] = spacing[c];
    for (int r = 0; r < 3; ++r)
    {
      pointTransform.Direction[3 * c + r] = d[3 * r + c];
    }
  }
  vdb::IndexBox& pointBox = placement.PointBox;
  for (int c = 0; c < 3; ++c)
  {
    pointBox.Min[c] = extent[2 * c];
    pointBox.Max[c] = extent[2 * c + 1];
  }
  // Cells: cell (i, j, k) is centred half a voxel up each axis that has cells.
  placement.CellTransform = pointTransform;
  placement.CellBox = pointBox;
  for (int c = 0; c < 3; ++c)
  {
    if (extent[2 * c + 1] > extent[2 * c])
    {
      placement.CellBox.Max[c] = extent[2 * c + 1] - 1;
      for (int r = 0; r < 3; ++r)
      {
        placement.CellTransform.Origin[r] += 0.5 * spacing[c] * pointTransform.Direction[3 * c + r];
      }
    }
  }
  return placement;
}

// The grids to write, from the arrays that can be grids, with what was skipped or renamed.
// Grid names: every point array keeps its name; a cell array keeps its name unless a
// point array (or an earlier cell array's new name) has it, then it becomes
// "<name>_cells", or "<name>_cells_2", "_cells_3"... the first that no array has.
struct FieldCollector
{
  std::set<std::string> Reserved; // every array's name, points and cells
  std::vector<vdb::FieldToWrite> Fields;
  std::vector<std::unique_ptr<std::vector<float>>> Storage; // converted values
  std::set<std::string> Names;                              // the grids' names so far
  std::string Skipped, Renamed;
  float Background = 0.0f;
  float Tolerance = 0.0f;
  bool BackgroundIsZero = false;

  explicit FieldCollector(vtkImageData* input)
  {
    for (vtkDataSetAttributes* data : { static_cast<vtkDataSetAttributes*>(input->GetPointData()),
           static_cast<vtkDataSetAttributes*>(input->GetCellData()) })
    {
      for (int i = 0; i < data->GetNumberOfArrays(); ++i)
      {
        vtkAbstractArray* array = data->GetAbstractArray(i);
        if (array && array->GetName())
        {
          this->Reserved.insert(array->GetName());
        }
      }
    }
  }

  void Collect(vtkDataSetAttributes* data, const vdb::IndexBox& box,
    const vdb::TransformInfo& transform, bool cells)
  {
    const char* kind = cells ? "cell" : "point";
    const vtkIdType expected = static_cast<vtkIdType>(box.VoxelCount());
    for (int i = 0; i < data->GetNumberOfArrays(); ++i)
    {
      vtkAbstractArray* abstract = data->GetAbstractArray(i);
      if (!abstract)
      {
        continue;
      }
      if (abstract->GetName() &&
        std::string(abstract->GetName()) == vtkDataSetAttributes::GhostArrayName())
      {
        continue;
      }
      const int nc = abstract->GetNumberOfComponents();
      if (!abstract->GetName() || !*abstract->GetName())
      {
        this->Skipped += std::string(this->Skipped.empty() ? "" : ", ") + "an unnamed " + kind +
          " array (" + std::to_string(nc) + " components; a grid needs a name)";
        continue;
      }
      vtkDataArray* array = vtkDataArray::SafeDownCast(abstract);
      if (!array || (nc != 1 && nc != 3) || array->GetNumberOfTuples() != expected)
      {
        this->Skipped += std::string(this->Skipped.empty() ? "" : ", ") + "'" +
          abstract->GetName() + "' (" +
          (array ? std::to_string(nc) + " components" : std::string("not numeric")) + ")";
        continue;
      }
      vdb::FieldToWrite field;
      field.Name = this->GridName(array->GetName(), cells);
      field.Components = nc;
      field.Values = FloatValues(array, this->Storage);
      field.Box = box;
      field.Transform = transform;
      field.Background = this->Background;
      field.Tolerance = this->Tolerance;
      field.FogVolume = nc == 1 && this->BackgroundIsZero && array->GetRange(0)[0] >= 0.0;
      this->Fields.push_back(field);
    }
  }

  std::string GridName(const std::string& arrayName, bool cells)
  {
    std::string name = arrayName;
    if (cells && this->Names.count(arrayName))
    {
      name = arrayName + "_cells";
      for (int n = 2; this->Reserved.count(name) || this->Names.count(name); ++n)
      {
        name = arrayName + "_cells_" + std::to_string(n);
      }
      this->Renamed += std::string(this->Renamed.empty() ? "" : ", ") + "cell array '" + arrayName +
        "' -> grid '" + name + "'";
    }
    this->Names.insert(name);
    return name;
  }
};
}

void vtkNimbusOpenVDBWriter::WriteData()
{
  this->SetErrorCode(vtkErrorCode::NoError);
  this->NumberOfActiveVoxels = 0;
  vtkImageData* input = this->GetInput();
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("FileName is not set: give the .vdb file to write");
    this->SetErrorCode(vtkErrorCode::NoFileNameError);
    return;
  }
  if (!input || input->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("the input image is empty: nothing to write to " << this->FileName);
    this->SetErrorCode(vtkErrorCode::UnknownError);
    return;
  }
  const GridPlacement placement = PlaceGrids(input);
  if (!std::isfinite(this->Background))
  {
    vtkErrorMacro(<< "Background must be a finite number (it is " << this->Background
                  << "): it is the value of every inactive voxel; nothing written to "
                  << this->FileName);
    this->SetErrorCode(vtkErrorCode::UnknownError);
    return;
  }

  FieldCollector collector(input);
  collector.Background = static_cast<float>(this->Background);
  collector.Tolerance = static_cast<float>(this->Tolerance);
  collector.BackgroundIsZero = this->Background == 0.0;
  collector.Collect(input->GetPointData(), placement.PointBox, placement.PointTransform, false);
  if (this->WriteCellData && input->GetNumberOfCells() > 0)
  {
    collector.Collect(input->GetCellData(), placement.CellBox, placement.CellTransform, true);
  }
  if (!collector.Renamed.empty())
  {
    vtkWarningMacro(<< "grid names of " << this->FileName
                    << " (a point array has the same name): " << collector.Renamed);
  }
  if (!collector.Fields.empty() && !collector.Skipped.empty())
  {
    vtkWarningMacro(<< "arrays not written (only named 1- and 3-component numeric arrays "
                       "become grids): "
                    << collector.Skipped);
  }
  if (collector.Fields.empty())
  {
    vtkErrorMacro(<< "nothing to write to " << this->FileName
                  << ": the image has no named 1- or 3-component numeric point or cell array"
                  << (collector.Skipped.empty() ? std::string(" (it has no arrays)")
                                                : " (it has: " + collector.Skipped + ")"));
    this->SetErrorCode(vtkErrorCode::UnknownError);
    return;
  }
  this->WriteFields(collector.Fields);
}

void vtkNimbusOpenVDBWriter::WriteFields(const std::vector<nimbus::vdb::FieldToWrite>& fields)
{
  std::vector<std::string> notes;
  int errorNumber = 0;
  try
  {
    this->NumberOfActiveVoxels = static_cast<vtkIdType>(vdb::WriteFields(
      this->FileName, fields, this->Compress, [this](double f) { this->UpdateProgress(f); }, &notes,
      &errorNumber));
  }
  catch (const vdb::Error& e)
  {
    vtkErrorMacro(<< e.what());
    if (errorNumber == ENOSPC || errorNumber == EFBIG || errorNumber == EDQUOT)
    {
      this->SetErrorCode(vtkErrorCode::OutOfDiskSpaceError);
    }
    else if (errorNumber != 0)
    {
      this->SetErrorCode(static_cast<unsigned long>(errorNumber)); // as vtkXMLWriter does
    }
    else
    {
      this->SetErrorCode(vtkErrorCode::UnknownError);
    }
    this->NumberOfActiveVoxels = 0;
    return;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< "cannot write " << this->FileName << ": " << e.what());
    this->SetErrorCode(vtkErrorCode::UnknownError);
    this->NumberOfActiveVoxels = 0;
    return;
  }
  for (const auto& note : notes)
  {
    vtkWarningMacro(<< note);
  }
}

void vtkNimbusOpenVDBWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Tolerance: " << this->Tolerance << "\n";
  os << indent << "Background: " << this->Background << "\n";
  os << indent << "WriteCellData: " << this->WriteCellData << "\n";
  os << indent << "Compress: " << this->Compress << "\n";
  os << indent << "NumberOfActiveVoxels: " << this->NumberOfActiveVoxels << "\n";
}
