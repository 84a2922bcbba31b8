"""Flank modifications (issue 31): the job file's [gear.modifications], the removal they define, profile.csv, and
the STEP solid sectioned at three X positions against the design involute moved by the modification (computed
here from the job's numbers, not by spur_cad.geometry.modifications)."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from spur_cad.errors import JobFileError
from spur_cad.geometry.modifications import normal_offset_mm, roll_length_mm
from spur_cad.geometry.sampling import sample_profile
from spur_cad.job import parse_job
from spur_cad.pipeline import job_profile_csv

GEAR = "[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 1.52\n"
SPUR = GEAR + ("[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\n"
               "lead_crowning_um = 10\n")
HELICAL = GEAR + "helix_angle_deg = 15\n" + ("[gear.modifications]\ntip_relief_um = 12\n"
                                           "tip_relief_start_diameter_mm = 97.5\n")


def test_an_unmodified_job_has_no_modifications_and_the_old_profile_csv():
    job = parse_job(GEAR + "[gear.modifications]\ntip_relief_start_diameter_mm = 98\n", "f.toml")
    assert job.modifications is None
    text = job_profile_csv(job, sample_profile(job.gear.tooth_space_profile(), 0.001)).decode()
    assert text.splitlines()[0] == "x_mm,y_mm"


def test_side_tables_override_the_common_one():
    job = parse_job(SPUR + "[gear.modifications.left]\ntip_relief_um = 5\nhelix_slope_um = -4\n", "f.toml")
    right, left = job.modifications.right, job.modifications.left
    assert (right.tip_relief_mm, left.tip_relief_mm) == (0.015, 0.005)
    assert (right.helix_slope_mm, left.helix_slope_mm) == (0.0, -0.004)
    assert right.lead_crowning_mm == left.lead_crowning_mm == 0.010
    assert right.tip_relief_start_roll_mm == left.tip_relief_start_roll_mm


@pytest.mark.parametrize("extra, line, words", [
    ("tip_relief_um = 15\n", 6, "[gear.modifications] tip_relief_start_diameter_mm = 0 must lie on the usable "
                                "involute"),
    ("tip_relief_um = 401\ntip_relief_start_diameter_mm = 98\n", 7, "tip_relief_um = 401 um is beyond 10 % of the "
                                                                  "module (400 um)"),
    ("lead_crowning_um = -1\n", 7, "[gear.modifications] lead_crowning_um must be in [0, 10000] um, got -1"),
    ("profile_slope_um = nan\n", 7, "profile_slope_um must be a finite number, got nan"),
    ("tip_relief_um = 10\ntip_relief_start_diameter_mm = 92\nroot_relief_um = 5\nroot_relief_start_diameter_mm = 95\n",
     10, "overlap: together they are longer than the usable involute"),
    ("end_relief_um = 5\nend_relief_length_mm = 10.5\n", 8, "end_relief_length_mm = 10.5 must be above 0"),
    ("tip_relief_shape = \"round\"\n", 7, "tip_relief_shape must be 'linear' or 'parabolic'"),
    ("tip_relief_um = 5\ntip_relief_start_diameter_mm = 98\n[gear.modifications.right]\n"
     "tip_relief_start_diameter_mm = 101\n", 10, "[gear.modifications.right] tip_relief_start_diameter_mm = 101 must "
                                                 "lie on the usable involute, between the form diameter"),
])
def test_errors_name_the_key_and_its_line(extra, line, words):
    with pytest.raises(JobFileError) as info:
        parse_job(GEAR + "[gear.modifications]\n" + extra, "f.toml")
    message = str(info.value)
    assert message.startswith(f"f.toml:{line}: "), message
    assert words in message, message
    assert "\n" not in message


def test_removal_follows_the_iso_21771_definitions():
    job = parse_job(GEAR + "[gear.modifications]\ntip_relief_um = 15\ntip_relief_start_diameter_mm = 98\n"
                           "tip_relief_shape = \"parabolic\"\nlead_crowning_um = 10\nprofile_slope_um = 4\n"
                           "end_relief_um = 6\nend_relief_length_mm = 2\nend_relief_faces = \"front\"\n", "f.toml")
    spec, mods = job.gear, job.modifications
    rb = spec.base_radius_mm
    l_form, l_tip = roll_length_mm(rb, 2 * spec.form_radius_mm), roll_length_mm(rb, 2 * spec.tip_radius_mm)
    l_start, l_mid = roll_length_mm(rb, 98.0), (l_form + l_tip) / 2

    def removal_um(roll, x):
        return 1000 * float(normal_offset_mm(mods, "right", roll, x))

    assert removal_um(l_mid, 10.0) == pytest.approx(0.0, abs=1e-12)  # mid-profile, mid-face: nothing
    assert removal_um(l_tip, 10.0) - removal_um(l_start, 10.0) == pytest.approx(15.0 - 4 * (l_tip - l_start)
                                                                                 / (l_tip - l_form))
    halfway = (l_start + l_tip) / 2
    slope_there = -4 * (halfway - l_mid) / (l_tip - l_form)
    assert removal_um(halfway, 10.0) == pytest.approx(15.0 / 4 + slope_there)  # parabolic: a quarter halfway
    assert removal_um(l_form, 10.0) - removal_um(l_tip, 10.0) == pytest.approx(4.0 - 15.0)  # f_Halpha = 4 um
    assert removal_um(l_mid, 20.0) == pytest.approx(10.0)  # C_beta at the back face
    assert removal_um(l_mid, 0.0) == pytest.approx(10.0 + 6.0)  # and the front face's end relief
    assert removal_um(l_mid, 1.0) == pytest.approx(10.0 * 0.81 + 3.0)
    grid = normal_offset_mm(mods, "right", np.linspace(l_form, l_tip, 7)[:, None], np.linspace(0, 20, 5)[None, :])
    assert grid.shape == (7, 5)


def test_profile_csv_of_a_modified_gear_has_both_profiles():
    job = parse_job(SPUR, "f.toml")
    rows = list(csv.DictReader(io.StringIO(job_profile_csv(job, sample_profile(job.gear.tooth_space_profile(),
                                                                               0.001)).decode())))
    assert list(rows[0]) == ["x_mm", "y_mm", "unmodified_x_mm", "unmodified_y_mm", "removal_um"]
    spec = job.gear
    rb = spec.base_radius_mm
    l_start, l_tip = roll_length_mm(rb, 98.0), roll_length_mm(rb, 100.0)
    checked = 0
    for row in rows:
        x, y = float(row["unmodified_x_mm"]), float(row["unmodified_y_mm"])
        radius = math.hypot(x, y)
        if spec.form_radius_mm + 0.01 < radius < spec.tip_radius_mm - 1e-6:  # the involute at mid-face: tip relief
            roll = math.sqrt(radius**2 - rb**2)
            expected = 15.0 * max(roll - l_start, 0.0) / (l_tip - l_start)
            assert float(row["removal_um"]) == pytest.approx(expected, abs=1e-6)
            checked += 1
    assert checked > 20


# --- the solid, read back from its STEP file ------------------------------------------------------------------


def _read_step(content: bytes, tmp_path):
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    path = tmp_path / "gear.step"
    path.write_bytes(content)
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


def _section_points(shape, x: float, per_edge: int = 200) -> np.ndarray:
    """Points (Y, Z) of the shape's section by the plane X = x, by OCP."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    section = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(x, 0, 0), gp_Dir(1, 0, 0)), False)
    section.SetRunParallel(True)
    section.Approximation(False)  # the exact intersection curves, not approximations of them
    section.Build()
    assert section.IsDone()
    points = []
    explorer = TopExp_Explorer(section.Shape(), TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge(explorer.Current()))
        for u in np.linspace(curve.FirstParameter(), curve.LastParameter(), per_edge):
            p = curve.Value(u)
            points.append((p.Y(), p.Z()))
        explorer.Next()
    return np.array(points)


