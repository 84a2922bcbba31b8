"""Acceptance of the toolpaths by an independent 2-D check (tests/silhouette.py): every
programmed pose's tool silhouette, turned into the part frame by the commanded A, against the
designed gear. Nothing here uses the generators' geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Polygon

from spur_cad.cam.finishing import finishing_toolpath
from spur_cad.cam.ir import Feature, MoveKind
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.roughing import estimated_roughing_moves, roughing_toolpath
from spur_cad.cam.strategies import FinishingParams
from spur_cad.geometry import gear_outline
from tests import silhouette
from tests.gears import CAM_GEARS, spec_of, tools_for
from tests.tiers import sweep

HALF_MICRON = 0.5e-3
SCALLOP = 0.005
TOOL_LENGTH = 30.0


def _roughed(spec, tool, strategy: str):
    """The roughing the checks below read: allowance 0.1 m, finish stock 0.005 m, blank 0.5 mm above the tips."""
    params = RoughingParams(flank_allowance_mm=0.1 * spec.module_mm, finish_stock_mm=0.005 * spec.module_mm,
                            strategy=strategy)
    blank = spec.tip_radius_mm + 0.5
    return params, blank, roughing_toolpath(spec, tool, Machine(), params, blank)


def _spaces(teeth: int) -> list[int]:
    return [0, 1, teeth - 1]


@pytest.fixture(scope="module")
def design_polygons():
    return {name: Polygon(gear_outline(spec_of(name), 1e-5)) for name in CAM_GEARS}


@pytest.mark.parametrize("name", CAM_GEARS)
def test_finishing_never_gouges_and_leaves_at_most_the_scallop(name, design_polygons):
    spec = spec_of(name)
    _, tool = tools_for(name)
    path = finishing_toolpath(spec, tool, Machine(), FinishingParams(strategy="perimeter", target_scallop_mm=SCALLOP,
                                                                      step_over_mm=spec.face_width_mm),
                              spec.tip_radius_mm + 0.5)
    spaces = _spaces(spec.teeth)
    rows = path.motion_mask & (path.station == 0) & np.isin(path.space, spaces)
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, tool.effective_corner_radius_mm, TOOL_LENGTH,
                                                mask=rows)
    assert silhouette.max_penetration_mm(design_polygons[name], sils) <= HALF_MICRON
    points, labels = silhouette.design_boundary(spec, spaces)
    leftover = silhouette.leftover_mm(points, sils)
    assert leftover.max() <= SCALLOP + HALF_MICRON, (leftover.max(), labels[int(np.argmax(leftover))])


@pytest.mark.parametrize("name", CAM_GEARS)
def test_finishing_cuts_every_flank_downward(name):
    spec = spec_of(name)
    _, tool = tools_for(name)
    path = finishing_toolpath(spec, tool, Machine(),
                              FinishingParams(strategy="perimeter", target_scallop_mm=SCALLOP, step_over_mm=2.0),
                              spec.tip_radius_mm + 0.5)
    for feature in (Feature.RIGHT_FLANK, Feature.LEFT_FLANK):
        runs = silhouette.cutting_direction_ok(path, feature)
        assert len(runs) == spec.teeth * len(np.unique(path.station)) and all(runs)


@pytest.mark.parametrize("strategy", ["flank", "levels"])
@pytest.mark.parametrize("name", sweep(CAM_GEARS, fast=["reference_z23_m4", "undercut_z8"]))
def test_roughing_respects_finish_stock_and_flank_allowance(name, strategy, design_polygons):
    spec = spec_of(name)
    tool, finishing = tools_for(name)
    params, blank, path = _roughed(spec, tool, strategy)
    rows = path.motion_mask & (path.space == 0)
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, 0.0, TOOL_LENGTH, mask=rows)
    # Never closer than the finish stock to the design: no reach into the design grown by it.
    grown = design_polygons[name].buffer(params.finish_stock_mm - 1e-6, quad_segs=256)
    assert silhouette.max_penetration_mm(grown, sils) <= HALF_MICRON
    # At most the flank allowance left on the flanks above the lowest pass at A = 0, read from the toolpath itself
    # (space 0 is cut at A = 0, so such a pass's Z is its height on the space axis; the flank strategy's passes
    # at other turns reach no lower on the flanks than its middle slot's lowest level).
    lowest = float(path.z[rows & (path.feature == Feature.LEVEL) & (path.a == 0.0)].min())
    points, labels = silhouette.design_boundary(spec, [0], labels=("fillet", "involute"))
    above = points[:, 1] >= lowest
    leftover = silhouette.leftover_mm(points[above], sils)
    assert leftover.max() <= params.flank_allowance_mm + HALF_MICRON
    # What stays below the lowest pass is within what the finishing tool's bottom can take when it
    # plunges: A_p = half its flat width (the method's catalogue rule).
    assert lowest - spec.root_radius_mm <= 0.5 * finishing.flat_width_mm + 1e-9


def _left_above_tip_mm(spec, path, tool, blank: float) -> float:
    """How far the blank roughing leaves over the tooth between spaces 0 and 1 stands above the tip circle:
    a polar grid (0.005 mm radially) from the tip circle to the blank over that tooth's whole pitch, against
    the tool silhouettes of spaces 0 and 1 (space 0's moves include that tooth's tip passes)."""
    rows = path.motion_mask & np.isin(path.space, [0, 1])
    union = shapely.union_all(silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, 0.0, TOOL_LENGTH,
                                                                   mask=rows))
    half_pitch = math.pi / spec.teeth
    axis = silhouette.to_part_frame(0.0, 1.0, -math.degrees(half_pitch))  # the tooth is up at A = -half a pitch
    centre = math.atan2(axis[0], axis[1])
    radius, angle = np.meshgrid(np.linspace(spec.tip_radius_mm, blank, 101),
                                centre + np.linspace(-half_pitch, half_pitch, 801))
    left = ~shapely.contains_xy(union, (radius * np.sin(angle)).ravel(), (radius * np.cos(angle)).ravel())
    return float((radius.ravel()[left] - spec.tip_radius_mm).max(initial=0.0))


@pytest.mark.parametrize("strategy", ["flank", "levels"])
@pytest.mark.parametrize("name", sweep(CAM_GEARS, fast=["reference_z23_m4", "undercut_z8"]))
def test_roughing_takes_the_blank_down_to_the_tip_circle_plus_the_finish_stock(name, strategy, design_polygons):
    """The tip passes never come nearer the design than the finish stock, and leave over the tooth at most the
    finish stock plus the height of the flat tool bottom over the circle at its passes' edge (by flanks, beside the
    tooth's corners, at most the flank allowance the runs leave there), within what the finishing tool takes off
    the tips in one pass (a slot: half its diameter)."""
    spec = spec_of(name)
    tool, finishing = tools_for(name)
    params, blank, path = _roughed(spec, tool, strategy)
    tips = path.motion_mask & (path.feature == Feature.TIP)
    assert np.count_nonzero(tips & (path.space == 0)) >= 1  # at least one pass along X over the land
    floor = spec.tip_radius_mm + params.finish_stock_mm
    assert path.z[tips].min() == pytest.approx(floor)
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, 0.0, TOOL_LENGTH, mask=tips)
    grown = design_polygons[name].buffer(params.finish_stock_mm - 1e-6, quad_segs=256)
    assert silhouette.max_penetration_mm(grown, sils) <= HALF_MICRON
    edge = np.abs(path.y[tips]).max() + tool.diameter_mm / 2.0
    left = _left_above_tip_mm(spec, path, tool, blank)
    # by flanks the tip passes span the land from tip edge to tip edge: beside the tooth's corners the runs leave
    # what lies within the flank allowance of the design, as on the flanks
    beside = params.flank_allowance_mm if strategy == "flank" else 0.0
    assert left <= max(math.hypot(edge, floor) - spec.tip_radius_mm, beside) + 0.005
    assert left <= 0.5 * finishing.diameter_mm
    # without the tip passes the whole allowance stands there (levels); by flanks, no less than with them (the runs
    # take what they can of the lands beside the tip edges, all of a land as narrow as z8 m2's; two-stage
    # roughing's bottom program leaves the lands to the larger tool)
    without = roughing_toolpath(spec, tool, Machine(), params, blank, tips=False)
    if strategy == "levels":
        assert _left_above_tip_mm(spec, without, tool, blank) == pytest.approx(0.5)
    else:
        assert _left_above_tip_mm(spec, without, tool, blank) >= left  # z8 m2: the runs take its narrow land
    # the work limit's estimate still bounds the moves, with several cuts over the tips on a large blank
    for radius in (blank, blank + 3.0):
        moves = len(roughing_toolpath(spec, tool, Machine(), params, radius))
        assert estimated_roughing_moves(spec, tool, params, radius)[0] >= moves


@pytest.mark.parametrize("name", CAM_GEARS)
def test_rapids_never_touch_the_stock(name):
    spec = spec_of(name)
    roughing, finishing = tools_for(name)
    blank = spec.tip_radius_mm + 0.5
    machine = Machine()
    params = RoughingParams(flank_allowance_mm=0.1 * spec.module_mm, finish_stock_mm=0.005 * spec.module_mm,
                            strategy="levels")
    for path, tool in ((roughing_toolpath(spec, roughing, machine, params, blank), roughing),
                       (finishing_toolpath(spec, finishing, machine,
                                           FinishingParams(strategy="perimeter", step_over_mm=2.0), blank),
                        finishing)):
        assert np.any(path.kind == MoveKind.RAPID)
        clearance = silhouette.rapids_clear_of_circle(path, tool.diameter_mm, tool.effective_corner_radius_mm,
                                                      TOOL_LENGTH,
                                                      blank)
        assert clearance >= machine.clearance_mm - 1e-6


@pytest.mark.parametrize("name", ["reference_z23_m4", "undercut_z8"])
def test_along_x_strategy_is_as_safe_and_warns_about_marks(name, design_polygons):
    spec = spec_of(name)
    _, tool = tools_for(name)
    path = finishing_toolpath(spec, tool, Machine(), FinishingParams(strategy="along_x", target_scallop_mm=SCALLOP),
                              spec.tip_radius_mm + 0.5)
    assert any("parallel to the contact lines" in w for w in path.warnings)
    rows = path.motion_mask & (path.space == 0)
    sils = silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, tool.effective_corner_radius_mm, TOOL_LENGTH,
                                                mask=rows)
    assert silhouette.max_penetration_mm(design_polygons[name], sils) <= HALF_MICRON
    points, _ = silhouette.design_boundary(spec, [0])
    assert silhouette.leftover_mm(points, sils).max() <= SCALLOP + HALF_MICRON
    # Every pass along X covers the whole face width plus the tool radius at both ends.
    passes = (path.kind == MoveKind.LINEAR) & (path.x != np.concatenate([[path.x[0]], path.x[:-1]]))
    assert path.x[passes].min() < -tool.diameter_mm / 2
    assert path.x[passes].max() > spec.face_width_mm + tool.diameter_mm / 2


@pytest.mark.parametrize("strategy", ["flank", "levels"])
@pytest.mark.parametrize("name", sweep(CAM_GEARS, fast=["reference_z23_m4", "undercut_z8"]))
def test_roughing_leaves_no_material_beyond_the_flank_allowance(name, strategy, design_polygons):
    """The material itself, not only the design points' distance to the tools: of space 0's sector of the blank
    above the lowest pass at A = 0, what no silhouette of spaces 0, 1 and z - 1 (their tip lands' passes
    included) covered lies within the flank allowance of the design (+1 um)."""
    spec = spec_of(name)
    tool, _ = tools_for(name)
    params, blank, path = _roughed(spec, tool, strategy)
    rows = path.motion_mask & np.isin(path.space, [0, 1, spec.teeth - 1])
    union = shapely.union_all(silhouette.silhouettes_in_part_frame(path, tool.diameter_mm, 0.0, TOOL_LENGTH,
                                                                   mask=rows))
    lowest = float(path.z[path.motion_mask & (path.space == 0) & (path.feature == Feature.LEVEL)
                          & (path.a == 0.0)].min())
    half = math.pi / spec.teeth
    angles = np.linspace(-half, half, 129)
    sector = Polygon(np.concatenate([[[0.0, 0.0]], 2.0 * blank * np.stack([np.sin(angles), np.cos(angles)], axis=1)]))
    stock = shapely.Point(0.0, 0.0).buffer(blank, quad_segs=1024).intersection(sector)
    stock = stock.intersection(shapely.box(-2.0 * blank, lowest, 2.0 * blank, 2.0 * blank))
    left = stock.difference(union).difference(design_polygons[name].buffer(params.flank_allowance_mm + 1e-3,
                                                                             quad_segs=64))
    assert left.area <= 1e-4, (left.area, left.bounds)
