"""What every CAM generator shares: the safe height for indexing, the plunge feed, the conversion of
simultaneous rotary moves to inverse-time feeds (docs/method.md), and the flank offset by the finish stock that
both roughing strategies work against."""

from __future__ import annotations

import numpy as np

from spur_cad.cam.ir import MAX_TOOLPATH_MOVES, MoveKind, Toolpath, relative_path_lengths
from spur_cad.cam.machine import Machine
from spur_cad.errors import WorkLimitError
from spur_cad.geometry.sampling import sample_profile
from spur_cad.geometry.spec import GearSpec

PLUNGE_FEED_FRACTION = 0.5
"""Plunges (Z moves into the cut) run at this fraction of the tool's cutting feed."""


def safe_height_mm(blank_radius_mm: float, machine: Machine) -> float:
    """Z at which the tool may index A: above the blank by the clearance."""
    return blank_radius_mm + machine.clearance_mm


def apply_inverse_time(path: Toolpath, machine: Machine) -> Toolpath:
    """Convert linear moves that turn A into inverse-time feeds (1/min) from the relative path length,
    limited by the rotary axis's maximum speed."""
    if len(path) == 0:
        return path
    start = path.start_poses()
    moving_a = (path.kind == MoveKind.LINEAR) & (np.abs(path.a - start[:, 3]) > 1e-12)
    if not moving_a.any():
        return path
    idx = np.nonzero(moving_a)[0]
    x0, y0, z0, a0 = start[idx].T
    length = relative_path_lengths(x0, y0, z0, a0, path.x[idx], path.y[idx], path.z[idx], path.a[idx])
    minutes = np.maximum(length / path.feed[idx], np.abs(path.a[idx] - a0) / machine.max_rotary_speed_deg_min)
    feed = path.feed.copy()
    feed[idx] = 1.0 / minutes
    inverse = path.inverse_time.copy()
    inverse[idx] = True
    return path.replace(feed=feed, inverse_time=inverse)


def offset_flank(spec: GearSpec, finish_stock_mm: float) -> tuple[np.ndarray, np.ndarray, float | None]:
    """Right flank (root arc, fillet, involute) offset into the space by the finish stock, root to tip
    edge, with each point's label and the height of the fillet/involute junction."""
    samples = sample_profile(spec.tooth_space_profile(), 1e-6 * spec.module_mm)
    names = np.array(samples.label_names())
    keep = names != "tip"
    points = samples.points[keep] + finish_stock_mm * samples.normals[keep]
    labels = names[keep]
    junction = None
    involute = np.nonzero(labels == "involute")[0]
    if len(involute) and involute[0] > 0:
        junction = float(points[involute[0], 1])
    return points, labels, junction


def check_moves(operation: str, moves: int, section: str, field: str) -> None:
    """Refuse (WorkLimitError naming [section] field) an operation whose estimated moves exceed MAX_TOOLPATH_MOVES."""
    if moves > MAX_TOOLPATH_MOVES:
        raise WorkLimitError(f"{operation} would need about {moves:.2g} moves (limit {MAX_TOOLPATH_MOVES:.0e}); "
                             f"raise [{section}] {field}", field=field, section=section)
