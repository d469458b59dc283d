/**
 * @class   vtkNimbusOpenVDBWriter
 * @brief   Writes the point (and cell) arrays of a vtkImageData as OpenVDB (.vdb) grids.
 *
 * The reverse of vtkNimbusOpenVDBReader. Each named 1-component numeric array becomes a
 * FloatGrid and each 3-component array a Vec3SGrid named after the array (non-float arrays
 * are converted to float; other component counts, non-numeric and unnamed arrays are
 * skipped with a warning). Image point (i, j, k) of the extent is VDB voxel (i, j, k); the
 * grid transform maps it to the image's world position (origin, spacing and direction
 * matrix). Cell arrays (when WriteCellData is on) are grids whose voxel (i, j, k) is cell
 * (i, j, k), so their transform is shifted by half a voxel; a cell array whose name is also
 * a written point array's becomes "<name>_cells", or "<name>_cells_2", "_cells_3"... the
 * first name no array of the image has (warned).
 *
 * Voxels whose value differs from Background by at most Tolerance (per component) are
 * inactive and not stored: Tolerance 0 keeps every voxel that is not exactly the
 * background. Scalar grids whose values are all >= 0 with Background 0 are tagged as fog
 * volumes (OpenVDB's class for density). Arrays with NaN or infinite values, and a
 * non-finite Background, are refused with an error (nothing is written).
 *
 * Safe replacement: the file is serialised in memory, written to "<target>.tmp-<pid>"
 * beside the target with every write checked, fsync'ed, given the old file's permission
 * bits and renamed over the target; any failure (full disk, file-size limit, ...) leaves an
 * existing file byte for byte and the error names the cause. A read-only target (no write
 * permission bit, or not writable by this user) is refused, as vtkXMLWriter refuses it,
 * also for root. Through a symbolic link the link's target file is replaced (the link
 * stays). A target with other hard links is replaced under this name only (the other names
 * keep the old content; warned). Errors set the error code (OutOfDiskSpaceError for a full
 * disk or a file-size limit, else the system's errno as vtkXMLWriter does, else
 * UnknownError) and Write() returns 0.
 */
#ifndef vtkNimbusOpenVDBWriter_h
#define vtkNimbusOpenVDBWriter_h

#include "NimbusIOOpenVDBModule.h" // export macro
#include "vtkWriter.h"

#include <vector> // for std::vector

class vtkImageData;
namespace nimbus
{
namespace vdb
{
struct FieldToWrite;
}
}

class NIMBUSIOOPENVDB_EXPORT vtkNimbusOpenVDBWriter : public vtkWriter
{
public:
  static vtkNimbusOpenVDBWriter* New();
  vtkTypeMacro(vtkNimbusOpenVDBWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The .vdb file to write.
  vtkSetFilePathMacro(FileName);
  vtkGetFilePathMacro(FileName);
  ///@}

  ///@{
  /// Voxels within this distance of Background (per component, in the array's units) are
  /// inactive and not stored. Default 0 (only exact background values are dropped).
  virtual void SetTolerance(double value);
  virtual double GetToleranceMinValue() { return 0.0; }
  virtual double GetToleranceMaxValue() { return VTK_FLOAT_MAX; }
  vtkGetMacro(Tolerance, double);
  ///@}

  ///@{
  /// The grids' background (the value of inactive voxels; every component for Vec3 grids).
  /// Default 0.
  vtkSetMacro(Background, double);
  vtkGetMacro(Background, double);
  ///@}

  ///@{
  /// Also write cell arrays (default on).
  vtkSetMacro(WriteCellData, bool);
  vtkGetMacro(WriteCellData, bool);
  vtkBooleanMacro(WriteCellData, bool);
  ///@}

  ///@{
  /// Blosc compression (default on); off writes uncompressed voxel values (faster to
  /// write and read, larger files).
  vtkSetMacro(Compress, bool);
  vtkGetMacro(Compress, bool);
  vtkBooleanMacro(Compress, bool);
  ///@}

  /// Active voxels in the last file written (all grids together).
  vtkGetMacro(NumberOfActiveVoxels, vtkIdType);

  vtkImageData* GetInput();

protected:
  vtkNimbusOpenVDBWriter();
  ~vtkNimbusOpenVDBWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  void WriteData() override;

  char* FileName = nullptr;
  double Tolerance = 0.0;
  double Background = 0.0;
  bool WriteCellData = true;
  bool Compress = true;
  vtkIdType NumberOfActiveVoxels = 0;

private:
  vtkNimbusOpenVDBWriter(const vtkNimbusOpenVDBWriter&) = delete;
  void operator=(const vtkNimbusOpenVDBWriter&) = delete;

  // WriteData's last step: the grids to FileName, errors to ErrorCode.
  void WriteFields(const std::vector<nimbus::vdb::FieldToWrite>& fields);
};

#endif
