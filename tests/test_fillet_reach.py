"""Issue 47 (3): the finishing corner's fillet reach on the rotary table follows the mate's SAP (cam.fillet_reach).

References independent of spur_cad's profile and mesh code: the SAP from ISO 21771's formulas (inv alpha_w from the
shift sum, a_w, the mate's tip circle d + 2 (h_a + x) m, the roll length a_w sin alpha_w - sqrt(r_a2^2 - r_b2^2));
what a corner r_t leaves from a brute-force sweep of a trapezoid rack tooth rounded by r_t (shapely opening) rolling
over the blank; the mate's tip corners from the involute function, turned through the mesh.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from shapely import Polygon, contains_xy, distance, points
from shapely.geometry import Point
from shapely.ops import unary_union

from spur_cad.cam.fillet_reach import fillet_reach, largest_reaching_corner_mm
from spur_cad.cam.plan import plan_cam
from spur_cad.cam.recommend import check_tools, recommend_tools
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError
from spur_cad.geometry.mate import GearPair, PairMember
from spur_cad.geometry.sampling import gear_outline
from spur_cad.geometry.spec import GearSpec
from spur_cad.job import parse_job
from spur_cad.pipeline import cam_inputs
from tests import silhouette

M, ALPHA = 1.0, math.radians(20.0)
Z1, X1, RHO = 30, 0.3, 0.38
Z2 = 20
CORNER = 0.44  # above the design fillet's tightest curvature radius (0.401 mm)


def inv(a: float) -> float:
    return math.tan(a) - a


def reference_pair(addendum2: float) -> tuple[float, float, float]:
    """(alpha_w, a_w, SAP diameter of gear 1) after ISO 21771 for the z30 x0.3 gear and a z20 x0 mate."""
    alpha_w = brentq(lambda a: inv(a) - inv(ALPHA) - 2.0 * X1 * math.tan(ALPHA) / (Z1 + Z2), 1e-3, 1.2)
    a_w = M * (Z1 + Z2) / 2.0 * math.cos(ALPHA) / math.cos(alpha_w)
    rb1, rb2 = M * Z1 / 2.0 * math.cos(ALPHA), M * Z2 / 2.0 * math.cos(ALPHA)
    ra2 = M * Z2 / 2.0 + addendum2 * M
    roll = a_w * math.sin(alpha_w) - math.sqrt(ra2**2 - rb2**2)
    return alpha_w, a_w, 2.0 * math.hypot(rb1, roll)


def pair_of(addendum2: float) -> GearPair:
    return GearPair(PairMember(Z1, profile_shift_coefficient=X1), PairMember(Z2, addendum_coefficient=addendum2), M)


def gear(sap_diameter_mm: float = 0.0) -> GearSpec:
    return GearSpec(teeth=Z1, module_mm=M, profile_shift_coefficient=X1, rack_tip_radius_mm=RHO,
                    active_profile_start_diameter_mm=sap_diameter_mm)


def rotate(p: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return p @ np.array([[c, s], [-s, c]])


def brute_force_material(corner_mm: float) -> Polygon:
    """Gear 1 as a rack tooth rounded by `corner_mm` leaves it (spaces -1, 0, 1; space 0 on +y): the blank less the
    rack tooth at 6001 rolls. Rack frame: rolling line y = r, tooth half-width pi m / 4 - x m tan(alpha) there,
    tip at the root circle r - (1.25 - x) m, narrowing by tan(alpha) per unit depth."""
    r = M * Z1 / 2.0
    half = math.pi * M / 4.0 - X1 * M * math.tan(ALPHA)
    tip_y, top_y = r - (1.25 - X1) * M, r + 3.0 * M
    w_tip, w_top = half - (r - tip_y) * math.tan(ALPHA), half + (top_y - r) * math.tan(ALPHA)
    sharp = Polygon([(-w_tip, tip_y), (w_tip, tip_y), (w_top, top_y), (-w_top, top_y)])
    tooth = np.array(sharp.buffer(-corner_mm, quad_segs=64).buffer(corner_mm, quad_segs=64).exterior.coords)
    teeth = [tooth + np.array([k * math.pi * M, 0.0]) for k in (-1, 0, 1)]
    cuts = []
    for phi in np.linspace(-5.0 * M / r, 5.0 * M / r, 6001):
        for t in teeth:
            cuts.append(Polygon(rotate(t - np.array([r * phi, 0.0]), -phi)))
    blank = Point(0.0, 0.0).buffer(r + (1.0 + X1) * M, quad_segs=512)
    return blank.difference(unary_union(cuts))


def mate_corner_path(addendum2: float) -> np.ndarray:
    """The mate's tooth-0 tip corners in gear 1's frame through the mesh (gear 1 turning +-2 pitches), kept within
    1.5 half-pitches of space 0's axis (where brute_force_material is exact)."""
    alpha_w, a_w, _ = reference_pair(addendum2)
    r2 = M * Z2 / 2.0
    ra2 = r2 + addendum2 * M
    alpha_a = math.acos(r2 * math.cos(ALPHA) / ra2)
    psi = math.pi / (2.0 * Z2) + inv(ALPHA) - inv(alpha_a)  # half the tip's angular thickness
    corners = ra2 * np.array([[math.sin(psi), -math.cos(psi)], [-math.sin(psi), -math.cos(psi)]])  # tooth down
    out = []
    for phi in np.linspace(-2.0, 2.0, 4001) * 2.0 * math.pi / Z1:
        mate = rotate(corners, -phi * Z1 / Z2) + np.array([0.0, a_w])  # turning opposite to gear 1
        out.append(rotate(mate, -phi))  # gear 1 turned by phi: its frame turned back
    path = np.concatenate(out)
    angle = np.arctan2(path[:, 0], path[:, 1])
    return path[np.abs(angle) < 1.5 * math.pi / Z1]


