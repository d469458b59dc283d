"""Every Nimbus VTK class follows one rule for setters with a range (docs/bad-input.md):
NaN and infinity are refused at once with an error naming the property, the previous
value is kept, and finite values are clamped to the range.

    PYTHONPATH=build/lib/python3.11/site-packages /usr/bin/python3 TestFiniteSetters.py

Finds every class of the `nimbus` package and every property with a range (a
Get<Name>MinValue method, which both Nimbus's finite setters and VTK's vtkSetClampMacro
make; the latter stores NaN, so any left fails here), sets NaN, +inf and -inf, and checks
the value stayed and an error was reported; then a value beyond each end is clamped.
"""
import math
import sys

import nimbus
from vtkmodules.vtkCommonCore import vtkCommand, vtkObject


class Errors:
    """Counts the errors an object reports (its ErrorEvent; observed, they are not printed)."""

    def __init__(self):
        self.count = 0

    def __call__(self, caller, event):
        self.count += 1


def ranged_properties(instance):
    """The properties with a range that the Nimbus class declares (not its VTK base's)."""
    vtk_base = next(base for base in type(instance).__mro__
                    if not base.__name__.startswith("vtkNimbus"))
    names = []
    for attribute in dir(instance):
        if hasattr(vtk_base, attribute):
            continue
        if attribute.startswith("Get") and attribute.endswith("MinValue"):
            name = attribute[3:-len("MinValue")]
            if hasattr(instance, "Set" + name) and hasattr(instance, "Get" + name):
                names.append(name)
    return names


def main():
    errors = Errors()
    failures, checked = [], 0
    classes = sorted(name for name in dir(nimbus) if name.startswith("vtkNimbus"))
    for class_name in classes:
        cls = getattr(nimbus, class_name)
        if not isinstance(cls, type) or not issubclass(cls, vtkObject):
            continue
        try:
            instance = cls()
        except TypeError:
            continue  # abstract
        instance.AddObserver(vtkCommand.ErrorEvent, errors)
        for name in ranged_properties(instance):
            get, set_ = getattr(instance, "Get" + name), getattr(instance, "Set" + name)
            low = getattr(instance, "Get%sMinValue" % name)()
            high = getattr(instance, "Get%sMaxValue" % name)()
            if isinstance(get(), int) and isinstance(low, int):
                continue  # integers cannot be NaN
            before = get()
            for bad in (math.nan, math.inf, -math.inf):
                reported = errors.count
                set_(bad)
                after = get()
                if not (after == before or (math.isnan(after) and math.isnan(before))):
                    failures.append("%s.Set%s(%r) changed it to %r" % (class_name, name, bad, after))
                if errors.count == reported:
                    failures.append("%s.Set%s(%r) reported no error" % (class_name, name, bad))
            span = abs(high - low) if math.isfinite(high - low) else 1.0
            for value, expected in ((low - max(span, 1.0), low), (high + max(span, 1.0), high)):
                if not math.isfinite(value):
                    continue
                set_(value)
                if get() != expected:
                    failures.append("%s.Set%s(%r) gave %r, not %r"
                                    % (class_name, name, value, get(), expected))
            set_(before)
            checked += 1
    print("%d properties with a range in %d classes checked" % (checked, len(classes)))
    for failure in failures:
        print("FAILED:", failure)
    if checked < 20:
        failures.append("only %d properties found: the search is broken" % checked)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
