"""Internal gears in the 3-axis variant: the example ring's (z 60, m 2, 20-tooth cutter, 18-tooth pinion) LinuxCNC
programs through rs274, the tool-centre path it interprets checked at full depth against the exact ring outline
(profile.py's segments, not the fitted arcs): no gouge, leftover on the active involute within the scallop target,
a root fillet of the tool radius at least; the roughing clears the hole down to the finish stock."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.three_axis import ROUGHING_ARC_SEGMENTS, check_three_axis
from spur_cad.cam.three_axis_ring import ring_finishing_toolpath, ring_roughing_toolpath
from spur_cad.cam.tools import ToolError
from spur_cad.job import load_job
from spur_cad.post import ProgramInfo, post_program
from spur_cad.post.settings import PostSettings
from tests.rs274_helper import canon_args, run_rs274
from tests.test_three_axis import GOUGE_MM, SCALLOP_TARGET_MM, TOLERANCE_MM, exact_outline, flat, interpreted_path

RING_JOB = Path(__file__).resolve().parents[1] / "resources" / "examples" / "ring_gear.toml"


def ring_job():
    return load_job(RING_JOB)


def pinion_tip_contact_radius_mm(spec) -> float:
    """The ring radius where the mating pinion's tip (no shift, addendum h_a* m) meets the line of action, found
    geometrically: the standard internal mesh (a = m (z - z_1) / 2, alpha_w = alpha: the example has no shift nor
    allowance) with the line of action through the pitch point, intersected with the pinion's tip circle."""
    assert spec.profile_shift_coefficient == 0.0 and spec.thickness_allowance_mm == 0.0
    m, z, z1, alpha = spec.module_mm, spec.teeth, spec.mating_pinion_teeth, math.radians(spec.pressure_angle_deg)
    a = m * (z - z1) / 2.0
    pinion_centre, pitch = np.array([0.0, a]), np.array([0.0, m * z / 2.0])
    direction = np.array([math.cos(alpha), math.sin(alpha)])
    tip = m * z1 / 2.0 + spec.addendum_coefficient * m
    # |pitch + s direction - pinion_centre| = tip: s^2 + 2 s (d . w) + |w|^2 - tip^2 = 0, w = pitch - pinion_centre
    w = pitch - pinion_centre
    half_b, c = float(direction @ w), float(w @ w - tip * tip)
    points = [pitch + s * direction for s in (-half_b + math.sqrt(half_b**2 - c), -half_b - math.sqrt(half_b**2 - c))]
    return max(float(np.hypot(*p)) for p in points)  # the end of contact toward the ring's root


def posted(path, name: str, tmp_path) -> tuple[Path, str]:
    text = post_program(path, PostSettings(), ProgramInfo(name, (), writes_a=False)).text
    target = tmp_path / f"{name}.ngc"
    target.write_text(text)
    return target, text


@pytest.mark.linuxcnc
def test_ring_finishing_cuts_the_exact_outline_with_arcs(tmp_path):
    job = ring_job()
    spec, tool = job.gear, job.tools.finishing
    radius = tool.diameter_mm / 2.0
    root = check_three_axis(spec, tool, None)
    path, levels, _ = ring_finishing_toolpath(spec, tool, Machine(), TOLERANCE_MM)
    program, text = posted(path, "finishing", tmp_path)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    centres, arcs = interpreted_path(canon)
    assert arcs > 0 and "G2" in text and "G3" in text
    assert min(levels) <= -spec.face_width_mm  # through the face width
    outline, labels = exact_outline(spec)
    radii = np.hypot(*outline.T)
    clearance, _ = cKDTree(centres).query(outline)
    gouge = radius - clearance  # > 0: the tool circle reaches into the ring
    assert gouge.max() <= GOUGE_MM, f"gouge {gouge.max() * 1000:.2f} um"
    active_start = pinion_tip_contact_radius_mm(spec)
    assert abs(active_start - root.active_start_radius_mm) < 1e-6  # the plan's figure, found another way
    involute = labels == "involute"
    assert (gouge[involute & (radii <= root.form_radius_mm)]).max() <= GOUGE_MM
    active = involute & (radii <= active_start)
    leftover = clearance[active] - radius
    assert leftover.max() <= SCALLOP_TARGET_MM, f"leftover {leftover.max() * 1000:.2f} um on the active involute"
    # the root: no tool circle beyond the root circle, and every point left beyond the active profile (the spaces'
    # outer ends) is touched by a whole tool circle of radius r inside the cut: its fillet is r at least
    assert (np.hypot(*centres.T) + radius).max() <= spec.root_radius_mm + GOUGE_MM
    beyond = outline[radii > active_start]
    _, nearest = cKDTree(centres).query(beyond)
    toward = beyond - centres[nearest]
    boundary = centres[nearest] + radius * toward / np.linalg.norm(toward, axis=1)[:, None]
    assert cKDTree(centres).query(boundary)[0].min() >= radius - GOUGE_MM


def helix_arcs(canon: list[str]) -> int:
    """ARC_FEED calls whose end Z differs from their start's (helical)."""
    z, count = math.nan, 0
    for line in canon:
        if line.startswith(("STRAIGHT_FEED", "STRAIGHT_TRAVERSE")):
            z = canon_args(line)[2]
        elif line.startswith("ARC_FEED"):
            end_z = canon_args(line)[5]
            count += end_z != z
            z = end_z
    return count