def test_sap_is_iso_21771s_and_half_a_millimetre_above_the_form_circle() -> None:
    _, _, sap = reference_pair(0.7)
    spec = gear(sap)
    reach = fillet_reach(spec, pair_of(0.7), CORNER)
    assert reach is not None
    assert reach.sap_diameter_mm == pytest.approx(sap, rel=1e-9)
    assert sap - 2.0 * spec.tooth_space_profile().form_radius_mm >= 0.5
    assert spec.tooth_space_profile().min_fillet_curvature_radius_mm < CORNER


def test_corner_refused_without_the_mate_and_accepted_with_it() -> None:
    _, _, sap = reference_pair(0.7)
    tool = Tool(diameter_mm=1.2, kind="bull_nose", corner_radius_mm=CORNER)
    bare = gear()
    rec = recommend_tools(bare, bare.tip_radius_mm + 0.5, 2.0)
    with pytest.raises(ToolError, match="exceeds finishing_max_corner_radius_mm = 0.4009 mm"):
        check_tools(bare, rec, None, tool)
    mated = gear(sap)
    check_tools(mated, recommend_tools(mated, mated.tip_radius_mm + 0.5, 2.0), None, tool, pair_of(0.7))


@pytest.mark.slow  # two simulated cuts (12 s); the reach limits above stay in the fast tier
def test_what_the_corner_leaves_is_below_the_sap_and_clear_of_the_mates_tips() -> None:
    """Brute force: the swept outline leaves the design's only below the SAP, and the mate's tip corners stay out
    of it; with the design's own rack round the corners stay out too (the mesh reference is sound)."""
    _, _, sap = reference_pair(0.7)
    left, design = brute_force_material(CORNER), brute_force_material(RHO)
    path = mate_corner_path(0.7)
    for material in (left, design):
        assert not contains_xy(material, path[:, 0], path[:, 1]).any()
    # the corners touch the design's involute (within the sweep's and path's sampling) as the pair meshes
    assert float(np.min(distance(design.exterior, points(path)))) < 5e-3
    extra = left.difference(design)  # what the corner leaves beyond the design
    thick = [g for g in getattr(extra, "geoms", [extra]) if g.area > 1e-8]
    assert thick, "the larger corner should leave material in the fillet"
    highest = max(float(np.max(np.hypot(*np.array(g.exterior.coords).T))) for g in thick)
    assert highest <= sap / 2.0, (highest, sap / 2.0)


