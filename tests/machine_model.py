"""A planted machine that cuts a gear from the job's LinuxCNC program as LinuxCNC interprets it (test-side code,
no tests here; issue 46).

The program is run through LinuxCNC's own interpreter (`rs274`, tests/rs274_helper.py): every feed move it
commands that crosses the transverse plane X = x gives one pose (Y, Z, A) there, interpolated along the move. The
machine then errs where a real one does, at each pose:

- the table stands at A + e(A) when A is commanded, e(A) a sum of harmonics (arcsec), evaluated at that pose's
  own commanded A (a controller's rotary compensation table holds the same function);
- the tool is larger in radius than programmed by `tool_radius_error_um`;
- the blank sits off the A axis: the gear's datum axis (its bore) is at `blank_offset_um` from the A axis in the
  table's frame, so the offset turns with A.

The cut is an independent 2-D section (tests/silhouette.py: shapely silhouettes of the tool in the part frame,
their union the material removed). Flank positions are the signed distances of the design's involute points, placed
about the datum axis, to the cut (+ material left, - gouged). Nothing of spur_cad's simulation, grading or
correction code is used; only its design outline (tests/silhouette.design_boundary).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
import shapely.affinity

from tests.rs274_helper import canon_args, run_rs274
from tests.silhouette import design_boundary, place_silhouettes

ARCSEC_DEG = 1.0 / 3600.0
TOOL_LENGTH_MM = 12.0


@dataclass(frozen=True)
class Harmonic:
    """One term of the table's error: amplitude_arcsec x sin(order A + phase_deg)."""

    amplitude_arcsec: float
    order: int
    phase_deg: float = 0.0


@dataclass(frozen=True)
class PlantedMachine:
    """The machine's errors (see the module docstring). blank_offset_um: the datum axis's (Y, Z) from the A axis in
    the table's frame at A 0 (it turns with the table)."""

    tool_radius_error_um: float = 0.0
    table: tuple[Harmonic, ...] = ()
    blank_offset_um: tuple[float, float] = (0.0, 0.0)

    def table_error_arcsec(self, a_deg: np.ndarray) -> np.ndarray:
        """e(A) (arcsec) at the commanded A (deg): the table stands this much further in A."""
        a = np.radians(np.asarray(a_deg, dtype=float))
        total = np.zeros_like(a)
        for term in self.table:
            total += term.amplitude_arcsec * np.sin(term.order * a + math.radians(term.phase_deg))
        return total


IDEAL = PlantedMachine()


def interpreted_poses(program_text: str, x_mm: float) -> np.ndarray:
    """(Y, Z, A) where each feed move of the program, as rs274 interprets it, crosses the plane X = x_mm (linear
    interpolation along the move: a move's axes run together), in program order. Raises if rs274 refuses it."""
    with tempfile.TemporaryDirectory(prefix="machine-model-") as work:
        path = Path(work) / "program.ngc"
        path.write_text(program_text)
        ok, canon, messages = run_rs274(path)
    assert ok, messages
    poses = []
    position = None
    for line in canon:
        if not line.startswith(("STRAIGHT_FEED(", "STRAIGHT_TRAVERSE(")):
            continue
        end = np.array(canon_args(line)[:4])  # X Y Z A
        if position is not None and line.startswith("STRAIGHT_FEED("):
            x0, x1 = position[0], end[0]
            if min(x0, x1) < x_mm < max(x0, x1):
                t = (x_mm - x0) / (x1 - x0)
                poses.append(position[1:] + t * (end[1:] - position[1:]))
        position = end
    return np.array(poses)


@dataclass(frozen=True)
class Section:
    """A transverse section as cut: the design's involute points about the datum axis, their side ('right': the
    sampled half, 'left': its mirror), space, radius, signed distance to the cut (mm, + material) and the nearest
    point of the cut's boundary (what a scanning probe touches)."""

    points: np.ndarray
    side: np.ndarray
    space: np.ndarray
    radius_mm: np.ndarray
    deviation_mm: np.ndarray
    surface: np.ndarray


def cut_section(spec, poses: np.ndarray, machine: PlantedMachine, tool_diameter_mm: float,
                corner_radius_mm: float) -> Section:
    """The section cut by the tool at the poses (Y, Z, A) on the machine: each pose turned to the table's actual A,
    the tool larger by the machine's radius error, the part frame's origin on the datum axis."""
    actual_a = poses[:, 2] + machine.table_error_arcsec(poses[:, 2]) * ARCSEC_DEG
    diameter = tool_diameter_mm + 2.0 * machine.tool_radius_error_um / 1000.0
    silhouettes = place_silhouettes(poses[:, 0], poses[:, 1], actual_a, diameter, corner_radius_mm, TOOL_LENGTH_MM)
    offset = -np.asarray(machine.blank_offset_um) / 1000.0
    union = shapely.affinity.translate(shapely.union_all(silhouettes), *offset)
    teeth = spec.teeth
    points, _ = design_boundary(spec, range(teeth), ("involute",))
    rings = shapely.get_rings(shapely.get_parts(union))
    segments = np.concatenate([np.stack([c[:-1], c[1:]], axis=1) for c in map(shapely.get_coordinates, rings)])
    lines = shapely.linestrings(segments)
    tree = shapely.STRtree(lines)
    (index, nearest), distance = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    order = np.argsort(index)
    index, nearest, distance = index[order], nearest[order], distance[order]
    assert np.array_equal(index, np.arange(len(points)))
    signed = distance.copy()
    signed[shapely.contains_xy(union, points[:, 0], points[:, 1])] *= -1.0  # inside the tool's sweep: gouged
    surface = shapely.get_coordinates(shapely.shortest_line(shapely.points(points), lines[nearest]))[1::2]
    angle = np.arctan2(points[:, 1], points[:, 0])
    space = np.mod(np.rint((angle - math.pi / 2.0) / (2.0 * math.pi / teeth)), teeth).astype(int)
    local = np.mod(angle - math.pi / 2.0 - space * 2.0 * math.pi / teeth + math.pi, 2.0 * math.pi) - math.pi
    side = np.where(local < 0.0, "right", "left")  # space 0's gap is centred on +Z, its sampled half at +Y
    return Section(points, side, space, np.hypot(points[:, 0], points[:, 1]), signed, surface)