HARD_MODIFICATIONS = ("[gear.modifications]\ntip_relief_um = 12\ntip_relief_start_diameter_mm = 37\n"
                      "root_relief_um = 8\nroot_relief_start_diameter_mm = 34.5\nroot_relief_shape = \"parabolic\"\n"
                      "profile_crowning_um = 3\nlead_crowning_um = 6\nend_relief_um = 10\nend_relief_length_mm = 2\n"
                      "[gear.modifications.left]\ntip_relief_um = 6\ntip_relief_shape = \"parabolic\"\n"
                      "profile_slope_um = -2\nlead_crowning_um = 3\nhelix_slope_um = 4\n")
HARD_COMMON = {"tip_relief_um": 12.0, "tip_relief_start_diameter_mm": 37.0, "root_relief_um": 8.0,
               "root_relief_start_diameter_mm": 34.5, "root_relief_shape": "parabolic", "profile_crowning_um": 3.0,
               "lead_crowning_um": 6.0, "end_relief_um": 10.0, "end_relief_length_mm": 2.0}
SIDES_OF_HARD = ("right", "left")
HARD_SIDES = {"right": HARD_COMMON,
              "left": {**HARD_COMMON, "tip_relief_um": 6.0, "tip_relief_shape": "parabolic", "profile_slope_um": -2.0,
                       "lead_crowning_um": 3.0, "helix_slope_um": 4.0}}


