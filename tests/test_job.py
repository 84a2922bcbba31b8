"""Job file schema: every section loads; unknown keys, wrong types, values outside the declared ranges and
failed cross-field checks name the key and its line; docs/job-file.md is what the declarations generate."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from spur_cad.errors import JobFileError
from spur_cad.job import SECTIONS, load_job, parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.keys import keys_of

ROOT = Path(__file__).resolve().parents[1]

FULL = """
[job]
name = "full"

[gear]
teeth = 30
module_mm = 2
face_width_mm = 15.5
rack_tip_radius_mm = 0.5
thickness_allowance_percent = 2.5

[stock]
radial_allowance_mm = 1.0

[tools.roughing]
kind = "flat"
diameter_mm = 3.0
flutes = 3

[tools.finishing]
kind = "bull_nose"
diameter_mm = 2.0
corner_radius_mm = 0.3

[roughing]
flank_allowance_mm = 0.15
clamp_rotary = true

[finishing]
strategy = "perimeter"

[machine]
max_spindle_rpm = 7000

[post]
dialect = "linuxcnc"
line_numbers = false
"""


def test_every_section_loads_with_types():
    job = parse_job(FULL, "full.toml")
    assert job.gear.teeth == 30 and job.gear.module_mm == 2.0 and isinstance(job.gear.module_mm, float)
    assert job.gear.thickness_allowance_fraction == pytest.approx(0.025)
    assert job.tools.roughing.diameter_mm == 3.0 and job.tools.roughing.flutes == 3
    assert job.tools.finishing.corner_radius_mm == 0.3
    assert job.roughing.clamp_rotary is True
    assert job.machine.max_spindle_rpm == 7000.0
    assert job.post.dialect == "linuxcnc"


def test_reference_example_is_the_method_gear():
    job = load_job(ROOT / "resources" / "examples" / "reference_gear.toml")
    g = job.gear
    assert (g.teeth, g.module_mm, g.pressure_angle_deg, g.profile_shift_coefficient) == (23, 4.0, 20.0, 0.0)
    assert (g.addendum_coefficient, g.dedendum_coefficient, g.rack_tip_radius_mm) == (1.0, 1.25, 0.8)
    assert g.thickness_allowance_fraction == pytest.approx(0.05) and g.face_width_mm == 20.0


# (old text, new text, what the message says after "full.toml:<line>: ", the key whose line it names)
ERRORS = [
    ("flutes = 3", "flutes = 3.5", "[tools.roughing] flutes must be a whole number, got 3.5", "flutes"),
    ("clamp_rotary = true", "clamp_rotary = 1", "[roughing] clamp_rotary must be true or false", "clamp_rotary"),
    ("[tools.finishing]", "[tools.polishing]", "unknown section [tools.polishing]", "[tools.polishing]"),
    ("max_spindle_rpm = 7000", "max_spindle_rmp = 7000", "unknown key 'max_spindle_rmp' in [machine]",
     "max_spindle_rmp"),
    ("kind = \"flat\"\ndiameter_mm = 3.0", "kind = \"flat\"",
     "[tools.roughing] is missing the required key 'diameter_mm'", "[tools.roughing]"),
    ("thickness_allowance_percent = 2.5", "thickness_allowance_percent = 80",
     "[gear] thickness_allowance_percent must be in [0, 20] %, got 80", "thickness_allowance_percent"),
    ("rack_tip_radius_mm = 0.5", "rack_tip_radius_mm = 1.5",
     "invalid gear: rack_tip_radius_mm = 1.5 mm is outside the accepted range [0, 1.2] mm", "rack_tip_radius_mm"),
    ("max_spindle_rpm = 7000", "max_spindle_rpm = nan", "[machine] max_spindle_rpm must be a finite number, got nan",
     "max_spindle_rpm"),
    ("max_spindle_rpm = 7000", "max_spindle_rpm = 50",
     "[machine] max_spindle_rpm must be in [100, 100000] 1/min, got 50", "max_spindle_rpm"),
    ("max_spindle_rpm = 7000", "max_spindle_rpm = 7000\nx_min_mm = 5.0\nx_max_mm = 4.0",
     "[machine] x_min_mm must be below x_max_mm", "x_min_mm"),
    ("clamp_rotary = true", "clamp_rotary = true\nfinish_stock_mm = 0.2",
     "[roughing] finish_stock_mm = 0.2 must be below flank_allowance_mm = 0.15", "finish_stock_mm"),
    ('strategy = "perimeter"', 'strategy = "spiral"', "[finishing] strategy 'spiral' is unknown", "strategy"),
    ('dialect = "linuxcnc"', 'dialect = "linuxcnc"\nrotary_mode = "spin"',
     "[post] rotary_mode must be 'unwound' or 'wrapped', got 'spin'", "rotary_mode"),
    ('dialect = "linuxcnc"', 'dialect = "linuxcnc"\nrotary_mode = "wrapped"',
     "[post] folded = true needs rotary_mode = 'unwound'", "rotary_mode"),
    ("corner_radius_mm = 0.3", "corner_radius_mm = 1.3",
     "[tools.finishing] finishing bull-nose corner_radius_mm = 1.3 must be in (0, 1)", "corner_radius_mm"),
]


@pytest.mark.parametrize("old, new, message, located", ERRORS)
def test_errors_name_key_and_line(old, new, message, located):
    assert old in FULL
    bad = FULL.replace(old, new)
    # the line is found here, independently of the loader: the first line of `new` that sets `located`
    line = next(n for n, text in enumerate(bad.splitlines(), start=1)
                if text.startswith(located) and (text in new or located.startswith("[")))
    with pytest.raises(JobFileError) as info:
        parse_job(bad, "full.toml")
    assert str(info.value).startswith(f"full.toml:{line}: {message}"), str(info.value)


def test_profile_tolerance_range():
    with pytest.raises(JobFileError, match="profile_tolerance_mm"):
        parse_job(FULL.replace('name = "full"', 'name = "full"\nprofile_tolerance_mm = 0'), "f.toml")


# --- every declared range, from the declarations -----------------------------------------------------------

MINIMAL = {"gear": {"teeth": 23, "module_mm": 4.0, "face_width_mm": 20.0}, "mate": {"teeth": 40},
           "tools.roughing": {"diameter_mm": 3.0},
           "tools.finishing": {"diameter_mm": 3.0}, "tools.bottom": {"diameter_mm": 2.0},
           "tools.roughing_top": {"diameter_mm": 6.0}}


def _job_text(section: str, key: str, literal: str) -> tuple[str, int]:
    """A minimal job setting `[section] key = literal`, and that line's number (counted here)."""
    tables = {"gear": dict(MINIMAL["gear"])}
    tables.setdefault(section, dict(MINIMAL.get(section, {})))
    lines: list[str] = []
    target = 0
    for name, table in tables.items():
        lines.append(f"[{name}]")
        for k, v in table.items():
            if not (name == section and k == key):
                lines.append(f"{k} = {v!r}")
        if name == section:
            lines.append(f"{key} = {literal}")
            target = len(lines)
    return "\n".join(lines) + "\n", target