def test_mate_reaching_deep_refuses_the_corner_its_tips_would_hit() -> None:
    """A mate of addendum 1.2 m: the involute still starts below its SAP, but its tip corners enter what the corner
    leaves (brute force), and check_tools refuses, naming the largest corner that works (not 0)."""
    _, _, sap = reference_pair(1.2)
    spec = gear(sap)
    reach = fillet_reach(spec, pair_of(1.2), CORNER)
    assert reach is not None and reach.form_diameter_mm <= sap
    path = mate_corner_path(1.2)
    assert contains_xy(brute_force_material(CORNER), path[:, 0], path[:, 1]).any()
    tool = Tool(diameter_mm=1.2, kind="bull_nose", corner_radius_mm=CORNER)
    with pytest.raises(ToolError, match=r"mate's tip corners enter .* the largest corner radius that works is 0\.4"):
        check_tools(spec, recommend_tools(spec, spec.tip_radius_mm + 0.5, 2.0), None, tool, pair_of(1.2))
    assert largest_reaching_corner_mm(spec, pair_of(1.2)) >= spec.tooth_space_profile().min_fillet_curvature_radius_mm


JOB = ("[gear]\nteeth = 30\nmodule_mm = 1.0\nprofile_shift_coefficient = 0.3\nrack_tip_radius_mm = 0.38\n"
       "face_width_mm = 2.0\n[stock]\nradial_allowance_mm = 0.3\n"
       "[tools.finishing]\ndiameter_mm = {d}\nkind = \"bull_nose\"\n"
       f"corner_radius_mm = {CORNER}\n[finishing]\nstrategy = \"{{strategy}}\"\ntarget_scallop_mm = 0.005\n"
       "[simulation]\nenabled = false\n")
MATE = "[mate]\nteeth = 20\naddendum_coefficient = 0.7\n"


@pytest.mark.parametrize("strategy, diameter", [("perimeter", 0.9), ("generating", 0.9)])
def test_the_planned_finishing_cuts_the_involute_from_the_sap_and_leaves_the_fillet_clear_of_the_mate(
        strategy: str, diameter: float) -> None:
    """Through the job file and the plan: refused without [mate]; with it, the finishing toolpath's silhouettes
    (tests/silhouette.py, the commanded poses only) never enter the design, leave at most the scallop on the involute
    from the SAP up, and the material they leave in space 0 is clear of the mate's tip corners (brute force above)."""
    text = JOB.replace("{d}", f"{diameter:g}").replace("{strategy}", strategy)
    alone = cam_inputs(parse_job(text, "job.toml"))
    with pytest.raises(SpurCadError, match="corner radius"):
        plan_cam(alone)
    job = parse_job(text + MATE, "job.toml")
    spec, tool = job.gear, job.tools.finishing
    plan = plan_cam(cam_inputs(job))
    path = plan.finishing.toolpath
    rows = path.motion_mask & np.isin(path.space, [0]) & (path.station <= 0)
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, CORNER, 30.0, mask=rows, substeps=4)
    design = Polygon(gear_outline(spec, 1e-5))
    assert silhouette.max_penetration_mm(design, sils) <= 0.5e-3
    involute, _ = silhouette.design_boundary(spec, [0], labels=("involute",))
    _, _, sap = reference_pair(0.7)
    above = np.hypot(involute[:, 0], involute[:, 1]) >= sap / 2.0
    assert silhouette.leftover_mm(involute[above], sils).max() <= 0.005 + 0.5e-3
    left = Point(0.0, 0.0).buffer(spec.tip_radius_mm, quad_segs=512).difference(unary_union(sils))
    path_points = mate_corner_path(0.7)
    near = np.abs(np.arctan2(path_points[:, 0], path_points[:, 1])) < math.pi / Z1  # space 0 and its teeth' halves
    inside = contains_xy(left, path_points[near, 0], path_points[near, 1])
    depth = float(np.max(distance(left.exterior, points(path_points[near][inside])), initial=0.0))
    assert depth <= 0.005 + 0.5e-3  # the involute's own scallop where the corners touch it, nothing from the fillet


