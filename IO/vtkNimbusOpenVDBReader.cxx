#include "vtkNimbusOpenVDBReader.h"

#include "MemoryBudget.h"
#include "VdbGrids.h"
#include "VdbUpAxis.h"

#include "vtkCommand.h"
#include "vtkDataArraySelection.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <new>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace vdb = nimbus::vdb;

struct vtkNimbusOpenVDBReader::Internals
{
  // The file's grid descriptors, re-read when the file name or its time stamp changes.
  std::string CachedPath;
  long long CachedMTime = -1;
  long long CachedSize = -1;
  std::vector<vdb::GridInfo> Grids;
  std::map<std::string, std::string> FileStrings; // file-level string metadata

  // The up axis of the last RequestInformation/RequestData (Choose).
  vdb::UpAxisChoice UpChoice;
  bool UpChosen = false;

  vtkNew<vtkDataArraySelection> Selection;
  vtkNew<vtkStringArray> Names;

  // The piece RequestData was asked for (UPDATE_PIECE_NUMBER, UPDATE_NUMBER_OF_PIECES,
  // UPDATE_NUMBER_OF_GHOST_LEVELS and the split mode); see PieceBox.
  int Piece = 0;
  int NumberOfPieces = 1;
  int GhostLevels = 0;
  int SplitMode = vtkExtentTranslator::BLOCK_MODE;

  // The box to read. One piece: the plan's whole box, as before pieces were supported
  // (producing more than a sub-extent request asks for is allowed, and a file series whose
  // files' boxes differ must get each file whole, not the box of the file its request was
  // made for). Piece p of n: VTK's block of the whole box grown by the ghost levels and
  // clamped -- what the executive puts in UPDATE_EXTENT, computed again from this file's box.
  vdb::IndexBox PieceBox(const vdb::IndexBox& whole) const
  {
    if (this->NumberOfPieces <= 1 || whole.Empty())
    {
      return whole;
    }
    int wholeExtent[6], extent[6];
    for (int c = 0; c < 3; ++c)
    {
      wholeExtent[2 * c] = static_cast<int>(whole.Min[c]);
      wholeExtent[2 * c + 1] = static_cast<int>(whole.Max[c]);
    }
    vtkNew<vtkExtentTranslator> translator;
    vdb::IndexBox box; // empty
    if (translator->PieceToExtentThreadSafe(this->Piece, this->NumberOfPieces, this->GhostLevels,
          wholeExtent, extent, this->SplitMode, 0))
    {
      for (int c = 0; c < 3; ++c)
      {
        box.Min[c] = extent[2 * c];
        box.Max[c] = extent[2 * c + 1];
      }
    }
    return box.Intersection(whole);
  }

  // The plan of the next read.
  struct Plan
  {
    std::vector<const vdb::GridInfo*> Read; // selected supported grids, OpenVDB's order (by name)
    const vdb::GridInfo* Reference = nullptr;
    vdb::IndexBox Box;
  };

  // Reads the descriptors (if stale) and refreshes the selection list. Throws vdb::Error.
  void Refresh(const std::string& path);
  // The up axis for the UpAxis property `requested` and this file (after Refresh).
  const vdb::UpAxisChoice& ChooseUp(int requested)
  {
    std::vector<std::string> creators;
    for (const auto& g : this->Grids)
    {
      if (!g.Creator.empty())
      {
        creators.push_back(g.Creator);
      }
    }
    this->UpChoice = vdb::ChooseUpAxis(requested, this->FileStrings, creators);
    this->UpChosen = true;
    return this->UpChoice;
  }
  // Which grids to read, the reference transform and the index box. Throws vdb::Error.
  Plan MakePlan(const char* boundsGrid, const std::string& path) const;
};

namespace
{
std::string Quote(const std::string& s)
{
  return "'" + s + "'";
}

bool StatFile(const std::string& path, long long& mtime, long long& size)
{
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
  {
    return false;
  }
  mtime = static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
  size = static_cast<long long>(st.st_size);
  return true;
}

}

