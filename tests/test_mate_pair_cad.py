"""The pair placed at the centre distance and meshing (spur_cad.cad.pair): the gear's and the mate's outlines
neither overlap nor stand apart by more than they should: in the symmetric position each flank of the mate's tooth
is half the normal backlash j_bn = j_wt cos(alpha_wt) cos(beta_b) from the gear's (ISO 21771), found here from the
transverse outlines (shapely) and, slow tier, from the OCP solids themselves; and the assembly STEP reads back as
two solids."""

from __future__ import annotations

import math

import numpy as np
import pytest
from OCP.gp import gp_Pnt
from shapely.geometry import Point, Polygon

from spur_cad.cad.pair import mate_placement, mate_spec, pair_shapes, pair_step_bytes
from spur_cad.geometry.mate import pair_facts
from spur_cad.geometry.sampling import gear_outline
from spur_cad.job import parse_job

GEAR = ("[gear]\nteeth = 30\nmodule_mm = 1.0\nface_width_mm = 4.0\nrack_tip_radius_mm = 0.38\n"
        "thickness_allowance_mm = 0.04\n")
RING = ("[gear]\nteeth = 60\nmodule_mm = 1.0\nface_width_mm = 4.0\nrack_tip_radius_mm = 0.3\ninternal = true\n"
        "shaper_cutter_teeth = 20\nrim_outer_diameter_mm = 70.0\naddendum_coefficient = 0.9\n")
CASES = {
    "external": GEAR + "[mate]\nteeth = 17\nprofile_shift_coefficient = 0.2\nthickness_allowance_mm = 0.02\n",
    "external, no backlash": GEAR.replace("thickness_allowance_mm = 0.04\n", "") + "[mate]\nteeth = 41\n",
    "ring mate": GEAR + "[mate]\nteeth = 60\ninternal = true\nprofile_shift_coefficient = -0.6\n"
                        "thickness_allowance_mm = 0.02\n",
    "ring gear": RING + "[mate]\nteeth = 30\nthickness_allowance_mm = 0.02\n",
}
TOLERANCE_MM = 1e-5


def _placed(points: np.ndarray, trsf) -> np.ndarray:
    """Gap-frame points (the front face: machine Y = x, Z = y) moved by the mate's placement."""
    moved = [gp_Pnt(0.0, float(x), float(y)).Transformed(trsf) for x, y in points]
    return np.array([(p.Y(), p.Z()) for p in moved])


@pytest.mark.parametrize("case", list(CASES))
def test_the_placed_outlines_stand_half_the_normal_backlash_apart(case):
    job = parse_job(CASES[case], "pair.toml")
    facts = pair_facts(job.pair)
    gear = gear_outline(job.gear, TOLERANCE_MM)
    mate = _placed(gear_outline(mate_spec(job.gear, job.pair), TOLERANCE_MM), mate_placement(job.pair))
    gear_poly, mate_poly = Polygon(gear), Polygon(mate)
    gap = gear_poly.exterior.distance(mate_poly.exterior)
    assert gap == pytest.approx(facts.normal_backlash_mm / 2.0, abs=3 * TOLERANCE_MM)
    if job.pair.mate.internal:  # the pinion inside the ring's hole
        assert mate_poly.contains(gear_poly)
    elif job.pair.gear.internal:
        assert gear_poly.contains(mate_poly)
    else:
        assert not gear_poly.intersects(mate_poly) or gear_poly.intersection(mate_poly).area < 1e-12
        assert mate_poly.contains(Point(0.0, facts.centre_distance_mm))  # the mate sits at Z = +a
    if case == "external, no backlash":
        assert facts.normal_backlash_mm == pytest.approx(0.0, abs=1e-12) and gap < 3 * TOLERANCE_MM


@pytest.mark.slow
def test_the_solids_mesh_and_the_assembly_step_holds_both(tmp_path):
    """OCP: the two solids (helical, 15 deg, opposite hands) share no volume and their distance is half the normal
    backlash through the whole face width; the assembly STEP reads back as two solids."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from tests.ocp_helper import read_step

    job = parse_job(CASES["external"].replace("face_width_mm = 4.0", "face_width_mm = 4.0\nhelix_angle_deg = 15.0"),
                    "pair.toml")
    gear, mate = pair_shapes(job.gear, job.pair)
    distance = BRepExtrema_DistShapeShape(gear, mate)
    distance.Perform()
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(BRepAlgoAPI_Common(gear, mate).Shape(), props)
    assert distance.Value() == pytest.approx(pair_facts(job.pair).normal_backlash_mm / 2.0, abs=1e-5)
    assert abs(props.Mass()) < 1e-9
    path = tmp_path / "pair.step"
    path.write_bytes(pair_step_bytes(job.gear, job.pair, timestamp="2026-01-01T00:00:00"))
    shape = read_step(path)
    explorer, solids = TopExp_Explorer(shape, TopAbs_SOLID), 0
    while explorer.More():
        solids += 1
        explorer.Next()
    assert solids == 2 and b"'mate'" in path.read_bytes() and math.isfinite(distance.Value())


@pytest.mark.slow
def test_the_docs_pair_example_runs_as_written():
    from tests.test_docs_examples import python_blocks

    (block,) = python_blocks("docs/cad.md", "pair_step_bytes(job.gear")
    namespace: dict = {}
    exec(compile(block, "docs/cad.md", "exec"), namespace)
    assert namespace["assembly"].startswith(b"ISO-10303-21;") and not namespace["mate"].IsNull()
