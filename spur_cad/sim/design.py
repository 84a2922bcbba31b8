"""The design points the simulation measures at: blades along the design normals ("point-vector" method).

One tooth space's boundary (tooth centre to tooth centre: right tip land, right involute, right
fillet, root arc, left fillet, left involute, left tip land) is sampled at even arc-length
spacing from the exact profile of `spur_cad.geometry`; every tooth space k uses the same
points turned by k * 360/z degrees (counter-clockwise in machine (Y, Z), as the part sits at
A = 0). Each point carries its exact unit normal pointing out of the material (into the space).
The same transverse points are repeated on rows along X; for a helical gear row x holds them
turned by the helix (`GearSpec.section_turn_rad(x)`), which the simulation kernel applies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.geometry.frames import turn_points
from spur_cad.geometry.profile import SEGMENT_LABELS, ToothSpaceProfile
from spur_cad.geometry.sampling import even_arc_length_parameters
from spur_cad.geometry.spec import GearSpec

FEATURES = SEGMENT_LABELS  # one vocabulary: the profile segments of spur_cad.geometry.profile
RIGHT, CENTRE, LEFT = 1, 0, -1


@dataclass(frozen=True)
class DesignGrid:
    """Sampled design of one tooth space (sector-local frame = gap frame of space 0) and the X rows.

    `points`/`normals` are (M, 2) in machine (Y, Z) at A = 0 for space 0; `feature` indexes
    FEATURES; `side` is RIGHT/LEFT (CENTRE for the root centre and tooth centres); `arc_mm` is
    the arc length along the outline from the right tooth centre. `rows_x` (R,) are the X
    positions of the rows, `row_width` (R,) the slab of stock each row stands for (volume).
    """

    teeth: int
    points: np.ndarray
    normals: np.ndarray
    feature: np.ndarray
    side: np.ndarray
    arc_mm: np.ndarray
    rows_x: np.ndarray
    row_width: np.ndarray
    spacing_mm: float
    twist_rad_per_mm: float = 0.0  # helical gears: row x holds the points turned by twist * x (positive A sense)

    @property
    def pitch_rad(self) -> float:
        return 2.0 * math.pi / self.teeth

    def space_points(self, k: int) -> np.ndarray:
        """Design points of tooth space k (part frame)."""
        return turn_points(self.points, k * self.pitch_rad)

    def space_normals(self, k: int) -> np.ndarray:
        return turn_points(self.normals, k * self.pitch_rad)

    def row_points(self, k: int, x_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """Design points and normals of tooth space k in the row at X = x_mm (turned by the helix)."""
        angle = k * self.pitch_rad + self.twist_rad_per_mm * x_mm
        return turn_points(self.points, angle), turn_points(self.normals, angle)

    def feature_names(self) -> list[str]:
        """'right involute', 'root', ... per point."""
        side_name = {RIGHT: "right ", LEFT: "left ", CENTRE: ""}
        return [f"{side_name[int(s)]}{FEATURES[int(f)]}" for f, s in zip(self.feature, self.side)]



def sample_space(profile: ToothSpaceProfile, spacing_mm: float) -> tuple[np.ndarray, ...]:
    """Points, normals, feature, side of one whole space, right tooth centre -> left tooth centre.

    The last point (left tooth centre) is left out: it is the next space's first point.
    """
    pts: list[np.ndarray] = []
    nrm: list[np.ndarray] = []
    feat: list[np.ndarray] = []
    for segment in profile.segments:  # right half, root -> tip
        if segment.end <= segment.start:
            continue
        params = even_arc_length_parameters(segment, spacing_mm)
        if pts:
            params = params[1:]
        pts.append(segment.points(params))
        nrm.append(segment.normals(params))
        feat.append(np.full(len(params), SEGMENT_LABELS.index(segment.label)))
    right_p, right_n, right_f = np.concatenate(pts), np.concatenate(nrm), np.concatenate(feat)
    mirror = np.array([-1.0, 1.0])
    points = np.concatenate([right_p[::-1], right_p[1:] * mirror])
    normals = np.concatenate([right_n[::-1], right_n[1:] * mirror])
    feature = np.concatenate([right_f[::-1], right_f[1:]])
    side = np.concatenate([np.full(len(right_p), RIGHT), np.full(len(right_p) - 1, LEFT)])
    side[len(right_p) - 1] = CENTRE  # root centre
    side[0] = CENTRE  # tooth centre
    # Gap frame (x, y) is machine (Y, Z) at A = 0 for space 0 (docs/architecture.md).
    return points[:-1], normals[:-1], feature[:-1], side[:-1]


def row_positions(x_min: float, x_max: float, spacing_mm: float, extra: np.ndarray | None = None,
                  face_width_mm: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Row X positions: an even grid over [x_min, x_max] (through X = 0 and X = b when given), plus `extra`
    positions (finishing stations and the midpoints between them, where scallop ridges stand); returns
    (positions, slab widths) with the slabs tiling [x_min, x_max]."""
    anchors = [0.0] if face_width_mm is None else [0.0, face_width_mm]
    step = spacing_mm
    if face_width_mm is not None and face_width_mm > 0.0:
        step = face_width_mm / math.ceil(face_width_mm / spacing_mm)
    grid = np.arange(math.floor((x_min - anchors[0]) / step), math.ceil((x_max - anchors[0]) / step) + 1) * step
    grid = grid[(grid >= x_min - 1e-9) & (grid <= x_max + 1e-9)]
    extra = np.asarray(extra if extra is not None else (), float)
    extra = extra[(extra >= x_min) & (extra <= x_max)]
    if len(extra) > 1:  # the grid only fills where the extra rows leave gaps wider than the spacing
        nearest = np.abs(grid[:, None] - extra[None, :]).min(axis=1)
        grid = grid[nearest > 0.5 * spacing_mm]
    rows = np.unique(np.round(np.concatenate([grid, extra, [x_min, x_max], anchors]), 9))
    rows = rows[(rows >= x_min - 1e-9) & (rows <= x_max + 1e-9)]
    edges = np.concatenate([[x_min], 0.5 * (rows[1:] + rows[:-1]), [x_max]])
    return rows, np.diff(edges)


