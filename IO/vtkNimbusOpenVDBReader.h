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
 * and skipped. Grid names and extents are known after UpdateInformation() without
 * reading voxels (from the file's bounding-box metadata).
 *
 * Pieces (data parallel): for piece p of n (UPDATE_PIECE_NUMBER, UPDATE_NUMBER_OF_PIECES,
 * UPDATE_NUMBER_OF_GHOST_LEVELS) the output is VTK's block of the image for that piece grown
 * by the ghost levels (the executive's UPDATE_EXTENT, computed from this file's box so that a
 * file series whose boxes differ stays right), bit-identical to the same points of the whole
 * image; only that part is read: OpenVDB reads each selected grid's topology (its node masks)
 * and only the voxel buffers of the leaves that touch the piece (a clipped read; a resampled
 * grid's box grown by 2 voxels), seeking over the others in the file, and the limits below
 * count the piece's points. Whole grids are still read for files older than OpenVDB's grid
 * instancing and for non-linear (frustum) transforms. A one-piece request gets the whole
 * image, as before.
 *
 * Up axis: the output is in Nimbus's z-up frame (x east, y north, z up). UpAxis says which
 * axis of the file points up: -1 Auto (default: the file's metadata "up_axis" if it has one,
 * else +Y when its "creator" names Houdini, else +Z), 0 +X, 1 +Y, 2 +Z, 3 -Y. The data is
 * turned by the rotation R of Physics/UpAxis.h (U = R W): an axis-aligned image is re-indexed
 * into an axis-aligned image (a y-up Houdini file of extent [0,9]x[0,19]x[0,4] becomes one of
 * [0,9]x[-4,0]x[0,19], origin (ox, -oz, oy), spacing (sx, sz, sy)); a rotated one gets the
 * direction R D and origin R o. 3-component grids (velocities) are rotated, v -> R v. +Z is
 * the file as it is, bit for bit. Pieces are pieces of the turned image. What was decided is
 * GetResolvedUpAxis(), GetResolvedUpAxisSource() and the output's field-data string array
 * "nimbus_up_axis_source" ("+Y (creator 'Houdini 20.5.278/GEO_VDBTranslator')"). See
 * docs/openvdb.md, "Which way is up".
 *
 * Bad input ends in an error and an empty output, never in a crash or garbage: the file's
 * layout is checked before OpenVDB reads it (a truncated file is reported with the byte
 * where it ends and the byte a grid needs), each grid is read from its own bytes only,
 * the image is refused before any allocation when it has more than MaximumNumberOfVoxels
 * values (points x selected grids, all grids of the file together) or needs more memory
 * than MemoryBudgetMiB, and no exception leaves RequestData. NaN and infinite values (and
 * negative values in fog volumes and grids named like density) are read as they are and
 * counted in a warning. Grids that share a name are all listed, the repeats with OpenVDB's
 * own suffix: "density", "density[1]" (warned). See docs/openvdb.md.
 */
#ifndef vtkNimbusOpenVDBReader_h
#define vtkNimbusOpenVDBReader_h

#include "NimbusIOOpenVDBModule.h" // export macro
#include "vtkImageAlgorithm.h"

#include <memory> // for std::unique_ptr

class vtkDataArraySelection;
class vtkImageData;
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
  /// Largest number of voxels read from one file: image points x selected grids (all
  /// grids together, so eight grids of 512^3 count 8 x 512^3). A larger read is refused
  /// with an error before allocating. Default 512^3.
  vtkSetClampMacro(MaximumNumberOfVoxels, vtkIdType, 1, VTK_ID_MAX);
  vtkGetMacro(MaximumNumberOfVoxels, vtkIdType);
  ///@}

  ///@{
  /// Memory budget of one read in MiB: the output arrays (4 bytes x components x points,
  /// all grids) plus the largest grid's file bytes and tree, estimated before anything is
  /// allocated; a read over it is refused with an error. Default (and any value <= 0):
  /// nimbus::DefaultMemoryBudgetMiB(), half the physical memory, at most 3/4 of the
  /// address-space limit.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  ///@}

  ///@{
  /// Which axis of the file points up (Physics/UpAxis.h): -1 Auto (default), 0 +X, 1 +Y,
  /// 2 +Z, 3 -Y. The output is turned so that this axis becomes +z.
  vtkSetClampMacro(UpAxis, int, -1, 3);
  vtkGetMacro(UpAxis, int);
  ///@}

  /// The up axis used for the file (0 +X, 1 +Y, 2 +Z, 3 -Y), after UpdateInformation().
  int GetResolvedUpAxis();
  /// Why, in words: "+Y (file metadata up_axis = 'y')", "+Y (creator 'Houdini ...')",
  /// "+Z (default)", "+X (chosen)"; empty before UpdateInformation() or when the file could
  /// not be read. The
  /// output carries the same text as the field-data string array "nimbus_up_axis_source".
  const char* GetResolvedUpAxisSource();

  /// Name of the output's field-data string array that says which axis was taken as up.
  static const char* UpAxisSourceArrayName() { return "nimbus_up_axis_source"; }

protected:
  vtkNimbusOpenVDBReader();
  ~vtkNimbusOpenVDBReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  /// The read itself; may throw (RequestData catches everything).
  int ReadImage(vtkImageData* output);

  char* FileName = nullptr;
  char* BoundsGrid = nullptr;
  vtkIdType MaximumNumberOfVoxels = vtkIdType(512) * 512 * 512;
  double MemoryBudgetMiB;
  int UpAxis = -1;

private:
  vtkNimbusOpenVDBReader(const vtkNimbusOpenVDBReader&) = delete;
  void operator=(const vtkNimbusOpenVDBReader&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