@pytest.mark.linuxcnc
@pytest.mark.parametrize("inner_diameter_mm", [0.0, 60.0], ids=["solid", "bore_60"])
def test_ring_roughing_clears_the_hole_down_to_the_finish_stock(inner_diameter_mm, tmp_path):
    job = ring_job()
    spec, tool, params = job.gear, job.tools.roughing, RoughingParams()
    radius = tool.diameter_mm / 2.0
    path, levels, offsets = ring_roughing_toolpath(spec, tool, Machine(), params, inner_diameter_mm / 2.0)
    program, _ = posted(path, "roughing", tmp_path)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    assert (helix_arcs(canon) > 0) == (inner_diameter_mm == 0.0)  # a solid blank is entered by a helix
    assert -np.diff([0.0, *levels]).max() <= params.max_level_depth_fraction * tool.diameter_mm + 1e-9
    centres, _ = interpreted_path(canon, spacing_mm=0.02)  # its distance from the outline then errs < 0.1 um
    outline, _ = exact_outline(spec)
    clearance, _ = cKDTree(centres).query(outline)
    chord = offsets[0] * (1.0 - math.cos(math.pi / (4 * ROUGHING_ARC_SEGMENTS)))  # the buffers' corner chords
    assert clearance.min() - radius >= params.finish_stock_mm - chord - 0.0005
    # cleared: every point of the hole at least a tool diameter plus the stock from the outline (a tool centre
    # could sit there) and outside the bore lies within the tool radius of the interpreted centres
    grid = np.mgrid[-60.0:60.0:0.25, -60.0:60.0:0.25].reshape(2, -1).T
    far = cKDTree(outline).query(grid)[0] >= tool.diameter_mm + params.finish_stock_mm
    inside = np.hypot(*grid.T) < spec.tip_radius_mm
    material = inside & far & (np.hypot(*grid.T) >= inner_diameter_mm / 2.0)
    reach = cKDTree(centres).query(grid[material])[0]
    assert reach.max() <= radius + 1e-3, f"material left {reach.max() - radius:.3f} mm from the tool"
    # passes step_over x D apart: neighbouring offsets
    assert np.diff(offsets).max() <= params.step_over_fraction * tool.diameter_mm + 1e-9


def test_a_tool_whose_fillet_reaches_the_active_profile_is_refused_in_one_line():
    spec = ring_job().gear
    with pytest.raises(ToolError) as caught:
        check_three_axis(spec, flat(2.4, 2), None)
    words = str(caught.value)
    assert "\n" not in words and "largest tool radius that works is 1.065 mm" in words
    assert "18-tooth mating pinion" in words and caught.value.field == "diameter_mm"
    without_pinion = dataclasses.replace(spec, mating_pinion_teeth=0)
    with pytest.raises(ToolError, match=r"set by the 20-tooth shaper cutter's mesh"):
        check_three_axis(without_pinion, flat(2.4, 2), None)
    assert check_three_axis(spec, flat(2.0, 2), None).fillet_radius_mm >= 1.0


@pytest.mark.slow
def test_the_ring_example_runs_through_the_pipeline_on_three_axes():
    """Programs without an A axis, arcs; the cut simulated and graded (an ideal machine: class 1), the root's
    leftover reported as the flat end mill's reach."""
    from spur_cad.pipeline import run_job

    result = run_job(ring_job())
    finishing, roughing = result.files["finishing.ngc"].decode(), result.files["roughing.ngc"].decode()
    assert "G2 " in finishing and "G3 " in finishing and "gear axis = Z" in finishing
    for program in (finishing, roughing):
        assert not [line for line in program.splitlines() if not line.startswith("(") and " A" in line]
    assert result.simulation.enabled and result.simulation.max_gouge_mm <= GOUGE_MM
    assert result.grading is not None and result.grading.overall_class == 1
    assert not [w for w in result.warnings if "not simulated" in w]
    report = result.files["report.html"].decode()
    assert "flat end mill cannot reach (the cutter-generated fillet is tighter than its radius)" in report


def test_the_ring_root_thickness_is_the_tooth_between_two_spaces():
    """At the ring's generated form circle the tooth's chord is the involute's (textbook arc thickness of an internal
    gear at that radius, as a chord); a tool that follows the fillet (r 0.3 < its 0.54 mm) leaves it, a D 2 leaves
    more there and at mid-fillet."""
    from spur_cad.cam.three_axis_root import root_thickness

    spec = ring_job().gear
    form = spec.tooth_space_profile().form_radius_mm
    arc = 2 * form * (math.pi / spec.teeth - spec.space_width_mm / (2 * spec.reference_radius_mm)
                      - (math.tan(math.radians(spec.pressure_angle_deg)) - math.radians(spec.pressure_angle_deg))
                      + math.tan(math.acos(spec.base_radius_mm / form)) - math.acos(spec.base_radius_mm / form))
    chord = 2 * form * math.sin(arc / (2 * form))
    follows, wide = root_thickness(spec, 0.3), root_thickness(spec, 1.0)
    assert abs(follows.rack_form_thickness_mm - chord) < 2e-4 and abs(follows.form_thickness_mm - chord) < 2e-4
    assert wide.form_thickness_mm > chord + 0.05 and wide.fillet_thickness_mm > wide.rack_fillet_thickness_mm + 0.1