def design_grid(spec: GearSpec, spacing_mm: float, x_min: float, x_max: float,
                extra_rows: np.ndarray | None = None) -> DesignGrid:
    """The design grid of `spec`: points every `spacing_mm` along the space, rows over [x_min, x_max]."""
    points, normals, feature, side = sample_space(spec.tooth_space_profile(), spacing_mm)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    rows, width = row_positions(x_min, x_max, spacing_mm, extra_rows, spec.face_width_mm)
    return DesignGrid(spec.teeth, points, normals, feature.astype(np.int8), side.astype(np.int8), arc, rows, width,
                      spacing_mm, spec.section_turn_rad(1.0))


def space_parameters(profile: ToothSpaceProfile, spacing_mm: float) -> np.ndarray:
    """Each `sample_space` point's parameter on its segment (same order: right tooth centre -> left)."""
    params: list[np.ndarray] = []
    for segment in profile.segments:
        if segment.end <= segment.start:
            continue
        values = even_arc_length_parameters(segment, spacing_mm)
        params.append(values[1:] if params else values)
    right = np.concatenate(params)
    return np.concatenate([right[::-1], right[1:]])[:-1]


def modification_removal_mm(spec: GearSpec, grid: DesignGrid, mods) -> np.ndarray:
    """(M, rows) material the flank modifications remove at each design point of `grid` along its normal (mm,
    positive into the material): involute points by the removal itself, fillet points by the form point's removal
    faded as (beta / beta_F)^2 along the form normal (as the B-rep), tip-land points near the tooth corner by their
    depth above the relieved flank, root points not at all. A cut's deviation from the modified design is the
    deviation from the design plus this."""
    from spur_cad.geometry.modifications import normal_offset_mm

    profile = spec.tooth_space_profile()
    involute, fillet = profile.involute, profile.fillet
    rb = spec.base_radius_mm
    params = space_parameters(profile, grid.spacing_mm)
    label = np.array(FEATURES)[grid.feature]
    x = grid.rows_x[None, :]
    removal = np.zeros((len(grid.points), len(grid.rows_x)))
    form_normal = involute.normals(np.array(involute.start))
    tip_point, tip_normal = involute.points(np.array(involute.end)), involute.normals(np.array(involute.end))
    for side, name in ((RIGHT, "right"), (LEFT, "left")):
        mirror = np.array([1.0, 1.0]) if side == RIGHT else np.array([-1.0, 1.0])
        here = grid.side == side
        flank = (label == "involute") & here
        removal[flank] = normal_offset_mm(mods, name, rb * params[flank][:, None], x)
        if fillet is not None and fillet.end > 0.0:
            near = (label == "fillet") & here
            form = normal_offset_mm(mods, name, rb * involute.start, x)
            along = grid.normals[near] @ (form_normal * mirror)
            removal[near] = form * ((params[near] / fillet.end) ** 2 * along)[:, None]
        land = (label == "tip") & here
        edge = tip_point * mirror - normal_offset_mm(mods, name, rb * involute.end, x)[..., None] * tip_normal * mirror
        reach = ((grid.points[land][:, None, :] - edge) * tip_normal * mirror).sum(axis=-1)
        removal[land] = np.maximum(reach / (grid.normals[land] @ (tip_normal * mirror))[:, None], 0.0)
    return removal

