"""Holding a through-cut gear in the 3-axis variant ([three_axis], docs/cam.md): holding tabs or an onion skin.

By default the gear is cut through (face width plus the break-through) and held on its bore or a fixture. A
**tab** leaves a bridge of material `tab_width_mm` wide, `tab_height_mm` high from the bottom face, from a tooth's
tip out to the blank: below the tab's top the tool centre stays out of a band along the tooth's centre line, as wide
as the tab plus the tool's diameter (where the path enters the band it rises to the tab's top, follows the same
lines and arcs there and comes down where it leaves). The tabs sit on `tabs` tips spread evenly round the gear.
An **onion skin** stops every level `onion_skin_mm` above the bottom face: the gear stays joined to the skin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from spur_cad.cam.machine import MachineError
from spur_cad.geometry.outline2d import Arc2D, Line2D, Segment2D
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key

_GROUP = "3-axis"


@dataclass(frozen=True)
class ThreeAxisSection:
    """[three_axis]: how a gear cut lying flat ([machine] axes = 3) stays held once cut through."""

    tabs: int = key(0, low=0, high=24, label="HoldingTabs", group=_GROUP,
                    meaning="holding tabs: this many tips, spread evenly, keep a bridge of material to the blank "
                            "(tab_width_mm wide, tab_height_mm high from the bottom face); 0: none, the blank held "
                            "on its bore or a fixture")
    tab_width_mm: float = key(2.0, unit="mm", low=0.1, high=50.0, label="TabWidth", group=_GROUP,
                              meaning="width of a holding tab (across the tooth's centre line)")
    tab_height_mm: float = key(1.0, unit="mm", low=0.1, high=50.0, label="TabHeight", group=_GROUP,
                               meaning="height of a holding tab from the bottom face (below the face width)")
    onion_skin_mm: float = key(0.0, unit="mm", low=0.0, high=20.0, label="OnionSkin", group=_GROUP,
                               meaning="a skin this thick left on the bottom face: every level stops this far above "
                                       "it (no break-through); 0: cut through")

    def __post_init__(self) -> None:
        """Every key in its range and one way of holding, checked once when the section is made (MachineError
        naming the key)."""
        check_section(self, "three_axis", MachineError)
        if self.tabs and self.onion_skin_mm > 0.0:
            raise MachineError("[three_axis] tabs and onion_skin_mm both hold the gear: give one of them",
                               field="onion_skin_mm", section="three_axis")

    def validate(self, face_width_mm: float) -> None:
        """The heights against the gear's face width: checked where the section meets the gear (the job loader,
        CamInputs), not again below."""
        for name in ("tab_height_mm", "onion_skin_mm"):
            if getattr(self, name) >= face_width_mm and (name != "tab_height_mm" or self.tabs):
                raise MachineError(f"[three_axis] {name} = {getattr(self, name):g} mm must be below the face "
                                   f"width {face_width_mm:g} mm", field=name, section="three_axis")


@dataclass(frozen=True)
class TabBand:
    """Where the tool centre may not go below a tab's top: within `half_width_mm` of the ray from the gear axis
    along `direction` (a tooth's centre line), on its outer side."""

    direction: tuple[float, float]  # unit vector
    half_width_mm: float

    def holds(self, point: tuple[float, float]) -> bool:
        ux, uy = self.direction
        return ux * point[0] + uy * point[1] > 0.0 and abs(ux * point[1] - uy * point[0]) < self.half_width_mm


def tab_bands(spec: GearSpec, holding: ThreeAxisSection, tool_radius_mm: float) -> list[TabBand]:
    """The bands of the job's tabs for a tool of `tool_radius_mm`: on tips k z / tabs (k = 0, 1, ...), tooth 0
    between tooth spaces 0 (on +Y) and 1."""
    bands = []
    for i in range(holding.tabs):
        tooth = round(i * spec.teeth / holding.tabs)
        angle = math.pi / 2.0 + math.pi / spec.teeth + tooth * 2.0 * math.pi / spec.teeth
        bands.append(TabBand((math.cos(angle), math.sin(angle)), holding.tab_width_mm / 2.0 + tool_radius_mm))
    return bands


def tab_top_mm(spec: GearSpec, holding: ThreeAxisSection) -> float:
    """Z of the tabs' top (Z0 on the top face)."""
    return -(spec.face_width_mm - holding.tab_height_mm)


def cut_depth_mm(spec: GearSpec, holding: ThreeAxisSection, break_through_mm: float) -> float:
    """How deep the levels go: the face width plus the break-through, or down to the onion skin."""
    if holding.onion_skin_mm > 0.0:
        return spec.face_width_mm - holding.onion_skin_mm
    return spec.face_width_mm + break_through_mm


def _line_crossings(segment: Segment2D, normal: tuple[float, float], offset: float) -> list[float]:
    """Fractions (0..1 exclusive) of `segment` where it crosses the line normal . p = offset."""
    nx, ny = normal
    if isinstance(segment, Line2D):
        a = nx * segment.start_xy[0] + ny * segment.start_xy[1] - offset
        b = nx * segment.end_xy[0] + ny * segment.end_xy[1] - offset
        return [a / (a - b)] if a * b < 0.0 else []
    cx, cy = segment.center_xy
    r, start, sweep = segment.radius_mm, segment.start_angle_rad, segment.sweep_rad
    distance = nx * cx + ny * cy - offset  # the centre's signed distance from the line
    if abs(distance) >= r:
        return []
    base, spread = math.atan2(ny, nx), math.acos(-distance / r)
    found = []
    for angle in (base + spread, base - spread):
        along = (angle - start) % (2 * math.pi) if sweep > 0 else (start - angle) % (2 * math.pi)
        fraction = along / abs(sweep)
        if 1e-12 < fraction < 1.0 - 1e-12:
            found.append(fraction)
    return found


def _piece(segment: Segment2D, t0: float, t1: float) -> Segment2D:
    start = segment.start_xy if t0 == 0.0 else segment.point_at(t0)
    end = segment.end_xy if t1 == 1.0 else segment.point_at(t1)
    if isinstance(segment, Line2D):
        return Line2D(start, end)
    return Arc2D(start, end, segment.center_xy, segment.counterclockwise)


def split_at_bands(loop: list[Segment2D], bands: list[TabBand]) -> list[tuple[Segment2D, bool]]:
    """The loop's segments split where they cross a band's edges, each with whether it lies in a band."""
    pieces = []
    for segment in loop:
        cuts = set()
        for band in bands:
            ux, uy = band.direction
            for side in (1.0, -1.0):  # the band's two edges, parallel to its centre line
                cuts.update(_line_crossings(segment, (-uy, ux), side * band.half_width_mm))
        ends = [0.0, *sorted(cuts), 1.0]
        for t0, t1 in zip(ends[:-1], ends[1:]):
            piece = _piece(segment, t0, t1)
            middle = piece.point_at(0.5)
            pieces.append((piece, any(band.holds(middle) for band in bands)))
    return pieces