void vtkNimbusOpenVDBReader::Internals::Refresh(const std::string& path)
{
  Internals& in = *this;
  long long mtime = -1, size = -1;
  StatFile(path, mtime, size);
  if (path == in.CachedPath && mtime == in.CachedMTime && size == in.CachedSize && mtime >= 0)
  {
    return;
  }
  in.CachedPath.clear();
  in.UpChosen = false;
  in.Grids = vdb::ReadFileInfo(path, &in.FileStrings);
  in.CachedPath = path;
  in.CachedMTime = mtime;
  in.CachedSize = size;

  std::set<std::string> present;
  in.Names->Reset();
  for (const auto& g : in.Grids)
  {
    if (g.Supported() && present.insert(g.Name).second)
    {
      in.Names->InsertNextValue(g.Name);
      if (!in.Selection->ArrayExists(g.Name.c_str()))
      {
        in.Selection->AddArray(g.Name.c_str(), true);
      }
    }
  }
  // Forget grids of a previous file (keeps the user's choices for grids still present).
  for (int i = in.Selection->GetNumberOfArrays() - 1; i >= 0; --i)
  {
    if (!present.count(in.Selection->GetArrayName(i)))
    {
      in.Selection->RemoveArrayByIndex(i);
    }
  }
}

vtkStandardNewMacro(vtkNimbusOpenVDBReader);

vtkNimbusOpenVDBReader::vtkNimbusOpenVDBReader()
  : MemoryBudgetMiB(nimbus::DefaultMemoryBudgetMiB())
  , Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(1);
  // Selection changes must re-execute the reader.
  this->Internal->Selection->AddObserver(vtkCommand::ModifiedEvent, this, &vtkObject::Modified);
}

vtkNimbusOpenVDBReader::~vtkNimbusOpenVDBReader()
{
  this->SetFileName(nullptr);
  this->SetBoundsGrid(nullptr);
}

int vtkNimbusOpenVDBReader::CanReadFile(const char* fileName)
{
  if (!fileName)
  {
    return 0;
  }
  FILE* f = std::fopen(fileName, "rb");
  if (!f)
  {
    return 0;
  }
  unsigned char magic[4] = { 0, 0, 0, 0 };
  const size_t n = std::fread(magic, 1, 4, f);
  std::fclose(f);
  return n == 4 && magic[0] == 0x20 && magic[1] == 0x42 && magic[2] == 0x44 && magic[3] == 0x56;
}

vtkDataArraySelection* vtkNimbusOpenVDBReader::GetGridSelection()
{
  return this->Internal->Selection;
}

int vtkNimbusOpenVDBReader::GetNumberOfGridArrays()
{
  return this->Internal->Selection->GetNumberOfArrays();
}

const char* vtkNimbusOpenVDBReader::GetGridArrayName(int index)
{
  return this->Internal->Selection->GetArrayName(index);
}

int vtkNimbusOpenVDBReader::GetGridArrayStatus(const char* name)
{
  return this->Internal->Selection->ArrayIsEnabled(name);
}

void vtkNimbusOpenVDBReader::SetGridArrayStatus(const char* name, int status)
{
  if (status)
  {
    this->Internal->Selection->EnableArray(name);
  }
  else
  {
    this->Internal->Selection->DisableArray(name);
  }
}

vtkStringArray* vtkNimbusOpenVDBReader::GetGridNames()
{
  return this->Internal->Names;
}