def _hard_job(helix_angle_deg: float) -> str:
    """17 teeth with every modification, different on the two sides (the loft that once took minutes)."""
    return (f"[gear]\nteeth = 17\nmodule_mm = 2.0\nface_width_mm = 16\nhelix_angle_deg = {helix_angle_deg}\n"
            + HARD_MODIFICATIONS)


def _expected_removal_mm(spec, values: dict, roll, x):
    """One flank side's removal (mm) at roll length L and face position X, from ISO 21771's definitions and the
    job's numbers (um; absent keys are 0): reliefs linear or parabolic from their start to the tip / form circle,
    profile crowning and slope about mid-profile, lead crowning and helix slope about mid-face, end reliefs linear
    over their length at both faces."""
    rb, b = spec.base_radius_mm, spec.face_width_mm
    l_form, l_tip = math.sqrt(spec.form_radius_mm**2 - rb**2), math.sqrt(spec.tip_radius_mm**2 - rb**2)
    l_mid, l_alpha = (l_form + l_tip) / 2, l_tip - l_form
    um = {key: value / 1000 for key, value in values.items() if key.endswith("_um")}
    removal = um.get("profile_crowning_um", 0.0) * (2 * (roll - l_mid) / l_alpha) ** 2 \
        - um.get("profile_slope_um", 0.0) * (roll - l_mid) / l_alpha
    if "tip_relief_um" in um:
        l_start = math.sqrt((values["tip_relief_start_diameter_mm"] / 2) ** 2 - rb**2)
        s = np.maximum(roll - l_start, 0.0) / (l_tip - l_start)
        removal = removal + um["tip_relief_um"] * (s**2 if values.get("tip_relief_shape") == "parabolic" else s)
    if "root_relief_um" in um:
        l_start = math.sqrt((values["root_relief_start_diameter_mm"] / 2) ** 2 - rb**2)
        s = np.maximum(l_start - roll, 0.0) / (l_start - l_form)
        removal = removal + um["root_relief_um"] * (s**2 if values.get("root_relief_shape") == "parabolic" else s)
    removal = removal + um.get("lead_crowning_um", 0.0) * (2 * (x - b / 2) / b) ** 2 \
        - um.get("helix_slope_um", 0.0) * (x - b / 2) / b
    if "end_relief_um" in um:
        length = values["end_relief_length_mm"]
        removal = removal + um["end_relief_um"] * (max(length - x, 0.0) + max(x - (b - length), 0.0)) / length
    return removal


@pytest.mark.slow
@pytest.mark.parametrize("text, sides", [
    (SPUR, {"tip_relief_um": 15.0, "tip_relief_start_diameter_mm": 98.0, "lead_crowning_um": 10.0}),
    (HELICAL, {"tip_relief_um": 12.0, "tip_relief_start_diameter_mm": 97.5}),
    (_hard_job(0), HARD_SIDES),
    (_hard_job(20), HARD_SIDES),
], ids=["spur tip relief and lead crowning", "helical tip relief", "spur every modification, sides differ",
        "helical every modification, sides differ"])
