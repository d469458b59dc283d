/**
 * @class   vtkNimbusSceneDensitySource
 * @brief   The density volume a Nimbus scene file describes, as vtkImageData.
 *
 * Reads the scene (JSON, docs/scene-format.md) and produces its medium's density
 * (or, with Medium = i >= 1, that of the scene's additional medium media[i - 1]):
 * either the point-data array of a .vti file or the output of
 * vtkNimbusMetaballCloudSource with the scene's parameters. The output's active
 * scalars are a float array named "density". Every Nimbus renderer (and the trade
 * harness) takes the density from here, so they all see the same volume.
 *
 * The output keeps the volume's direction matrix (a rotated .vti stays rotated;
 * the reference renderer refuses it rather than ignore it). The volume's size
 * (from its whole extent) is checked against MemoryBudgetMiB before it is made;
 * NaN, infinite or negative densities are reported as a warning with their
 * count. No exception leaves the algorithm (errors: vtkErrorMacro, empty output).
 */
#ifndef vtkNimbusSceneDensitySource_h
#define vtkNimbusSceneDensitySource_h

#include "NimbusReferenceModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include "vtkSmartPointer.h" // for the inner algorithm

#include <string> // for std::string

class NIMBUSREFERENCE_EXPORT vtkNimbusSceneDensitySource : public vtkImageAlgorithm
{
public:
  static vtkNimbusSceneDensitySource* New();
  vtkTypeMacro(vtkNimbusSceneDensitySource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The scene file (JSON).
  vtkSetStdStringFromCharMacro(SceneFileName);
  vtkGetCharFromStdStringMacro(SceneFileName);
  ///@}

  ///@{
  /// Which medium's density: 0 (default) the scene's `medium`, i >= 1 its additional
  /// medium `media[i - 1]` (scene format version 3). A medium the scene does not have is
  /// an error naming how many it has.
  vtkSetClampMacro(Medium, int, 0, 64);
  vtkGetMacro(Medium, int);
  ///@}

  ///@{
  /// Memory the volume may take, MiB: the grid's points times 12 bytes (the inner
  /// source's or reader's array, up to 8 bytes a value, and the float copy).
  /// Default nimbus::DefaultMemoryBudgetMiB(); <= 0: that default.
  vtkSetMacro(MemoryBudgetMiB, double);
  vtkGetMacro(MemoryBudgetMiB, double);
  ///@}

protected:
  vtkNimbusSceneDensitySource();
  ~vtkNimbusSceneDensitySource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  // The work of RequestInformation and RequestData; they may throw.
  int SetUpInner(vtkInformation*, vtkInformationVector**, vtkInformationVector*);
  int MakeVolume(vtkImageData* output);

  std::string SceneFileName;
  double MemoryBudgetMiB;
  int Medium = 0;

private:
  // The reader or metaball source the scene asks for, set up by RequestInformation.
  vtkSmartPointer<vtkAlgorithm> Inner;
  std::string InnerArrayName;

  vtkNimbusSceneDensitySource(const vtkNimbusSceneDensitySource&) = delete;
  void operator=(const vtkNimbusSceneDensitySource&) = delete;
};

#endif
