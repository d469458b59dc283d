/**
 * @class   vtkNimbusSceneDensitySource
 * @brief   The density volume a Nimbus scene file describes, as vtkImageData.
 *
 * Reads the scene (JSON, docs/scene-format.md) and produces its medium's density:
 * either the point-data array of a .vti file or the output of
 * vtkNimbusMetaballCloudSource with the scene's parameters. The output's active
 * scalars are a float array named "density". Every Nimbus renderer (and the trade
 * harness) takes the density from here, so they all see the same volume.
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

protected:
  vtkNimbusSceneDensitySource();
  ~vtkNimbusSceneDensitySource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  std::string SceneFileName;

private:
  // The reader or metaball source the scene asks for, set up by RequestInformation.
  vtkSmartPointer<vtkAlgorithm> Inner;
  std::string InnerArrayName;

  vtkNimbusSceneDensitySource(const vtkNimbusSceneDensitySource&) = delete;
  void operator=(const vtkNimbusSceneDensitySource&) = delete;
};

#endif
