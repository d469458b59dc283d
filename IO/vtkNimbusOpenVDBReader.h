/**
 * @class   vtkNimbusOpenVDBReader
 * @brief   Reads the float, double and Vec3 grids of an OpenVDB (.vdb) file into one
 *          vtkImageData.
 *
 * Every selected grid becomes a point-data array of one vtkImageData: float and double
 * grids a 1-component float array, Vec3s/Vec3d grids a 3-component float array (e.g.
 * velocity), named after the grid. The image covers the union of the selected grids'
 * active-voxel bounding boxes, or the box of the grid named by BoundsGrid. VDB voxel
 * (i, j, k) is image point (i, j, k): the extent is the VDB index box, the origin is the
 * world position of index (0, 0, 0) and the spacing the voxel size. Points outside a grid's
 * active voxels get the grid's own (inactive) value — its background for fog volumes.
 *
 * The reference grid (BoundsGrid, or the first selected non-empty grid in the order OpenVDB
 * lists them, which is by name) gives the
 * transform; a grid with another transform is resampled trilinearly at the image points
 * (warned). Rotated transforms become the image's direction matrix; non-uniform voxel
 * sizes its per-axis spacing; sheared or non-linear (frustum) transforms are approximated
 * — each case raises a warning that says what was done (docs/openvdb.md).
 *
 * Grids of other types (bool, int32, int64, string, points, ...) are listed in a warning
 * and skipped. Images with more than MaximumNumberOfVoxels points are refused before any
 * memory is allocated. Grid names and extents are known after UpdateInformation() without
 * reading voxels (from the file's bounding-box metadata).
 */
#ifndef vtkNimbusOpenVDBReader_h
#define vtkNimbusOpenVDBReader_h

#include "NimbusIOOpenVDBModule.h" // export macro
#include "vtkImageAlgorithm.h"

#include <memory> // for std::unique_ptr

class vtkDataArraySelection;
class vtkStringArray;

class NIMBUSIOOPENVDB_EXPORT vtkNimbusOpenVDBReader : public vtkImageAlgorithm
{
public:
  static vtkNimbusOpenVDBReader* New();
  vtkTypeMacro(vtkNimbusOpenVDBReader, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The .vdb file to read.
  vtkSetFilePathMacro(FileName);
  vtkGetFilePathMacro(FileName);
  ///@}

  /// 1 when the file starts with OpenVDB's magic number (ParaView's reader factory asks).
  static int CanReadFile(const char* fileName);

  ///@{
  /// Which grids to read (all supported grids are enabled when a file is first opened).
  /// Only float, double, Vec3s and Vec3d grids are listed.
  vtkDataArraySelection* GetGridSelection();
  int GetNumberOfGridArrays();
  const char* GetGridArrayName(int index);
  int GetGridArrayStatus(const char* name);
  void SetGridArrayStatus(const char* name, int status);
  ///@}

  /// Names of the supported grids of the file (after UpdateInformation()).
  vtkStringArray* GetGridNames();

  ///@{
  /// When set to a grid's name, the image covers that grid's active bounding box and that
  /// grid's transform is the reference; empty (default) or "(union)" (ParaView's drop-down
  /// entry), unless a grid has that name: the union of the selected grids.
  vtkSetStringMacro(BoundsGrid);
  vtkGetStringMacro(BoundsGrid);
  ///@}

  ///@{
  /// Largest number of image points read; a larger image is refused with an error before
  /// allocating (memory is 4 bytes x components x points per grid). Default 512^3.
  vtkSetClampMacro(MaximumNumberOfVoxels, vtkIdType, 1, VTK_ID_MAX);
  vtkGetMacro(MaximumNumberOfVoxels, vtkIdType);
  ///@}

protected:
  vtkNimbusOpenVDBReader();
  ~vtkNimbusOpenVDBReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;
  char* BoundsGrid = nullptr;
  vtkIdType MaximumNumberOfVoxels = vtkIdType(512) * 512 * 512;

private:
  vtkNimbusOpenVDBReader(const vtkNimbusOpenVDBReader&) = delete;
  void operator=(const vtkNimbusOpenVDBReader&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