vtkNimbusOpenVDBReader::Internals::Plan vtkNimbusOpenVDBReader::Internals::MakePlan(
  const char* boundsGrid, const std::string& path) const
{
  const Internals& in = *this;
  Plan plan;
  std::vector<std::string> unsupported;
  std::set<std::string> taken;
  for (const auto& g : in.Grids)
  {
    if (!g.Supported())
    {
      unsupported.push_back(Quote(g.Name) + " (" + g.ValueType + ")");
      continue;
    }
    if (in.Selection->ArrayIsEnabled(g.Name.c_str()) && taken.insert(g.Name).second)
    {
      plan.Read.push_back(&g);
    }
  }
  if (taken.empty() && in.Names->GetNumberOfValues() == 0)
  {
    std::string found;
    for (const auto& u : unsupported)
    {
      found += (found.empty() ? "" : ", ") + u;
    }
    throw vdb::Error(Quote(path) + " has no float, double, Vec3s or Vec3d grid to read" +
      (found.empty() ? std::string(" (it has no grids)") : " (found: " + found + ")"));
  }
  if (plan.Read.empty())
  {
    throw vdb::Error("no grid selected (enable at least one in GridSelection)");
  }
  bool byGrid = boundsGrid && *boundsGrid;
  if (byGrid)
  {
    for (const auto& g : in.Grids)
    {
      if (g.Supported() && g.Name == boundsGrid)
      {
        plan.Reference = &g;
        break;
      }
    }
    byGrid = plan.Reference || std::string(boundsGrid) != "(union)";
  }
  if (byGrid)
  {
    if (!plan.Reference)
    {
      throw vdb::Error(
        "BoundsGrid " + Quote(boundsGrid) + " is not a float/double/Vec3 grid of " + Quote(path));
    }
    plan.Box = plan.Reference->ActiveBox;
    if (plan.Box.Empty())
    {
      throw vdb::Error("BoundsGrid " + Quote(boundsGrid) + " is empty (no active voxels)");
    }
    return plan;
  }
  // Reference: the first selected grid with active voxels (else the first selected).
  plan.Reference = plan.Read.front();
  for (const auto* g : plan.Read)
  {
    if (!g->ActiveBox.Empty())
    {
      plan.Reference = g;
      break;
    }
  }
  for (const auto* g : plan.Read)
  {
    plan.Box = plan.Box.Union(vdb::BoxInReference(*g, plan.Reference->Transform));
  }
  if (plan.Box.Empty())
  {
    std::string names;
    for (const auto* g : plan.Read)
    {
      names += (names.empty() ? "" : ", ") + Quote(g->Name);
    }
    throw vdb::Error("every selected grid is empty (no active voxels): " + names);
  }
  return plan;
}

namespace
{
void RowMajorDirection(const vdb::TransformInfo& t, double out[9])
{
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      out[3 * r + c] = t.Direction[3 * c + r];
    }
  }
}
}

int vtkNimbusOpenVDBReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("FileName is not set: give the .vdb file to read");
    return 0;
  }
  Internals::Plan plan;
  this->Internal->UpChosen = false;
  try
  {
    this->Internal->Refresh(this->FileName);
    plan = this->Internal->MakePlan(this->BoundsGrid, this->FileName);
  }
  catch (const vdb::Error& e)
  {
    vtkErrorMacro(<< e.what());
    return 0;
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< "cannot read the grids of " << this->FileName << ": " << e.what());
    return 0;
  }
  // The image in the up frame: its extent, origin, spacing and direction (the file's own
  // for +Z). Pieces are requested in this frame.
  const vdb::UpTurn turn(this->Internal->ChooseUp(this->UpAxis).Axis, plan.Reference->Transform);
  const vdb::TransformInfo t = turn.TurnTransform(plan.Reference->Transform);
  const vdb::IndexBox box = turn.TurnBox(plan.Box);
  int extent[6];
  for (int c = 0; c < 3; ++c)
  {
    extent[2 * c] = static_cast<int>(box.Min[c]);
    extent[2 * c + 1] = static_cast<int>(box.Max[c]);
  }
  double direction[9];
  RowMajorDirection(t, direction);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), t.Origin.data(), 3);
  outInfo->Set(vtkDataObject::SPACING(), t.Spacing.data(), 3);
  outInfo->Set(vtkDataObject::DIRECTION(), direction, 9);
  // Pieces (data parallel): RequestData produces the requested extent (UPDATE_EXTENT).
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

