#include "vtkNimbusOpenVDBWriter.h"

#include "VdbGrids.h"

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

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace vdb = nimbus::vdb;

vtkStandardNewMacro(vtkNimbusOpenVDBWriter);

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

  int extent[6];
  input->GetExtent(extent);
  vdb::TransformInfo pointTransform;
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
  vdb::IndexBox pointBox;
  for (int c = 0; c < 3; ++c)
  {
    pointBox.Min[c] = extent[2 * c];
    pointBox.Max[c] = extent[2 * c + 1];
  }
  // Cells: cell (i, j, k) is centred half a voxel up each axis that has cells.
  vdb::TransformInfo cellTransform = pointTransform;
  vdb::IndexBox cellBox = pointBox;
  for (int c = 0; c < 3; ++c)
  {
    if (extent[2 * c + 1] > extent[2 * c])
    {
      cellBox.Max[c] = extent[2 * c + 1] - 1;
      for (int r = 0; r < 3; ++r)
      {
        cellTransform.Origin[r] += 0.5 * spacing[c] * pointTransform.Direction[3 * c + r];
      }
    }
  }

  std::vector<vdb::FieldToWrite> fields;
  std::vector<std::unique_ptr<std::vector<float>>> storage;
  std::set<std::string> names;
  std::string skipped;
  auto collect = [&](vtkDataSetAttributes* data, const vdb::IndexBox& box,
                   const vdb::TransformInfo& transform, bool cells)
  {
    const vtkIdType expected = static_cast<vtkIdType>(box.VoxelCount());
    for (int i = 0; i < data->GetNumberOfArrays(); ++i)
    {
      vtkDataArray* array = data->GetArray(i);
      if (!array || !array->GetName() ||
        std::string(array->GetName()) == vtkDataSetAttributes::GhostArrayName())
      {
        continue;
      }
      const int nc = array->GetNumberOfComponents();
      if ((nc != 1 && nc != 3) || array->GetNumberOfTuples() != expected)
      {
        skipped += std::string(skipped.empty() ? "" : ", ") + "'" + array->GetName() + "' (" +
          std::to_string(nc) + " components)";
        continue;
      }
      vdb::FieldToWrite field;
      field.Name = array->GetName();
      if (cells && names.count(field.Name))
      {
        field.Name += "_cells";
      }
      names.insert(field.Name);
      field.Components = nc;
      field.Values = FloatValues(array, storage);
      field.Box = box;
      field.Transform = transform;
      field.Background = static_cast<float>(this->Background);
      field.Tolerance = static_cast<float>(this->Tolerance);
      field.FogVolume = nc == 1 && this->Background == 0.0 && array->GetRange(0)[0] >= 0.0;
      fields.push_back(field);
    }
  };
  collect(input->GetPointData(), pointBox, pointTransform, false);
  if (this->WriteCellData && input->GetNumberOfCells() > 0)
  {
    collect(input->GetCellData(), cellBox, cellTransform, true);
  }
  if (!skipped.empty())
  {
    vtkWarningMacro(<< "arrays not written (only 1- and 3-component arrays become grids): "
                    << skipped);
  }
  if (fields.empty())
  {
    vtkErrorMacro(<< "nothing to write to " << this->FileName
                  << ": the image has no 1- or 3-component numeric point or cell arrays");
    this->SetErrorCode(vtkErrorCode::UnknownError);
    return;
  }
  try
  {
    this->NumberOfActiveVoxels = static_cast<vtkIdType>(vdb::WriteFields(
      this->FileName, fields, this->Compress, [this](double f) { this->UpdateProgress(f); }));
  }
  catch (const vdb::Error& e)
  {
    vtkErrorMacro(<< e.what());
    this->SetErrorCode(vtkErrorCode::CannotOpenFileError);
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
