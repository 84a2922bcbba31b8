"""Lengths and feeds as the user's FreeCAD unit schema shows them (Edit > Preferences > General > Units), with
enough decimals for micrometres; used by the task panel, its summary and notes, the gear's precise outputs and
every error message (plain Python: `units` is `FreeCAD.Units`, or None for the job file's mm and mm/min).

FreeCAD's own texts (Quantity.UserString, the property editor, Gui::QuantitySpinBox) use the user's global
"Number of decimals" (2 by default: 0.01 mm, or 0.01 in = 0.25 mm under an imperial schema). The user's
setting stays as it is: a text here asks FreeCAD for the schema's unit (`getUserPreferred`) and picks its own
decimals from a resolution in mm, and a spin box gets a Quantity whose `Format` carries that precision (0.20's
QuantitySpinBox shows a Quantity with its own format; checked in tests/test_workbench_units_gui.py).
"""

from __future__ import annotations

import math
import re

MESSAGE_RESOLUTION_MM = 0.0001  # notes, limits, messages, fields: 0.1 um (a typed 0.0005 mm is not rounded)
INSPECTION_RESOLUTION_MM = 0.0001  # inspection values: 0.1 um, always 4 decimals in mm
RESOLUTIONS = {"mm": MESSAGE_RESOLUTION_MM, "um": 0.01, "deg": 0.0001, "mm/min": 0.1, "mm/s^2": 0.1}
"""Smallest step each job-file unit needs to show (in that unit)."""
FIELD_MIN_DECIMALS = 2  # FreeCAD's default number of decimals: fields look like FreeCAD's own
_NUMBER = r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
_UNITS = r"mm/min|mm/rev|mm/s\^2|mm"
_UNIT = rf"({_UNITS})(?![\w/^])"
_LENGTH_OR_FEED = re.compile(  # '[0.05, 100] mm' (a range: both ends in one unit) or '3.55 mm'
    rf"(?P<open>[\[(])(?P<low>{_NUMBER}), (?P<high>{_NUMBER})(?P<close>[\])]) (?P<range_unit>{_UNITS})(?![\w/^])"
    rf"|(?<![\w.])(?P<value>{_NUMBER}) {_UNIT}")
PER_REVOLUTION_RESOLUTION = 0.0001  # mm/rev: a lathe feed to 0.1 um per revolution


def preferred(value: float, unit: str, units) -> tuple[float, str, float]:
    """(the number shown, the schema's unit name, `unit`s per shown unit) for `value` in `unit` ("mm", "mm/min",
    "deg", "mm/s^2"); without `units`, `value` in `unit` itself. The shown unit may depend on the size (um for
    small lengths in the standard schema)."""
    if units is None or not math.isfinite(value):
        return float(value), unit, 1.0
    quantity = units.Quantity(f"{float(value)!r} {unit}")
    _, factor, name = quantity.getUserPreferred()
    per_unit = factor / units.Quantity(f"1 {unit}").Value  # FreeCAD's internal units (mm/s) -> `unit`
    return float(value) / per_unit, name, per_unit


def decimals(shown: float, per_unit: float, resolution: float, min_decimals: int = 0) -> int:
    """Fewest decimals (at least `min_decimals`) that show `shown` to `resolution` (in the job-file unit; a
    displayed unit is `per_unit` of them): 3 in mm for a micrometre, 4 in inches, 1 in um."""
    most = max(0, math.ceil(math.log10(per_unit / resolution) - 1e-9))  # 6 in inches: 0.0254 um, not 0.254
    if not math.isfinite(shown):
        return 0
    for count in range(min(min_decimals, most), most + 1):
        if round(shown, count) == round(shown, most):
            return count
    return most


def text(value: float, unit: str = "mm", units=None, resolution: float | None = None, fixed: bool = False,
         like: float | None = None) -> str:
    """`value` (in `unit`) as the user's schema writes it: '3.55 mm', '0.1398 in', '83.333 mm/s'. `fixed`:
    always the resolution's decimals ('21.4500 mm' for inspection values), else only the digits it has; `like`:
    in the unit the schema gives that value (both ends of a range in one unit)."""
    step = resolution if resolution is not None else RESOLUTIONS.get(unit, MESSAGE_RESOLUTION_MM)
    _, name, per_unit = preferred(value if like is None else like, unit, units)
    shown = float(value) / per_unit
    count = decimals(shown, per_unit, step, 99 if fixed else 0)
    separator = "" if name == '"' else " "
    return f"{shown:.{count}f}{separator}{name}"


def inspection_text(value_mm: float, units=None) -> str:
    """An inspection length to 0.1 um: '21.4567 mm' (4 decimals), '0.844752 in', '45.6 um'."""
    return text(value_mm, "mm", units, INSPECTION_RESOLUTION_MM, fixed=True)


def field_quantity(value: float, unit: str, units):
    """A FreeCAD Quantity of `value` in `unit` whose format shows it to the unit's resolution (at least
    FreeCAD's 2 decimals): what a Gui::QuantitySpinBox is given, so that 0.5 mm reads 0.01969 in, not 0.02 in."""
    quantity = units.Quantity(f"{float(value)!r} {unit}")
    shown, _, per_unit = preferred(value, unit, units)
    form = dict(quantity.Format)
    form["Precision"] = decimals(shown, per_unit, RESOLUTIONS.get(unit, MESSAGE_RESOLUTION_MM), FIELD_MIN_DECIMALS)
    quantity.Format = form
    return quantity


def display_unit(unit: str, units) -> tuple[str, float]:
    """(the suffix a plain number field shows, `unit`s per shown unit) for a unit FreeCAD has no field for:
    'mm/rev' -> ('in/rev', 25.4) under an imperial schema; 'mm/s^2' the schema's acceleration. Other units
    (m/min, 1/min, s, %) stay as they are."""
    if unit.endswith("/rev") and unit.split("/")[0] == "mm":
        _, name, per_unit = preferred(1.0, "mm", units)
        return f"{name}/rev", per_unit
    if unit == "mm/s^2":
        _, name, per_unit = preferred(1000.0, unit, units)
        return name, per_unit
    return unit, 1.0


def _number_field_text(value: float, unit: str, units) -> str:
    """A value of a unit FreeCAD has no quantity for (mm/rev, mm/s^2) as the panel's number field shows it."""
    name, per_unit = display_unit(unit, units)
    resolution = PER_REVOLUTION_RESOLUTION if unit == "mm/rev" else RESOLUTIONS.get(unit, MESSAGE_RESOLUTION_MM)
    shown = float(value) / per_unit
    return f"{shown:.{decimals(shown, per_unit, resolution)}f} {name}"


def message(sentence: str, units=None) -> str:
    """A message with its lengths and feeds ('[0.05, 100] mm', '3.55 mm', '1 mm/min', '0.1 mm/rev') in the
    user's schema (mm/rev and mm/s^2 as the panel's number fields show them)."""
    def one(value: float, unit: str, like: float | None = None) -> str:
        if unit in ("mm/rev", "mm/s^2"):
            return _number_field_text(value, unit, units)
        return text(value, unit, units, like=like)

    def converted(found: re.Match) -> str:
        if found.group("value") is not None:
            return one(float(found.group("value")), found.group(found.lastindex or 0))
        high, unit = float(found.group("high")), found.group("range_unit")
        low_text, high_text = (one(float(found.group(end)), unit, like=high) for end in ("low", "high"))
        return f"{found.group('open')}{low_text}, {high_text}{found.group('close')}"

    return _LENGTH_OR_FEED.sub(converted, sentence)
