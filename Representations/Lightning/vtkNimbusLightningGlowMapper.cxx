#include "vtkNimbusLightningGlowMapper.h"

#include "Lightning.h"

#include "vtkDataArray.h"
#include "vtkLookupTable.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkNimbusLightningGlowMapper);

vtkNimbusLightningGlowMapper::vtkNimbusLightningGlowMapper()
{
  this->EmissiveOn();
  this->ScalarVisibilityOn();
  this->SetScalarModeToUsePointFieldData();
  this->SelectColorArray("intensity");
  this->SetLookupTable(this->Colors);
  this->UseLookupTableScalarRangeOn();
  this->SetScaleArray(nullptr);
  this->SetOpacityArray(nullptr);
}

vtkNimbusLightningGlowMapper::~vtkNimbusLightningGlowMapper() = default;

void vtkNimbusLightningGlowMapper::Render(vtkRenderer* renderer, vtkActor* actor)
{
  vtkPolyData* input = this->GetInput();
  vtkDataArray* intensity = input ? input->GetPointData()->GetArray("intensity") : nullptr;
  if (!intensity || input->GetNumberOfPoints() == 0)
  {
    return; // no sources (before the flash): no glow
  }
  double range[2];
  intensity->GetRange(range, 0);
  const double brightest = range[1];
  if (!(brightest > 0.0) || !std::isfinite(brightest))
  {
    return;
  }
  // The colours: the point's intensity over the brightest one's, times the colour (the
  // table is linear in intensity; its absolute scale is in the shader's gain).
  this->Colors->SetNumberOfTableValues(256);
  this->Colors->SetTableRange(0.0, brightest);
  for (int i = 0; i < 256; ++i)
  {
    const double f = i / 255.0;
    this->Colors->SetTableValue(i, f * std::clamp(this->Color[0], 0.0, 1.0),
      f * std::clamp(this->Color[1], 0.0, 1.0), f * std::clamp(this->Color[2], 0.0, 1.0), 1.0);
  }
  const double radius = this->GlowRadiusMetres;
  this->SetScaleFactor(radius / this->MetresPerUnit);
  // L(b) = sigma_s I / (4 b) (Physics/Lightning.h) with b = (the splat's offset) x R: the
  // gain at offset 1 for the brightest source, the offset floored at the channel's radius.
  const double gain =
    nimbus::LightningGlowRadiance(this->AirScatteringPerMetre, brightest, radius) * this->Exposure;
  const double floor = std::min(1.0, this->ChannelRadiusMetres / radius);
  std::ostringstream code;
  code.precision(9);
  code << "//VTK::Color::Impl\n"
          "  float b = length(offsetVCVSOutput.xy);\n"
          "  if (b > 1.0) { discard; }\n"
          "  float fade = (1.0 - b * b) * (1.0 - b * b);\n"
          "  float glow = "
       << gain << " / max(b, " << floor
       << ") * fade;\n"
          "  diffuseColor *= glow;\n"
          "  ambientColor *= glow;\n";
  if (code.str() != this->LastShaderCode)
  {
    this->LastShaderCode = code.str();
    this->SetSplatShaderCode(this->LastShaderCode.c_str());
  }
  this->Superclass::Render(renderer, actor);
}

void vtkNimbusLightningGlowMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "AirScatteringPerMetre: " << this->AirScatteringPerMetre << " /m\n";
  os << indent << "GlowRadiusMetres: " << this->GlowRadiusMetres << "\n";
  os << indent << "ChannelRadiusMetres: " << this->ChannelRadiusMetres << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "Color: " << this->Color[0] << ", " << this->Color[1] << ", " << this->Color[2]
     << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
}