namespace
{
/// Bytes of one value of a grid as OpenVDB holds it in memory.
uint64_t ValueBytes(vdb::ValueKind kind)
{
  switch (kind)
  {
    case vdb::ValueKind::Float:
      return 4;
    case vdb::ValueKind::Double:
      return 8;
    case vdb::ValueKind::Vec3Float:
      return 12;
    case vdb::ValueKind::Vec3Double:
      return 24;
    default:
      return 0;
  }
}

bool LooksLikeDensity(const vdb::GridInfo& g)
{
  std::string lower = g.Name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return g.GridClass == "fog volume" || lower.find("density") != std::string::npos;
}
}

int vtkNimbusOpenVDBReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  if (!output)
  {
    vtkErrorMacro("no vtkImageData output");
    return 0;
  }
  output->Initialize();
  if (!this->FileName || !*this->FileName)
  {
    vtkErrorMacro("FileName is not set: give the .vdb file to read");
    return 0;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  Internals& internal = *this->Internal;
  internal.Piece =
    outInfo->Has(SDDP::UPDATE_PIECE_NUMBER()) ? outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()) : 0;
  internal.NumberOfPieces = outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES())
    ? outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES())
    : 1;
  internal.GhostLevels = outInfo->Has(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS())
    ? outInfo->Get(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS())
    : 0;
  internal.SplitMode = outInfo->Has(vtkExtentTranslator::UPDATE_SPLIT_MODE())
    ? outInfo->Get(vtkExtentTranslator::UPDATE_SPLIT_MODE())
    : vtkExtentTranslator::BLOCK_MODE;
  // No exception leaves the pipeline: OpenVDB, the standard library and VTK's allocations
  // all end here in an error and an empty output.
  try
  {
    if (this->ReadImage(output))
    {
      return 1;
    }
  }
  catch (const vdb::Error& e)
  {
    vtkErrorMacro(<< e.what());
  }
  catch (const std::bad_alloc& e)
  {
    vtkErrorMacro(<< "out of memory reading " << this->FileName << " (" << e.what()
                  << "); lower MemoryBudgetMiB or MaximumNumberOfVoxels, or select fewer grids");
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< "cannot read " << this->FileName << ": " << e.what());
  }
  output->Initialize();
  return 0;
}

