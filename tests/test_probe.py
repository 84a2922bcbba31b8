"""The on-machine probing program probe.<ext> ([probe], docs/probing.md): LinuxCNC's rs274 reads it; every probe
move ends at the design point + (ball radius - overtravel) along the design normal, computed here from the
textbook involute; the documented point counts and order; A indexed only at the clearance height; the Fanuc /
Haas form holds the same targets in well-formed G31 / DPRNT blocks; the header says what probing cannot see;
bad [probe] values are one line naming the file, the line and the key."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from spur_cad.errors import JobFileError
from spur_cad.job import parse_job
from spur_cad.pipeline import probe_program
from tests.gears import REFERENCE_JOB
from tests.rs274_helper import canon_args, run_rs274
from tests.textbook import Textbook, inv

REFERENCE = REFERENCE_JOB.read_text()
TEXTBOOK = Textbook(z=23, m=4.0, alpha_deg=20.0, rho=0.8, allowance_fraction=0.05)  # resources/examples/reference
BALL_MM, OVERTRAVEL_MM = 2.0, 0.5  # [probe]'s defaults, written out in the job below
FACE_MM, CLEARANCE_Z_MM = 20.0, 50.0 + 0.5 + 1.0 + 1.0  # tip + radial allowance + [machine] clearance + ball radius
PROBE = f"\n[probe]\nstylus_diameter_mm = {BALL_MM}\novertravel_mm = {OVERTRAVEL_MM}\n"


def _job(dialect: str = "linuxcnc", probe: str = PROBE):
    return parse_job(REFERENCE.replace('dialect = "linuxcnc"', f'dialect = "{dialect}"') + probe, "ref.toml")


def _form_radius(g: Textbook) -> float:
    """Where the rack's corner round meets its straight flank, rolled onto the gear (not undercut): the flank's
    tangent point lies B + rho sin(alpha) below the rolling line."""
    roll = g.r * math.sin(g.alpha) - (g.corner_depth + g.rho * math.sin(g.alpha)) / math.sin(g.alpha)
    return math.hypot(g.rb, roll)


def _flank(g: Textbook, radius: float, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Space 0's involute point at `radius` and its unit normal into the space (gap frame: x to the right, y
    along the space's axis): the right flank sits at polar angle theta_b + inv(alpha_y) from +y toward +x, and
    its normal runs from the point away from where the line of action touches the base circle (theta_b + t)."""
    alpha_y = math.acos(g.rb / radius)
    polar, touch = g.theta_b + inv(alpha_y), g.theta_b + math.tan(alpha_y)
    p = radius * np.array([math.sin(polar), math.cos(polar)])
    n = p - g.rb * np.array([math.sin(touch), math.cos(touch)])
    n /= np.linalg.norm(n)
    mirror = np.array([1.0 if side == "right" else -1.0, 1.0])
    return p * mirror, n * mirror


def _expected(g: Textbook) -> list[tuple[int, str, str, float, np.ndarray]]:
    """(space, side, kind, X, probe move's end in the part frame) in the documented order: per space the pitch
    points (right, left), then in the spaces at 0, 90, 180, 270 deg per flank the profile trace (10 points,
    form circle to 95 % of the roll length to the tip) and the helix trace (5 points)."""
    roll_form, roll_tip = math.sqrt(_form_radius(g) ** 2 - g.rb ** 2), math.sqrt(g.ra ** 2 - g.rb ** 2)
    rolls = np.linspace(roll_form, roll_form + 0.95 * (roll_tip - roll_form), 10)
    profile_radii = [math.hypot(g.rb, roll) for roll in rolls]
    cut = min(0.05 * FACE_MM, g.m)
    helix_x = np.linspace(cut, FACE_MM - cut, 5)
    traced = {round(j * g.z / 4) for j in range(4)}
    found = []

    def add(k, side, kind, x, radius):
        p, n = _flank(g, radius, side)
        target = p + (BALL_MM / 2 - OVERTRAVEL_MM) * n
        turn = 2 * math.pi * k / g.z  # space k is space 0 turned by k * 360/z (positive A sense)
        c, s = math.cos(turn), math.sin(turn)
        turned = np.array([c * target[0] - s * target[1], s * target[0] + c * target[1]])
        found.append((k, side, kind, float(x), turned))

    for k in range(g.z):
        for side in ("right", "left"):
            add(k, side, "pitch", FACE_MM / 2, g.r)
        if k in traced:
            for side in ("right", "left"):
                for radius in profile_radii:
                    add(k, side, "profile", FACE_MM / 2, radius)
                for x in helix_x:
                    add(k, side, "helix", x, g.r)
    return found