def base_roll_mm(spec, radius_mm: np.ndarray) -> np.ndarray:
    """Roll length sqrt(r^2 - r_b^2) of points at radius_mm."""
    return np.sqrt(np.maximum(radius_mm ** 2 - spec.base_radius_mm ** 2, 0.0))


@dataclass(frozen=True)
class FlankFigures:
    """Per side: each space's flank position at the reference circle and its mean over the profile evaluation range
    (um along the normal, + material), F_p (um of arc on the reference circle, about the datum axis) and the deepest
    gouge (um, >= 0)."""

    at_reference_um: dict[str, np.ndarray]
    mean_um: dict[str, np.ndarray]
    pitch_total_um: dict[str, float]
    gouge_um: float

    @property
    def size_um(self) -> float:
        """The mean flank position over both sides and every space (+ material)."""
        return float(np.mean([values.mean() for values in self.mean_um.values()]))


def flank_figures(spec, section: Section, evaluation_roll_mm: tuple[float, float]) -> FlankFigures:
    """The section's flanks: position at the reference circle (interpolated in radius), the mean over the
    evaluation range (roll lengths, ISO 1328's profile evaluation range), F_p per side as the spread of the positions
    at the reference circle over cos alpha (the normal shift of a flank is its arc on the base circle; on the
    reference circle the arc is that over cos alpha), and the deepest gouge in the evaluation range."""
    roll = base_roll_mm(spec, section.radius_mm)
    start, end = evaluation_roll_mm
    in_range = (roll >= start) & (roll <= end)
    cos_alpha = spec.base_radius_mm / spec.reference_radius_mm
    at_reference, mean, pitch = {}, {}, {}
    for name in ("right", "left"):
        at_ref = np.empty(spec.teeth)
        means = np.empty(spec.teeth)
        for k in range(spec.teeth):
            on = (section.side == name) & (section.space == k)
            order = np.argsort(section.radius_mm[on])
            at_ref[k] = np.interp(spec.reference_radius_mm, section.radius_mm[on][order],
                                  section.deviation_mm[on][order])
            means[k] = section.deviation_mm[on & in_range].mean()
        at_reference[name], mean[name] = at_ref * 1000.0, means * 1000.0
        pitch[name] = float(np.ptp(at_ref)) * 1000.0 / cos_alpha
    gouge = max(0.0, -float(section.deviation_mm[in_range].min()) * 1000.0)
    return FlankFigures(at_reference, mean, pitch, gouge)


def scan_csv(sections: dict[float, Section], turn_deg: float = 0.0) -> str:
    """A scan of the cut on its datum axis in the `spur-cad grade` CSV format (x_mm,y_mm,X_mm): the points of the
    cut's surface nearest the design's involute points, in each plane X of `sections`, turned by turn_deg about the
    datum axis (a scanner's frame has its own zero turn; its origin is the datum axis)."""
    c, s = math.cos(math.radians(turn_deg)), math.sin(math.radians(turn_deg))
    lines = ["x_mm,y_mm,X_mm"]
    for x_mm, section in sections.items():
        y = c * section.surface[:, 0] - s * section.surface[:, 1]
        z = s * section.surface[:, 0] + c * section.surface[:, 1]
        lines += [f"{a:.6f},{b:.6f},{x_mm:.4f}" for a, b in zip(y, z)]
    return "\n".join(lines) + "\n"


def cut_planes(spec, program_text: str, machine: PlantedMachine, tool_diameter_mm: float, corner_radius_mm: float,
               planes_mm: tuple[float, ...]) -> dict[float, Section]:
    """The sections at each plane X; a plane whose poses equal an earlier plane's (passes straight along X) reuses
    that plane's cut."""
    sections: dict[float, Section] = {}
    done: list[tuple[np.ndarray, Section]] = []
    for x_mm in planes_mm:
        poses = interpreted_poses(program_text, x_mm)
        same = [section for earlier, section in done if earlier.shape == poses.shape and np.array_equal(earlier, poses)]
        sections[x_mm] = same[0] if same else cut_section(spec, poses, machine, tool_diameter_mm, corner_radius_mm)
        if not same:
            done.append((poses, sections[x_mm]))
    return sections
