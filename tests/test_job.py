"""Job file schema: every section loads, unknown keys and wrong types name the key and line."""

from __future__ import annotations

from pathlib import Path

import pytest

from spur_cad.errors import JobFileError
from spur_cad.job import load_job, parse_job

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


@pytest.mark.parametrize("old, new, message", [
    ("flutes = 3", "flutes = 3.5", "full.toml:18: [tools.roughing] flutes must be a whole number, got 3.5"),
    ("clamp_rotary = true", "clamp_rotary = 1", "full.toml:27: [roughing] clamp_rotary must be true or false"),
    ("[tools.finishing]", "[tools.polishing]", "unknown section [tools.polishing]"),
    ("max_spindle_rpm = 7000", "max_spindle_rmp = 7000", "full.toml:33: unknown key 'max_spindle_rmp' in [machine]"),
    ("kind = \"flat\"\ndiameter_mm = 3.0", "kind = \"flat\"", "[tools.roughing] is missing the required key 'diameter_mm'"),
    ("thickness_allowance_percent = 2.5", "thickness_allowance_percent = 80",
     "full.toml:10: invalid gear: thickness_allowance_percent / 100 = 0.8"),
])
def test_errors_name_key_and_line(old, new, message):
    assert old in FULL
    with pytest.raises(JobFileError) as info:
        parse_job(FULL.replace(old, new), "full.toml")
    assert message in str(info.value)


def test_profile_tolerance_range():
    with pytest.raises(JobFileError, match="profile_tolerance_mm"):
        parse_job(FULL.replace('name = "full"', 'name = "full"\nprofile_tolerance_mm = 0'), "f.toml")