@pytest.mark.linuxcnc
def test_the_interpreted_generating_program_agrees(tmp_path) -> None:
    """The generating finishing program as LinuxCNC's rs274 reads it: its cutting passes (fed moves along X alone)
    seen along X never enter the design, leave at most the scallop on the involute from the SAP up, and what they
    leave in space 0 lets the mate's tip corners in by no more than that scallop."""
    from spur_cad.pipeline import build_programs  # noqa: PLC0415 (the posts' imports, only for this test)
    from tests.rs274_helper import run_rs274  # noqa: PLC0415
    from tests.test_post import canonical_straight_moves  # noqa: PLC0415

    job = parse_job(JOB.replace("{d}", "0.9").replace("{strategy}", "generating") + MATE, "job.toml")
    spec, tool = job.gear, job.tools.finishing
    plan = plan_cam(cam_inputs(job))
    programs, _ = build_programs(job, plan)
    (tmp_path / "finishing.ngc").write_text(programs["finishing"].text)
    ok, canon, messages = run_rs274(tmp_path / "finishing.ngc", timeout_s=300)
    assert ok, messages
    passes = np.array([end for feed, _, _, start, end in canonical_straight_moves(canon)
                       if feed and start is not None and np.allclose(start[1:], end[1:], atol=1e-9)
                       and start[0] != end[0]])
    assert len(passes) % Z1 == 0
    first = passes[: len(passes) // Z1]  # every space runs the same passes, space 0's first (A relative to 0)
    sils = list(silhouette.place_silhouettes(first[:, 1], first[:, 2], first[:, 3], tool.diameter_mm, CORNER, 30.0))
    assert silhouette.max_penetration_mm(Polygon(gear_outline(spec, 1e-5)), sils) <= 0.5e-3
    involute, _ = silhouette.design_boundary(spec, [0], labels=("involute",))
    _, _, sap = reference_pair(0.7)
    above = np.hypot(involute[:, 0], involute[:, 1]) >= sap / 2.0
    assert silhouette.leftover_mm(involute[above], sils).max() <= 0.005 + 0.5e-3
    left = Point(0.0, 0.0).buffer(spec.tip_radius_mm, quad_segs=512).difference(unary_union(sils))
    path_points = mate_corner_path(0.7)
    near = np.abs(np.arctan2(path_points[:, 0], path_points[:, 1])) < math.pi / Z1
    inside = contains_xy(left, path_points[near, 0], path_points[near, 1])
    assert float(np.max(distance(left.exterior, points(path_points[near][inside])), initial=0.0)) <= 0.005 + 0.5e-3


@pytest.mark.slow
def test_spur_cads_simulation_of_the_whole_job_shows_no_gouge() -> None:
    """The whole job (generating, with [mate]) through run_job and spur_cad's own simulation: no gouge, the involute
    within the target scallop (5 um), the fillet left thicker than that (what the larger corner leaves)."""
    from spur_cad.pipeline import run_job  # noqa: PLC0415 (the whole pipeline, only for this test)

    text = JOB.replace("{d}", "0.9").replace("{strategy}", "generating").replace("enabled = false", "enabled = true")
    text = text.replace("[tools.finishing]", "[tools.roughing]\ndiameter_mm = 0.3\n[tools.finishing]")
    simulated = run_job(parse_job(text + MATE, "job.toml")).simulation
    assert simulated.enabled and simulated.max_gouge_mm <= 0.5e-3

    def leftover(feature: str) -> float:
        found = [simulated.feature(f"{side} {feature}") for side in ("left", "right")]
        assert all(f is not None for f in found)
        return max(f.max_leftover_mm for f in found if f is not None)

    assert leftover("involute") <= 0.005 + 0.5e-3
    assert leftover("fillet") > 0.005


def test_a_sharp_rack_and_a_corner_no_rack_carries() -> None:
    """A sharp rack (its corner's trochoid fillet as tight as 0.057 mm) with the mate takes a 0.2 mm corner (the rack
    with that round leaves the involute below the SAP, clear of the mate); a corner beyond what any rack tooth
    carries is refused naming the largest that works, which is not 0."""
    _, _, sap = reference_pair(0.7)
    sharp = GearSpec(teeth=Z1, module_mm=M, profile_shift_coefficient=X1, active_profile_start_diameter_mm=sap)
    reach = fillet_reach(sharp, pair_of(0.7), 0.2)
    assert reach is not None and reach.fits
    assert reach.form_diameter_mm > 2.0 * sharp.tooth_space_profile().form_radius_mm
    assert largest_reaching_corner_mm(sharp, pair_of(0.7)) > 0.2
    tool = Tool(diameter_mm=1.2, kind="bull_nose", corner_radius_mm=0.55)
    with pytest.raises(ToolError, match=r"carries a tip round that large .* the largest corner radius that works is "
                                        r"0\.4[0-9]{2} mm$"):
        check_tools(sharp, recommend_tools(sharp, sharp.tip_radius_mm + 0.5, 2.0), None, tool, pair_of(0.7))