def test_step_sections_are_the_design_involute_moved_by_the_modification(text, sides, tmp_path):
    """Every section point on the usable involute (all teeth, both flanks, each with its side's modifications)
    lies at the expected removal below the design involute within 1.5 um, and the section covers the whole
    involute; at three X positions (inside the end reliefs, mid-face)."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    from spur_cad.pipeline import build_cad

    job = parse_job(text, "f.toml")
    spec = job.gear
    if "right" not in sides:
        sides = {"right": sides, "left": sides}
    _, files = build_cad(job, timestamp="2026-01-01T00:00:00")
    shape = _read_step(files["gear.step"], tmp_path)
    assert BRepCheck_Analyzer(shape).IsValid()
    rb, pitch = spec.base_radius_mm, 2 * math.pi / spec.teeth
    theta_b = spec.base_half_space_angle_rad
    low, high = spec.form_radius_mm + 0.05, spec.tip_radius_mm - 0.02
    for x in (0.3, spec.face_width_mm / 2, spec.face_width_mm - 0.3):
        yz = _section_points(shape, x)
        # Part frame at A = 0 -> the section as at X = 0 (undo the helix turn) -> polar angle from +Z, clockwise.
        turn = -spec.section_turn_rad(x)
        y = yz[:, 0] * math.cos(turn) - yz[:, 1] * math.sin(turn)
        z = yz[:, 0] * math.sin(turn) + yz[:, 1] * math.cos(turn)
        radius = np.hypot(y, z)
        signed = (np.arctan2(y, z) + pitch / 2) % pitch - pitch / 2  # into space 0: + its right flank (+Y)
        folded = np.abs(signed)  # the left flank mirrored onto the right
        for side, on_side in (("right", signed > 0), ("left", signed < 0)):
            on_involute = on_side & (radius > low) & (radius < high) & (folded < pitch / 2 - 1e-3)
            r, theta = radius[on_involute], folded[on_involute]
            # Involutes of one base circle are parallel: a point at polar angle theta lies r_b (theta - theta_inv(r))
            # into the tooth from the design involute, whose foot point has roll length L + removal.
            pressure = np.arccos(rb / r)
            removal = rb * (theta - theta_b - (np.tan(pressure) - pressure))
            roll = np.sqrt(r**2 - rb**2)
            expected = np.zeros_like(roll)
            for _ in range(3):
                expected = _expected_removal_mm(spec, sides[side], roll + expected, x)
            assert np.abs(removal - expected).max() < 1.5e-3, (x, side, np.abs(removal - expected).max())
            gaps = np.diff(np.sort(roll))
            assert roll.min() < math.sqrt(low**2 - rb**2) + 0.5 and roll.max() > math.sqrt(high**2 - rb**2) - 0.5
            assert gaps.max() < 0.3, (x, side)  # every flank is there, not only some
            assert on_involute.sum() > spec.teeth * 20


@pytest.mark.slow  # a modified gear's whole inspection sheet (9 s)
def test_the_inspection_sheet_lists_the_modifications_and_says_where_span_and_pins_touch():
    from spur_cad.pipeline import run_job

    result = run_job(parse_job(SPUR + "[gear.modifications.left]\ntip_relief_um = 11\n", "f.toml"))
    report = result.files["report.html"].decode()
    assert "flank modification tip relief C_a (right / left)" in report and "15.0 / 11.0" in report
    assert "lead crowning C_beta" in report
    assert "measured where the flanks are unmodified" in report
    summary = result.files["summary.json"].decode()
    assert '"tip relief C_a": {\n        "right": 15.0,\n        "left": 11.0' in summary


def test_a_span_taken_on_a_modified_flank_is_a_warning_with_what_it_reads():
    from spur_cad.geometry.inspection import inspection_sheet, modification_inspection
    from spur_cad.pipeline import run_job

    job = parse_job(GEAR + "[gear.modifications]\nprofile_slope_um = 20\n", "f.toml")
    sheet = inspection_sheet(job.gear)
    facts = modification_inspection(job.gear, job.modifications, sheet)
    rb = job.gear.base_radius_mm
    l_form = roll_length_mm(rb, 2 * job.gear.form_radius_mm)
    l_tip = roll_length_mm(rb, 2 * job.gear.tip_radius_mm)
    roll = roll_length_mm(rb, 2 * sheet.span_contact_radius_mm)
    removal_um = -20 * (roll - (l_form + l_tip) / 2) / (l_tip - l_form)  # the material grows toward the tip
    assert facts.span_removal_um == pytest.approx((removal_um, removal_um))
    assert facts.span_modified_mm == pytest.approx(sheet.span_measurement_mm - 2 * removal_um / 1000)
    assert not facts.measured_unmodified
    report = run_job(job).files["report.html"].decode()
    assert "warning: the span anvils touch modified flanks" in report


TOOLS = "[tools.finishing]\ndiameter_mm = 'auto'\ncorner_radius_mm = 'auto'\n[tools.roughing]\ndiameter_mm = 'auto'\n"


@pytest.mark.parametrize("mods, line, table, key, added", [
    ("[gear.modifications]\nprofile_slope_um = -40\nhelix_slope_um = 30\n", 14, "gear.modifications",
     "profile_slope_um", 35.0),
    ("[gear.modifications]\nprofile_slope_um = 10\n[gear.modifications.left]\nhelix_slope_um = -52\n", 16,
     "gear.modifications.left", "helix_slope_um", 31.0),
])
def test_slopes_that_add_more_than_the_finish_stock_are_refused_at_the_key(mods, line, table, key, added):
    """Signed slopes add material on one half of the flank (profile slope -40 um: 20 um at the form circle; helix
    slope 30 um: 15 um at the front face); more than [roughing] finish_stock_mm is refused, at the slope's line."""
    text = GEAR + TOOLS + "[roughing]\nfinish_stock_mm = 0.03\n" + mods
    with pytest.raises(JobFileError) as info:
        parse_job(text, "f.toml")
    message = str(info.value)
    assert message.startswith(f"f.toml:{line}: [{table}] ") and "\n" not in message, message
    assert f"add {added:.1f} um of material" in message and "finish_stock_mm = 0.03" in message, message
    assert text.splitlines()[line - 1].startswith(key)
    # as much as roughing leaves is accepted, and a job without tools is not checked
    parse_job(text.replace("finish_stock_mm = 0.03", f"finish_stock_mm = {added / 1000:.4f}"), "f.toml")
    parse_job(GEAR + mods, "f.toml")