def _to_part(y: float, z: float, a_deg: float) -> np.ndarray:
    """Machine (Y, Z) at A back to the part frame: machine = R(A) part, A right-handed about +X."""
    a = math.radians(a_deg)
    return np.array([y * math.cos(a) + z * math.sin(a), -y * math.sin(a) + z * math.cos(a)])


@pytest.fixture(scope="module")
def linuxcnc_program(tmp_path_factory) -> tuple[Path, str]:
    name, text = probe_program(_job())
    assert name == "probe.ngc"
    path = tmp_path_factory.mktemp("probe") / name
    path.write_bytes(text)
    return path, text.decode()


@pytest.mark.linuxcnc
def test_rs274_runs_the_program_and_every_probe_move_ends_at_the_design_target(linuxcnc_program, tmp_path):
    path, _ = linuxcnc_program
    tools = tmp_path / "tools.tbl"
    tools.write_text("T20 P20 Z0 D0.0787 ;touch probe, ball 2 mm\n")  # rs274's own table has no T20
    ok, canon, messages = run_rs274(path, tools)
    assert ok, messages
    probes = [canon_args(line) for line in canon if line.startswith("STRAIGHT_PROBE(")]
    expected = _expected(TEXTBOOK)
    assert len(probes) == len(expected) == 23 * 2 + 4 * 2 * (10 + 5)
    for (x, y, z, a, *_), (k, side, kind, x_expected, target) in zip(probes, expected):
        assert x == pytest.approx(x_expected, abs=1e-4), (k, side, kind)
        assert _to_part(y, z, a) == pytest.approx(target, abs=2e-4), (k, side, kind)
        assert (a + 360.0 * k / 23) % 360.0 == pytest.approx(0.0, abs=1e-4) or \
            (a + 360.0 * k / 23) % 360.0 == pytest.approx(360.0, abs=1e-4)  # the space's axis vertical


@pytest.mark.linuxcnc
def test_rs274_sees_a_indexed_only_at_the_clearance_height(linuxcnc_program, tmp_path):
    path, text = linuxcnc_program
    tools = tmp_path / "tools.tbl"
    tools.write_text("T20 P20 Z0 D0.0787\n")
    ok, canon, messages = run_rs274(path, tools)
    assert ok, messages
    pose = None
    a_moves = 0
    for line in canon:
        if not line.startswith(("STRAIGHT_TRAVERSE(", "STRAIGHT_FEED(", "STRAIGHT_PROBE(")):
            continue
        new = canon_args(line)[:4]
        if line.startswith("STRAIGHT_TRAVERSE(") and pose is not None:
            assert min(pose[2], new[2]) >= CLEARANCE_Z_MM - 1e-4, line  # rapids only at the clearance height
        if pose is not None and abs(new[3] - pose[3]) > 1e-9:
            a_moves += 1
            assert line.startswith("STRAIGHT_TRAVERSE(") and new[:3] == pose[:3], line  # A alone, no X Y Z
            assert pose[2] >= CLEARANCE_Z_MM - 1e-4, line
        pose = new
    assert a_moves == 22  # one index per space after space 0 (A0 at the start is no change)
    assert "(PROBEOPEN probe.log)" in text and text.index("(PROBEOPEN probe.log)") < text.index("G38.2")
    assert text.rindex("G38.2") < text.index("(PROBECLOSE)")


FANUC_G31 = re.compile(r"G31 Y(-?\d+\.\d{1,3}) Z(-?\d+\.\d{1,3}) F\d+\.\d")
DPRNT = re.compile(r"DPRNT\[X#5061\[\d\d\]Y#5062\[\d\d\]Z#5063\[\d\d\]A#5064\[\d\d\]\]")
NO_TRIP = re.compile(r"IF\[\[ABS\[#5062-\[(-?\d+\.\d+)\]\]\+ABS\[#5063-\[(-?\d+\.\d+)\]\]\]LT0\.001\]THEN#3000=1\(.*\)")


@pytest.mark.parametrize("dialect, name", [("fanuc", "probe.nc"), ("haas", "probe.nc")])
def test_the_g31_form_holds_the_same_targets_in_well_formed_blocks(dialect, name):
    file_name, body = probe_program(_job(dialect))
    assert file_name == name
    lines = body.decode().splitlines()
    assert lines[0] == lines[-1] == "%" and lines[-2] == "M30" and lines[-3] == "PCLOS"
    assert "POPEN" in lines and lines.index("POPEN") < next(i for i, line in enumerate(lines) if line.startswith("G31"))
    expected = _expected(TEXTBOOK)
    a_deg, found = None, 0
    for i, line in enumerate(lines):
        if line.startswith("G0 A"):
            a_deg = float(line[4:])
        if not line.startswith("G31"):
            continue
        match = FANUC_G31.fullmatch(line)
        assert match, line
        assert DPRNT.fullmatch(lines[i + 1]), lines[i + 1]
        check = NO_TRIP.fullmatch(lines[i + 2])
        assert check and check.groups() == match.groups(), lines[i + 2]  # the alarm compares with this move's end
        y, z = float(match.group(1)), float(match.group(2))
        assert _to_part(y, z, a_deg) == pytest.approx(expected[found][4], abs=2e-3)
        found += 1
    assert found == len(expected)


