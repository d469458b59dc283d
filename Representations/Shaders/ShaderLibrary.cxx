#include "ShaderLibrary.h"

#include "nimbusAtmosphere.h"
#include "nimbusColor.h"
#include "nimbusPhase.h"
#include "nimbusSkyView.h"

namespace nimbus
{
namespace
{
void Replace(std::string& text, const std::string& tag, const std::string& replacement)
{
  for (std::size_t at = text.find(tag); at != std::string::npos;
       at = text.find(tag, at + replacement.size()))
  {
    text.replace(at, tag.size(), replacement);
  }
}
} // namespace

std::string ShaderLibrarySource()
{
  return std::string(nimbusPhase) + "\n" + nimbusColor + "\n" + nimbusAtmosphere + "\n";
}

std::string WithShaderLibrary(const std::string& source)
{
  std::string result = source;
  Replace(result, "//NIMBUS::Library", ShaderLibrarySource());
  Replace(result, "//NIMBUS::SkyView", nimbusSkyView);
  return result;
}
} // namespace nimbus