namespace
{
void SetGeometry(vtkImageData* output, const vdb::TransformInfo& t)
{
  output->SetOrigin(t.Origin.data());
  output->SetSpacing(t.Spacing.data());
  double direction[9];
  RowMajorDirection(t, direction);
  output->SetDirectionMatrix(direction);
}

/// The field-data string array that says which axis was taken as up, and why.
void AddUpAxisSource(vtkImageData* output, const std::string& source)
{
  vtkNew<vtkStringArray> array;
  array->SetName(vtkNimbusOpenVDBReader::UpAxisSourceArrayName());
  array->InsertNextValue(source);
  output->GetFieldData()->AddArray(array);
}

/// The voxel limit and the memory budget, checked before anything is allocated. `turning`:
/// the voxels are re-indexed into the up frame, through a copy of the largest grid's array.
bool WithinLimits(vtkNimbusOpenVDBReader* self, const std::vector<const vdb::GridInfo*>& read,
  const vdb::IndexBox& box, bool turning)
{
  const char* fileName = self->GetFileName();
  const uint64_t voxels = box.VoxelCount();
  uint64_t components = 0;
  uint64_t workBytes = 0; // the largest grid's file bytes and tree, while it is read
  for (const auto* g : read)
  {
    components += static_cast<uint64_t>(g->Components);
    const uint64_t active = g->ActiveVoxelCount > 0 ? uint64_t(g->ActiveVoxelCount) : 0;
    uint64_t tree = 0;
    if (!nimbus::CheckedProduct({ active, ValueBytes(g->Kind) }, tree))
    {
      tree = UINT64_MAX / 2;
    }
    workBytes = std::max(workBytes, std::min(UINT64_MAX / 4, tree + uint64_t(g->FileBytes)));
    if (turning)
    {
      // The copy a grid's values are re-indexed from (after its tree is gone).
      workBytes = std::max(workBytes, voxels * uint64_t(g->Components) * 4);
    }
  }
  std::ostringstream dims;
  dims << (box.Max[0] - box.Min[0] + 1) << " x " << (box.Max[1] - box.Min[1] + 1) << " x "
       << (box.Max[2] - box.Min[2] + 1);
  uint64_t values = 0;
  const bool valuesFit =
    nimbus::CheckedProduct({ voxels, static_cast<uint64_t>(read.size()) }, values);
  const vtkIdType maximum = self->GetMaximumNumberOfVoxels();
  if (!valuesFit || values > static_cast<uint64_t>(maximum))
  {
    std::ostringstream values_text;
    if (valuesFit)
    {
      values_text << values;
    }
    else
    {
      values_text << "more than 2^64";
    }
    vtkErrorWithObjectMacro(
      self, << "refusing to read " << fileName << ": the image would have " << dims.str() << " = "
            << voxels << " points x " << read.size() << " grid(s) = " << values_text.str()
            << " voxels (" << nimbus::FormatBytes(double(voxels) * double(components) * 4.0)
            << "), more than MaximumNumberOfVoxels = " << maximum
            << " (all grids of the file together); raise MaximumNumberOfVoxels, select "
               "fewer grids or set BoundsGrid");
    return false;
  }
  const double budgetMiB = self->GetMemoryBudgetMiB() > 0.0 ? self->GetMemoryBudgetMiB()
                                                            : nimbus::DefaultMemoryBudgetMiB();
  const double outputBytes = double(voxels) * double(components) * 4.0;
  const std::string over = nimbus::OverBudgetMessage("reading " + std::string(fileName) + " (" +
      dims.str() + " points, " + std::to_string(components) +
      " float components in all, plus the largest grid while it is read)",
    outputBytes + double(workBytes), budgetMiB * 1024.0 * 1024.0);
  if (!over.empty())
  {
    vtkErrorWithObjectMacro(
      self, << over << "; raise MemoryBudgetMiB, select fewer grids or set BoundsGrid");
    return false;
  }
  return true;
}

/// Says what happened to transforms, names, empty grids and unsupported grids.
void WarnAboutGrids(vtkNimbusOpenVDBReader* self, const std::vector<vdb::GridInfo>& grids,
  const std::vector<const vdb::GridInfo*>& read, const vdb::GridInfo& reference,
  const std::string& transformNote)
{
  const char* fileName = self->GetFileName();
  if (!transformNote.empty())
  {
    vtkWarningWithObjectMacro(
      self, << "grid " << Quote(reference.Name) << " of " << fileName << ": " << transformNote);
  }
  std::string unsupported;
  std::map<std::string, std::vector<std::string>> repeated;
  for (const auto& g : grids)
  {
    if (!g.Supported())
    {
      unsupported += (unsupported.empty() ? "" : ", ") + Quote(g.Name) + " (" + g.ValueType + ")";
    }
    repeated[g.StoredName].push_back(Quote(g.Name));
  }
  if (!unsupported.empty())
  {
    vtkWarningWithObjectMacro(self, << "skipped grids of unsupported value type in " << fileName
                                    << ": " << unsupported
                                    << "; only float, double, Vec3s and Vec3d grids are read");
  }
  for (const auto& r : repeated)
  {
    if (r.second.size() > 1 || (r.first.empty() && !r.second.empty()))
    {
      std::string list;
      for (const auto& n : r.second)
      {
        list += (list.empty() ? "" : ", ") + n;
      }
      if (r.first.empty())
      {
        vtkWarningWithObjectMacro(self,
          << fileName << " has " << r.second.size() << " unnamed grid(s): listed as " << list);
      }
      else
      {
        vtkWarningWithObjectMacro(self, << fileName << " has " << r.second.size() << " grids named "
                                        << Quote(r.first) << ": all are listed, as " << list
                                        << " (OpenVDB's names for repeated grids, in file order)");
      }
    }
  }
  for (const auto* g : read)
  {
    if (g->ActiveBox.Empty())
    {
      vtkWarningWithObjectMacro(
        self, << "grid " << Quote(g->Name)
              << " has no active voxels: its array holds the grid's background value");
    }
  }
}

/// Values that are no density: said, with counts (they are read as they are).
void WarnAboutValues(vtkNimbusOpenVDBReader* self,
  const std::vector<vtkSmartPointer<vtkFloatArray>>& arrays,
  const std::vector<const vdb::GridInfo*>& read)
{
  for (size_t i = 0; i < arrays.size(); ++i)
  {
    nimbus::ValueCensus census = nimbus::TakeCensus(
      arrays[i]->GetPointer(0), static_cast<std::size_t>(arrays[i]->GetNumberOfValues()));
    const bool densityLike = arrays[i]->GetNumberOfComponents() == 1 && LooksLikeDensity(*read[i]);
    if (!densityLike)
    {
      census.Negative = 0;
    }
    if (!census.AllFiniteNonNegative())
    {
      vtkWarningWithObjectMacro(
        self, << "grid " << Quote(read[i]->Name) << " of " << self->GetFileName() << " has "
              << nimbus::DescribeCensus(census) << " (of " << arrays[i]->GetNumberOfValues() << ")"
              << (census.Negative ? "; negative values are no density" : "")
              << ": they are read as they are; clean them before rendering");
    }
  }
}

/// The arrays read over the file's box `box`, turned into the up frame in place (through a
/// copy of one array at a time when the voxels are re-indexed).
void TurnArrays(const vdb::UpTurn& turn, const vdb::IndexBox& box,
  const std::vector<vtkSmartPointer<vtkFloatArray>>& arrays)
{
  if (turn.Identity())
  {
    return;
  }
  std::vector<float> copy;
  for (const auto& array : arrays)
  {
    float* values = array->GetPointer(0);
    const int components = array->GetNumberOfComponents();
    if (turn.Reindexes())
    {
      copy.assign(values, values + array->GetNumberOfValues());
      turn.TurnValues(box, copy.data(), components, values);
    }
    else
    {
      turn.TurnValues(box, values, components, values);
    }
  }
}
}