@pytest.mark.slow  # a loft of many sections (7 s); the modified solid's own checks stay in the fast tier
def test_a_loft_through_unmodified_sections_has_the_design_volume():
    """A negligible lead crowning (0.001 um) makes the gear a loft sewn from B-spline shells: valid, and its volume is
    the design's (transverse area x face width) within 1e-6, spur and helical."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    from spur_cad.cad.solid import build_gear_shape, front_face_area_mm2, solid_volume_mm3

    for helix_angle_deg in (0, 20):
        text = _hard_job(helix_angle_deg).split("[gear.modifications]")[0]
        job = parse_job(text + "[gear.modifications]\nlead_crowning_um = 0.001\n", "f.toml")
        lofted, _ = build_gear_shape(job.gear, modifications=job.modifications)
        design, _ = build_gear_shape(job.gear)
        assert BRepCheck_Analyzer(lofted).IsValid()
        design_volume = front_face_area_mm2(design) * job.gear.face_width_mm
        assert solid_volume_mm3(lofted) == pytest.approx(design_volume, rel=1e-6)


@pytest.mark.slow  # a solid of every modification (5 s)
def test_the_every_modification_gear_loses_at_least_its_flanks_removal():
    """The 17-tooth gear with every modification: the volume lost is at least the removal integrated over the
    involute flanks (first order: flank area element L / r_b dL dX; the fillets lose material besides) and at most
    the largest removal times a generous tooth surface."""
    from spur_cad.cad.solid import build_gear_shape, front_face_area_mm2, solid_volume_mm3

    job = parse_job(_hard_job(0), "f.toml")
    spec = job.gear
    modified, _ = build_gear_shape(spec, modifications=job.modifications)  # about 3 s (docs/benchmarks.md)
    design, _ = build_gear_shape(spec)
    lost = front_face_area_mm2(design) * spec.face_width_mm - solid_volume_mm3(modified)
    rb = spec.base_radius_mm
    roll = np.linspace(math.sqrt(spec.form_radius_mm**2 - rb**2), math.sqrt(spec.tip_radius_mm**2 - rb**2), 801)
    x = np.linspace(0.0, spec.face_width_mm, 801)
    flanks, largest = 0.0, 0.0
    for side in SIDES_OF_HARD:
        removal = np.array([_expected_removal_mm(spec, HARD_SIDES[side], roll, xi) for xi in x])
        assert removal[:, 0].min() > 0.0  # at the form circle: the fillet, moved by it, loses material too
        flanks += spec.teeth * np.trapezoid(np.trapezoid(removal * roll / rb, roll, axis=1), x)
        largest = max(largest, removal.max())
    surface = 2 * spec.teeth * spec.face_width_mm * (spec.tip_radius_mm - spec.root_radius_mm) * 2  # generous
    assert flanks < lost < largest * surface, (flanks, lost, largest * surface)


def test_an_absurd_loft_is_refused_before_it_is_built():
    from spur_cad.cad.solid import build_gear_shape
    from spur_cad.errors import WorkLimitError

    job = parse_job("[gear]\nteeth = 17\nmodule_mm = 2.0\nface_width_mm = 300\nhelix_angle_deg = 45\n"
                    "[gear.modifications]\nlead_crowning_um = 5\n", "f.toml")
    with pytest.raises(WorkLimitError) as info:
        build_gear_shape(job.gear, modifications=job.modifications)
    message = str(info.value)
    turn_deg = math.degrees(300 * math.tan(math.radians(45)) / (17 * 2.0 / math.cos(math.radians(45)) / 2))
    assert "lofted through about" in message and "limit 1e+06" in message, message
    assert f"{turn_deg:.0f} degrees" in message, message


def _orange_columns(png: bytes) -> np.ndarray:
    """Column indices of the pixels drawn in the modified profile's colour (#ff7f0e)."""
    from matplotlib.image import imread

    rgb = imread(io.BytesIO(png), format="png")[..., :3]
    close = np.abs(rgb - np.array([1.0, 0x7F / 255, 0x0E / 255])).max(axis=-1) < 0.08
    return np.nonzero(close)[1]