def _numeric_keys():
    return [(section, k) for section, cls in SECTIONS.items() for k in keys_of(cls) if k.type in (float, int)]


@pytest.mark.parametrize("section, key", [(s, k.name) for s, k in _numeric_keys() if k.type is float])
@pytest.mark.parametrize("literal", ["nan", "inf", "-inf"])
def test_every_number_rejects_nan_and_infinity_naming_key_and_line(section, key, literal):
    text, line = _job_text(section, key, literal)
    with pytest.raises(JobFileError) as info:
        parse_job(text, "f.toml")
    assert str(info.value).startswith(f"f.toml:{line}: [{section}] {key} must be a finite number, got {literal}")


def _outside(k) -> list:
    """Values just outside each numeric end of a key's declared range."""
    values = []
    for end, sign, is_open in ((k.low, -1, k.low_open), (k.high, 1, k.high_open)):
        if end is None or isinstance(end, str):
            continue
        if is_open:
            values.append(end)
        else:
            values.append(end + sign * (1 if k.type is int else max(abs(end) * 1e-6, 1e-9)))
    return values


@pytest.mark.parametrize("section, key", [(s, k.name) for s, k in _numeric_keys() if k.low is not None])
def test_every_declared_range_rejects_values_just_outside_naming_key_and_line(section, key):
    k = next(k for k in keys_of(SECTIONS[section]) if k.name == key)
    for value in _outside(k):
        text, line = _job_text(section, key, repr(value))
        with pytest.raises(JobFileError) as info:
            parse_job(text, "f.toml")
        assert str(info.value).startswith(f"f.toml:{line}: [{section}] {key} must be in "), str(info.value)
        assert str(info.value).endswith(f", got {value!r}") or str(info.value).endswith(f", got {value:g}")


