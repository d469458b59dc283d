// Setters of the physical numbers of every Nimbus VTK class that refuse NaN and
// infinity, and AllFinite (Nimbus::Common; included by .cxx files only).
//
// The one rule for a non-finite value given to a setter: it is refused at once, with a
// vtkErrorMacro that names the property and the value, and the previous value is kept
// (so the object stays valid and the next RequestData runs with what it had). Values
// with no clamp range (bounds, vectors, lengths checked against each other) are still
// checked by the class's RequestData with the rest of their range.
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

namespace nimbus
{
/// Whether all `count` values are finite (no NaN, no infinity).
inline bool AllFinite(const double* values, int count)
{
  return std::all_of(values, values + count, [](double v) { return std::isfinite(v); });
}
}

#endif