int vtkNimbusOpenVDBReader::ReadImage(vtkImageData* output)
{
  Internals& internal = *this->Internal;
  internal.Refresh(this->FileName);
  const Internals::Plan plan = internal.MakePlan(this->BoundsGrid, this->FileName);
  // The image is the file's, turned into the up frame (nothing changes for +Z). Pieces are
  // pieces of the turned image: only the piece's part of the plan's box is read into the
  // image (each voxel's value does not depend on the box, so a piece equals the whole image's
  // crop bit for bit). ReadDense reads only the leaves that touch the box (clipped reads).
  const vdb::UpAxisChoice& up = internal.ChooseUp(this->UpAxis);
  const vdb::UpTurn turn(up.Axis, plan.Reference->Transform);
  const vdb::IndexBox turnedBox = internal.PieceBox(turn.TurnBox(plan.Box));
  const vdb::IndexBox box = turn.FileBox(turnedBox); // the file's index box to read
  const vdb::TransformInfo turned = turn.TurnTransform(plan.Reference->Transform);
  if (box.Empty() && !plan.Box.Empty())
  {
    // A piece with no point of the image (more pieces than points): an empty image.
    SetGeometry(output, turned);
    AddUpAxisSource(output, up.Source);
    return 1;
  }

  // Refuse absurd reads before allocating anything: the voxel limit counts every selected
  // grid's values (points x grids), the memory budget every byte of the read.
  if (!WithinLimits(this, plan.Read, box, turn.Reindexes()))
  {
    return 0;
  }
  WarnAboutGrids(this, internal.Grids, plan.Read, *plan.Reference, turned.Note);
  if (!up.Warning.empty())
  {
    vtkWarningMacro(<< this->FileName << ": " << up.Warning);
  }

  int extent[6];
  for (int c = 0; c < 3; ++c)
  {
    extent[2 * c] = static_cast<int>(turnedBox.Min[c]);
    extent[2 * c + 1] = static_cast<int>(turnedBox.Max[c]);
  }
  output->SetExtent(extent);
  SetGeometry(output, turned);

  const uint64_t voxels = box.VoxelCount();
  std::vector<std::string> names;
  std::vector<float*> targets;
  std::vector<vtkSmartPointer<vtkFloatArray>> arrays;
  for (const auto* g : plan.Read)
  {
    auto array = vtkSmartPointer<vtkFloatArray>::New();
    array->SetName(g->Name.c_str());
    array->SetNumberOfComponents(g->Components);
    // Within the budget (checked above), so VTK's allocation (which aborts on failure in
    // this VTK) is not asked for more than the budget allows.
    array->SetNumberOfTuples(static_cast<vtkIdType>(voxels)); // ReadDense sets every value
    names.push_back(g->Name);
    targets.push_back(array->GetPointer(0));
    arrays.push_back(array);
  }
  std::vector<std::string> resampled;
  vdb::TransformInfo exact = plan.Reference->Transform;
  vdb::ReadDense(
    this->FileName, names, plan.Reference->Transform, box, targets, &resampled,
    [this](double f) { this->UpdateProgress(f); }, &exact);
  TurnArrays(turn, box, arrays);
  // The transform read with the voxels (bit-exact; see ReadDense), turned.
  SetGeometry(output, turn.TurnTransform(exact));
  for (const auto& name : resampled)
  {
    vtkWarningMacro(<< "grid " << Quote(name)
                    << " has a different transform from the reference grid "
                    << Quote(plan.Reference->Name)
                    << ": resampled trilinearly at the image points (values are interpolated; "
                       "read it alone, or set BoundsGrid to it, for its own voxels)");
  }
  WarnAboutValues(this, arrays, plan.Read);
  for (size_t i = 0; i < arrays.size(); ++i)
  {
    output->GetPointData()->AddArray(arrays[i]);
    if (i == 0)
    {
      if (arrays[i]->GetNumberOfComponents() == 1)
      {
        output->GetPointData()->SetActiveScalars(arrays[i]->GetName());
      }
    }
    if (arrays[i]->GetNumberOfComponents() == 3 && !output->GetPointData()->GetVectors())
    {
      output->GetPointData()->SetActiveVectors(arrays[i]->GetName());
    }
  }
  AddUpAxisSource(output, up.Source);
  return 1;
}