def test_a_bound_naming_another_key():
    text = small = "[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n[post]\nmax_line_number = 99\n"
    assert parse_job(small + "line_number_step = 99\n", "f.toml").post.line_number_step == 99
    with pytest.raises(JobFileError) as info:
        parse_job(text + "line_number_step = 100\n", "f.toml")
    assert str(info.value) == "f.toml:7: [post] line_number_step must be in 1..max_line_number (= 99), got 100"


def values_of_bound(bound, keys) -> float:
    """A range bound as a number: a bound naming another key of the section is that key's default."""
    return next(k.default for k in keys if k.name == bound) if isinstance(bound, str) else bound


def test_declarations_are_complete_and_consistent():
    """Every field of a section is a declared key; its unit matches its name; its default is accepted."""
    from spur_cad.keys import value_problem

    suffix_units = {"_mm": "mm", "_deg": "deg", "_percent": "%", "_s": "s", "_mm_min": "mm/min", "_m_min": "m/min",
                    "_deg_min": "deg/min", "_rpm": "1/min", "_mm_s2": "mm/s^2", "_deg_s2": "deg/s^2", "_kg": "kg",
                    "_kg_dm3": "kg/dm^3", "_mm_rev": "mm/rev", "_um": "um", "_arcsec": "arcsec"}
    labels = []
    for section, cls in SECTIONS.items():
        keys = keys_of(cls)
        assert [k.name for k in keys] == [f.name for f in dataclasses.fields(cls)], section
        for k in keys:
            suffix = max((s for s in suffix_units if k.name.endswith(s)), key=len, default="")
            assert k.unit == suffix_units.get(suffix, ""), (section, k.name, k.unit)
            assert k.meaning and k.label and k.group, (section, k.name)
            if not k.required:
                values = {x.name: x.default for x in keys}
                assert value_problem(k, k.default, values) is None, (section, k.name)
            if k.type is float and k.low is not None:
                names = {x.name for x in keys}
                low, high = (values_of_bound(b, keys) for b in (k.low, k.high))
                assert all(b in names for b in (k.low, k.high) if isinstance(b, str)), (section, k.name)
                assert math.isfinite(low) and math.isfinite(high) and low < high, (section, k.name)
            labels.append(k.label.format(Role=section.removeprefix("tools.")))
    assert len(labels) == len(set(labels))


def test_the_simulators_accepted_resolutions_are_the_declared_range():
    from spur_cad.job import SimulationSection
    from spur_cad.keys import key_of
    from spur_cad.sim.simulate import SimSettings, SimulationError

    k = key_of(SimulationSection, "resolution_mm")
    for value in (k.low, k.high):
        SimSettings(resolution_mm=value)  # made: its checks pass
    for value in (k.low * 0.99, k.high * 1.01):
        with pytest.raises(SimulationError):
            SimSettings(resolution_mm=value)


def test_docs_job_file_md_is_generated_from_the_declarations():
    committed = (ROOT / "docs" / "job-file.md").read_text()
    assert committed == job_file_reference_markdown(), (
        "docs/job-file.md is out of date: run `python -m spur_cad.keydocs > docs/job-file.md`")


TWO_TOOLS = """[gear]
teeth = 23
module_mm = 4.0
rack_tip_radius_mm = 0.8
face_width_mm = 20.0

[tools.roughing]
diameter_mm = 3.5

[tools.finishing]
kind = "bull_nose"
diameter_mm = 2.0
corner_radius_mm = 0.5
"""


def test_two_different_tools_may_not_share_a_tool_number():
    from spur_cad.errors import JobFileError
    from spur_cad.job import parse_job

    job = parse_job(TWO_TOOLS, "two.toml")  # no numbers given: T1 roughing, T2 finishing
    assert (job.tools.roughing.tool_number, job.tools.finishing.tool_number) == (1, 2)
    with pytest.raises(JobFileError) as error:
        parse_job(TWO_TOOLS + "tool_number = 1\n", "two.toml")
    message = str(error.value)
    assert message.startswith("two.toml:14: [tools.finishing] tool_number = 1 is also the roughing tool's number")
    assert "roughing flat D 3.5 mm" in message and "finishing bull_nose D 2 mm r 0.5 mm" in message
    # the same end mill for both operations (its own cutting data each) may keep one number
    same = TWO_TOOLS.replace('kind = "bull_nose"\ndiameter_mm = 2.0\ncorner_radius_mm = 0.5\n',
                             "diameter_mm = 3.5\ncutting_speed_m_min = 150.0\ntool_number = 1\n")
    assert parse_job(same, "same.toml").tools.finishing.tool_number == 1
