// Setters of the mapper's and the sky's physical numbers that refuse NaN and
// infinity (private to Nimbus::Representations; included by .cxx files only).
//
// vtkSetClampMacro lets NaN through (every comparison with NaN is false) and turns
// +-infinity into the end of the range, a value nobody asked for; vtkSetMacro takes
// anything. These definitions refuse a non-finite value with an error that names
// the property and the value it keeps, and clamp finite values like
// vtkSetClampMacro. The declarations stay plain `virtual void SetX(double)` in the
// class headers, so that VTK's wrappers (Python, ParaView's client-server) see them.
#ifndef nimbus_FiniteSetters_h
#define nimbus_FiniteSetters_h

#include <algorithm>
#include <cmath>

/// Defines `void cls::Set<name>(double)`: refuses non-finite values (error, value
/// kept), clamps finite ones to [Get<name>MinValue(), Get<name>MaxValue()] (declared
/// in the class, as vtkSetClampMacro does).
#define nimbusDefineFiniteSetter(cls, name)                                                        \
  void cls::Set##name(double value)                                                                \
  {                                                                                                \
    if (!std::isfinite(value))                                                                     \
    {                                                                                              \
      vtkErrorMacro("Set" #name "(" << value << "): not a finite number; " #name " stays "         \
                                    << this->name << ".");                                         \
      return;                                                                                      \
    }                                                                                              \
    const double clamped =                                                                         \
      std::clamp(value, this->Get##name##MinValue(), this->Get##name##MaxValue());                 \
    if (this->name != clamped)                                                                     \
    {                                                                                              \
      this->name = clamped;                                                                        \
      this->Modified();                                                                            \
    }                                                                                              \
  }

#endif