int vtkNimbusOpenVDBReader::GetResolvedUpAxis()
{
  return this->Internal->UpChosen ? static_cast<int>(this->Internal->UpChoice.Axis)
                                  : static_cast<int>(nimbus::UpAxis::PositiveZ);
}

const char* vtkNimbusOpenVDBReader::GetResolvedUpAxisSource()
{
  return this->Internal->UpChosen ? this->Internal->UpChoice.Source.c_str() : "";
}

void vtkNimbusOpenVDBReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "BoundsGrid: " << (this->BoundsGrid ? this->BoundsGrid : "(union)") << "\n";
  os << indent << "MaximumNumberOfVoxels: " << this->MaximumNumberOfVoxels << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
  os << indent << "UpAxis: " << this->UpAxis
     << (this->UpAxis == nimbus::vdb::AutoUpAxis ? " (Auto)" : "") << "\n";
  os << indent << "ResolvedUpAxis: "
     << (this->Internal->UpChosen ? this->Internal->UpChoice.Source : "(not read yet)") << "\n";
  os << indent << "Grids:";
  for (int i = 0; i < this->Internal->Selection->GetNumberOfArrays(); ++i)
  {
    os << " " << this->Internal->Selection->GetArrayName(i)
       << (this->Internal->Selection->GetArraySetting(i) ? "(on)" : "(off)");
  }
  os << "\n";
}