def test_the_profile_figure_draws_both_modified_flanks_magnified():
    from spur_cad.geometry.sampling import sample_profile
    from spur_cad.pipeline import modified_flank_samples
    from spur_cad.report.plots import removal_magnification, tooth_space_png

    job = parse_job(_hard_job(0), "f.toml")
    plain = parse_job(_hard_job(0).split("[gear.modifications]")[0], "f.toml")
    samples = sample_profile(job.gear.tooth_space_profile(), 0.001)
    assert modified_flank_samples(plain) is None
    assert len(_orange_columns(tooth_space_png(plain.gear, samples))) == 0
    columns = _orange_columns(tooth_space_png(job.gear, samples, modified_flank_samples(job)))
    middle = 0.5 * (columns.min() + columns.max())
    assert (columns < middle - 50).sum() > 200 and (columns > middle + 50).sum() > 200  # left and right flanks
    depth = job.gear.tip_radius_mm - job.gear.root_radius_mm
    for largest_mm in (0.012, 0.0009, 0.3):
        factor = removal_magnification(job.gear, largest_mm)
        assert 0.4 * 0.04 * depth < factor * largest_mm <= 0.04 * depth
        assert f"{factor:.0e}"[0] in "125"


@pytest.mark.parametrize("example, what", [("flat_gear.toml", "the 3-axis variant"),
                                           ("ring_gear.toml", "an internal gear's ring")])
def test_modifications_are_refused_where_the_cut_would_not_follow_them(example, what):
    """The 3-axis variant and a ring cut the unmodified outline: modifications there are one line at their table."""
    from pathlib import Path

    text = (Path(__file__).resolve().parent.parent / "resources" / "examples" / example).read_text()
    text += "\n[gear.modifications]\nlead_crowning_um = 5\n"
    with pytest.raises(JobFileError) as info:
        parse_job(text, "f.toml")
    message = str(info.value)
    line = text.splitlines().index("[gear.modifications]") + 1
    assert message.startswith(f"f.toml:{line}: [gear.modifications] ") and "\n" not in message, message
    assert what in message and "leave them out" in message