def test_the_header_says_what_probing_cannot_see(linuxcnc_program):
    _, text = linuxcnc_program
    header = " ".join(line for line in text.splitlines()[:20] if line.startswith("("))
    assert "CANNOT SEE" in header
    assert "repeatable index error" in header and "offsets" in header  # shared by the cut and the probe
    assert "size and wear" in header and "deflection" in header and "runout" in header  # what it sees
    assert "Pitch" in header and "external measurement or the table's calibration" in header


def test_the_traces_lie_in_the_grades_evaluation_ranges():
    from spur_cad.cam.probing import ProbeSection, design_points
    from spur_cad.grade.simulated import helix_range_mm, profile_range_mm

    job = _job()
    points = design_points(job.gear, ProbeSection())
    assert job.gear.form_radius_mm == pytest.approx(_form_radius(TEXTBOOK), abs=1e-9)
    rolls = [math.sqrt(p.radius_mm ** 2 - job.gear.base_radius_mm ** 2) for p in points if p.kind == "profile"]
    assert (min(rolls), max(rolls)) == pytest.approx(profile_range_mm(job.gear), abs=1e-9)
    xs = [p.x_mm for p in points if p.kind == "helix"]
    assert (min(xs), max(xs)) == pytest.approx(helix_range_mm(FACE_MM, 4.0), abs=1e-12)


# (what the job adds or changes, what the message says after "ref.toml:<line>: ", the text of the line named)
BAD = [
    ({"dialect": "siemens"}, "[post] dialect = 'siemens' has no probing program", 'dialect = "siemens"'),
    ({"probe": "\n[probe]\ntool_number = 2\n"}, "[probe] tool_number = 2 is the finishing tool's number too",
     "tool_number = 2"),
    ({"probe": "\n[probe]\nstylus_diameter_mm = 6\n"}, "[probe] stylus_diameter_mm = 6: the ball", "stylus_diameter"),
    ({"probe": "\n[probe]\nprobe_on_code = \"M30\"\n"}, "[probe] probe_on_code = 'M30' must be one M code",
     "probe_on_code"),
    ({"probe": "\n[probe]\npitch = false\nprofile = false\nhelix = false\n"}, "[probe] pitch, profile and helix are "
     "all false", "pitch = false"),
    ({"probe": "\n[probe]\nprofile_points = 9\n"}, "[probe] profile_points must be in 10..200, got 9",
     "profile_points"),
    ({"helical": True}, "[probe] probes spur gears only: [gear] helix_angle_deg = 15", "[probe]"),
]


@pytest.mark.parametrize("change, message, line_text", BAD)
def test_bad_probe_settings_are_one_line_naming_file_line_and_key(change, message, line_text):
    text = REFERENCE.replace('dialect = "linuxcnc"', f'dialect = "{change.get("dialect", "linuxcnc")}"')
    if change.get("helical"):
        text = text.replace("face_width_mm = 20.0", "face_width_mm = 20.0\nhelix_angle_deg = 15.0")
    text += change.get("probe", "\n[probe]\n")
    line = max(n for n, row in enumerate(text.splitlines(), start=1) if row.startswith(line_text))  # the last
    with pytest.raises(JobFileError) as info:
        parse_job(text, "ref.toml")
    assert str(info.value).startswith(f"ref.toml:{line}: {message}"), str(info.value)
    assert "\n" not in str(info.value)


def test_without_probe_no_program_and_the_probe_words_never_come_from_user_text():
    from spur_cad.post.header import inert_comment_text

    assert _job(probe="").probe is None
    for text in ("PROBEOPEN /etc/passwd", "probeclose", "LOGCLOSE"):
        assert inert_comment_text(text, 80).startswith("_")  # LinuxCNC would act on them as comments


def test_a_run_writes_probe_ngc_into_the_output_set(tmp_path):
    from spur_cad.outputs import write_output_set
    from spur_cad.pipeline import run_job

    gear = REFERENCE[REFERENCE.index("[gear]"):REFERENCE.index("[stock]")]
    job = parse_job(f"{gear}\n[simulation]\nenabled = false\n{PROBE}", "gear.toml")  # no tools: no CAM
    files = run_job(job).files
    assert files["probe.ngc"] == probe_program(job)[1]
    written = {path.name for path in write_output_set(tmp_path, files)}
    assert "probe.ngc" in written and (tmp_path / "probe.ngc").read_bytes() == files["probe.ngc"]
