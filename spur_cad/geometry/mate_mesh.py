"""Trochoid interference of an external pair, found by following the mesh (docs/geometry.md, "Gear pairs").

Each gear's tip corners (where its involute meets its tip circle) trace a trochoid relative to the other gear; it
must not enter the other gear's material, the rack-generated fillet included. The pair turns through the mesh
(three pitches of this gear either side of the symmetric position, where a tooth of the mate stands in this gear's
space 0), and the corners of the five teeth nearest the mesh are followed in the other gear's frame, against its
exact outline (sampled within 0.1 um). Internal pairs have their own closed-form check (geometry/mate.py, KHK's
tip interference condition).
"""

from __future__ import annotations

import math

import numpy as np
from shapely import Polygon, contains_xy, distance, points

from spur_cad.geometry.frames import turn_points, turn_points_by
from spur_cad.geometry.mate import GearPair, PairFacts
from spur_cad.geometry.mate_gear import mate_spec
from spur_cad.geometry.sampling import gear_outline
from spur_cad.geometry.spec import GearSpec

OUTLINE_TOLERANCE_MM = 1e-4
STEPS = 1801
"""Positions through the mesh (six pitches of this gear): about 1/300 pitch apart."""
NEAR_TEETH = 2
"""Teeth either side of the one in mesh whose corners are followed."""


def _tip_corners(spec: GearSpec) -> np.ndarray:
    """Both tip corners of the teeth next to space 0 and NEAR_TEETH further each way, in the gear's gap frame (space
    0's axis +y): the right half's involute end at the tip circle, mirrored, turned by whole pitches."""
    tip = spec.tooth_space_profile().tip
    corner = tip.points(np.array([tip.start]))[0]
    pair = np.array([corner, corner * np.array([-1.0, 1.0])])
    pitch = 2.0 * math.pi / spec.teeth
    return np.concatenate([turn_points(pair, k * pitch) for k in range(-NEAR_TEETH, NEAR_TEETH + 1)])


def corner_intrusion_mm(body: GearSpec, other: GearSpec, centre_distance_mm: float) -> float:
    """How deep (mm) `other`'s tip corners enter `body`'s material as the external pair meshes, `other`'s axis at
    (0, a) in `body`'s gap frame, turned by pi - pi/z_other so that its tooth stands in body's space 0 (the
    symmetric position); 0 when they stay outside."""
    z1, z2 = body.teeth, other.teeth
    phi = np.linspace(-3.0, 3.0, STEPS) * 2.0 * math.pi / z1  # body's turn
    corners = _tip_corners(other)
    own = turn_points_by(corners, math.pi - math.pi / z2 - phi * z1 / z2)  # other's turn, opposite and in ratio
    world = own + np.array([0.0, centre_distance_mm])
    relative = np.concatenate([turn_points_by(world[i], np.array([-phi[i]]))[0] for i in range(len(phi))])
    material = Polygon(gear_outline(body, OUTLINE_TOLERANCE_MM))
    inside = contains_xy(material, relative[:, 0], relative[:, 1])
    if not inside.any():
        return 0.0
    return float(np.max(distance(material.exterior, points(relative[inside]))))


def trochoid_intrusion_mm(spec: GearSpec, pair: GearPair, facts: PairFacts) -> tuple[float, float]:
    """(the mate's tip corners into this gear, this gear's tip corners into the mate), mm; external pairs only."""
    mate = mate_spec(spec, pair)
    a = facts.centre_distance_mm
    return corner_intrusion_mm(spec, mate, a), corner_intrusion_mm(mate, spec, a)
