"""`spur-cad verify`: cut the job's stock with G-code programs from anywhere and judge the part.

The programs are read as a controller would (spur_cad.verify.reader), each move goes to the
simulator with the job's tool of the number in the spindle, and the deviations of the design
points are reported per tooth space, feature and finishing station, with a deviation map. A
program passes when no point is gouged by more than the gouge tolerance (default: the simulation's
resolution, its own error) and none is left more than the leftover tolerance above the design
(default: the finishing target scallop plus the resolution).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from spur_cad.cam.ir import Feature, MoveKind, Operation, Toolpath
from spur_cad.errors import SpurCadError, shown
from spur_cad.verify.reader import ProgramMoves

if TYPE_CHECKING:  # the simulator loads only when a program is simulated
    from spur_cad.job import Job
    from spur_cad.sim.simulate import Cut, SimResult

POINTS = ("tip", "corner-centre")


@dataclass(frozen=True)
class VerifyOptions:
    """How to read and judge: the programmed point, the tolerances (None: the defaults above)."""

    point: str = "tip"  # "corner-centre": Z is programmed at the tool's corner-radius centre
    gouge_tolerance_mm: float | None = None
    leftover_tolerance_mm: float | None = None
    point_tools: tuple[int, ...] = ()  # the tools `point` applies to (empty: every tool)
    a_offset_deg: float = 0.0  # added to every A read: the job's A of the programs' A zero (another A zero)

    def __post_init__(self) -> None:
        """Refuse an option out of its range, once, when the options are made (verify_moves trusts them)."""
        if self.point not in POINTS:
            raise SpurCadError(f"--point must be one of {', '.join(POINTS)}, got {shown(self.point)}")
        if not (math.isfinite(self.a_offset_deg) and abs(self.a_offset_deg) <= 360.0):
            raise SpurCadError(f"--a-offset-deg must be in [-360, 360] deg, got {self.a_offset_deg:g}")
        for name in ("gouge_tolerance_mm", "leftover_tolerance_mm"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and 0.0 <= value <= 10.0):
                raise SpurCadError(f"--{name.replace('_', '-')} must be in [0, 10] mm, got {value:g}")


@dataclass(frozen=True)
class SpacePlace:
    """Where in a tooth space a deviation is: the design feature and point, X and the finishing station."""

    feature: str
    point: int
    x_mm: float
    station: int  # -1: none


@dataclass(frozen=True)
class SpaceVerdict:
    """One tooth space: its largest gouge and leftover (mm, >= 0) and where they are."""

    space: int
    max_gouge_mm: float
    max_leftover_mm: float
    worst_gouge: SpacePlace
    worst_leftover: SpacePlace


@dataclass(frozen=True)
class VerifyResult:
    """The verdict: per space, overall, the tolerances used, and the rs274 verdicts of LinuxCNC programs."""

    spaces: tuple[SpaceVerdict, ...]
    max_gouge_mm: float
    max_leftover_mm: float
    gouge_tolerance_mm: float
    leftover_tolerance_mm: float
    moves: int
    seconds: float
    rs274: dict = field(default_factory=dict)
    deviation_map: str = ""
    simulation: object = None  # the spur_cad.sim SimResult (for drawing the deviations on the gear)

    @property
    def passed(self) -> bool:
        return self.max_gouge_mm <= self.gouge_tolerance_mm and self.max_leftover_mm <= self.leftover_tolerance_mm

    def summary(self) -> dict:
        """The verdict as JSON-ready data (verify.json)."""
        return {"passed": self.passed, "max_gouge_mm": self.max_gouge_mm, "max_leftover_mm": self.max_leftover_mm,
                "gouge_tolerance_mm": self.gouge_tolerance_mm, "leftover_tolerance_mm": self.leftover_tolerance_mm,
                "moves": self.moves, "seconds": round(self.seconds, 3), "rs274": self.rs274,
                "spaces": [dataclasses.asdict(space) for space in self.spaces]}

    def lines(self) -> list[str]:
        """The verdict for people: one line per space beyond tolerance, then the overall line."""
        out = []
        for space in self.spaces:
            for kind, value, tolerance, worst in (("gouge", space.max_gouge_mm, self.gouge_tolerance_mm,
                                                   space.worst_gouge),
                                                  ("leftover", space.max_leftover_mm, self.leftover_tolerance_mm,
                                                   space.worst_leftover)):
                if value > tolerance:
                    station = f", station {worst.station}" if worst.station >= 0 else ""
                    out.append(f"space {space.space}: {kind} {value * 1000:.1f} um at X {worst.x_mm:.3f} mm, "
                               f"{worst.feature}{station} (tolerance {tolerance * 1000:.1f} um)")
        verdict = "PASS" if self.passed else "FAIL"
        out.append(f"{verdict}: max gouge {self.max_gouge_mm * 1000:.1f} um (tolerance "
                   f"{self.gouge_tolerance_mm * 1000:.1f}), max leftover {self.max_leftover_mm * 1000:.1f} um "
                   f"(tolerance {self.leftover_tolerance_mm * 1000:.1f}), {len(self.spaces)} spaces, {self.moves:,} "
                   "moves")
        return out


def toolpaths(moves: ProgramMoves, tools: dict, roughing_number: int | None, point: str,
              point_tools: tuple[int, ...] = (), a_offset_deg: float = 0.0) -> list[Cut]:
    """(Toolpath, Tool) per run of moves with one tool in the spindle; the job's `tools` by tool number; A is
    the program's plus `a_offset_deg` (VerifyOptions)."""
    from spur_cad.sim.simulate import Cut

    cuts: list[Cut] = []
    if len(moves) == 0:
        return cuts
    change = np.nonzero(np.diff(moves.tool))[0] + 1
    for begin, end in zip(np.concatenate([[0], change]), np.concatenate([change, [len(moves)]])):
        number = int(moves.tool[begin])
        if number == 0:
            raise SpurCadError(f"{moves.source}:{int(moves.line[begin])}: a move before any tool is loaded "
                               "(T<number> M6)")
        if number not in tools:
            known = ", ".join(f"T{n}" for n in sorted(tools)) or "none"
            raise SpurCadError(f"{moves.source}:{int(moves.line[begin])}: moves with tool T{number}, which the job "
                               f"does not have (its tools: {known}; the job's [tools.*] tool_number)")
        tool = tools[number]
        part = slice(begin, end)
        at_centre = point == "corner-centre" and (not point_tools or number in point_tools)
        z = moves.z[part] - (tool.effective_corner_radius_mm if at_centre else 0.0)
        count = end - begin
        path = Toolpath(
            kind=np.where(moves.rapid[part], MoveKind.RAPID, MoveKind.LINEAR).astype(np.int8),
            x=moves.x[part], y=moves.y[part], z=z,  # views: the moves are not changed
            a=moves.a[part] + a_offset_deg if a_offset_deg else moves.a[part],
            feed=moves.feed[part], inverse_time=moves.inverse_time[part],
            space=np.full(count, -1, np.int32), station=np.full(count, -1, np.int32),
            feature=np.full(count, Feature.NONE, np.int8),
            operation=Operation.ROUGHING if number == roughing_number else Operation.FINISHING,
            tool_number=number, spindle_rpm=float(moves.spindle_rpm[begin]))
        cuts.append(Cut(path, tool))
    return cuts


def station_positions(path: Toolpath) -> np.ndarray:
    """X of transverse finishing stations: feed moves in Y, Z or A that keep X (rows are added there)."""
    start = path.start_poses()
    feed = path.kind == MoveKind.LINEAR
    transverse = (path.x == start[:, 0]) & ((path.y != start[:, 1]) | (path.a != start[:, 3]))
    return np.unique(np.round(path.x[feed & transverse], 6))


def _where(result: SimResult, k: int, flat_index: int, rows: np.ndarray, names: list[str]) -> SpacePlace:
    j, r = np.unravel_index(flat_index, result.deviation[k][:, rows].shape)
    row = np.nonzero(rows)[0][r]
    return SpacePlace(names[j], int(j), float(result.grid.rows_x[row]), int(result.station_of_row()[row]))


def space_verdicts(result: SimResult) -> tuple[SpaceVerdict, ...]:
    """The largest gouge and leftover of each tooth space inside the face width, and where they are."""
    rows, names = result.gear_rows, result.grid.feature_names()
    verdicts = []
    for k in range(result.deviation.shape[0]):
        dev = result.deviation[k][:, rows]
        verdicts.append(SpaceVerdict(k, float(max(0.0, -dev.min())), float(max(0.0, dev.max())),
                                     _where(result, k, int(np.argmin(dev)), rows, names),
                                     _where(result, k, int(np.argmax(dev)), rows, names)))
    return tuple(verdicts)


def deviation_map_csv(result: SimResult) -> str:
    """Per space, feature and row of the face width: the smallest and largest deviation (um)."""
    rows = np.nonzero(result.gear_rows)[0]
    names = result.grid.feature_names()
    features = list(dict.fromkeys(names))
    lines = ["space,feature,x_mm,min_deviation_um,max_deviation_um"]
    for k in range(result.deviation.shape[0]):
        for feature in features:
            mask = np.array([name == feature for name in names])
            block = result.deviation[k][mask][:, rows] * 1000.0
            lows, highs = block.min(axis=0), block.max(axis=0)
            lines += [f"{k},{feature},{result.grid.rows_x[r]:.4f},{lo:.2f},{hi:.2f}"
                      for r, lo, hi in zip(rows, lows, highs)]
    return "\n".join(lines) + "\n"


def verify_moves(job: Job, programs: list[ProgramMoves], options: VerifyOptions = VerifyOptions(),
                 progress: Callable[[float], None] | None = None) -> VerifyResult:
    """Simulate the job's stock cut by `programs` in order and judge the part (see the module docstring)."""
    from spur_cad.pipeline import job_stock
    from spur_cad.sim.simulate import SimSettings, simulate

    tools = {tool.tool_number: tool for tool in (job.tools.roughing, job.tools.finishing) if tool is not None}
    roughing_number = job.tools.roughing.tool_number if job.tools.roughing is not None else None
    cuts = [cut for moves in programs for cut in toolpaths(moves, tools, roughing_number, options.point,
                                                           options.point_tools, options.a_offset_deg)]
    if not cuts:
        raise SpurCadError("the programs have no moves to verify")
    finishing = [cut.path for cut in cuts if cut.path.operation == Operation.FINISHING]
    stations = np.unique(np.concatenate([station_positions(path) for path in finishing])) if finishing else None
    resolution = job.simulation.resolution_mm
    result = simulate(job.gear, job_stock(job), cuts, SimSettings(resolution_mm=resolution),
                      station_x=stations, progress=progress)
    gouge_tol = options.gouge_tolerance_mm if options.gouge_tolerance_mm is not None else resolution
    leftover_tol = (options.leftover_tolerance_mm if options.leftover_tolerance_mm is not None
                    else job.finishing.target_scallop_mm + resolution)
    return VerifyResult(space_verdicts(result), result.max_gouge_mm, result.max_leftover_mm, gouge_tol, leftover_tol,
                        sum(len(moves) for moves in programs), result.seconds, deviation_map=deviation_map_csv(result),
                        simulation=result)


def result_files(result: VerifyResult) -> dict[str, bytes]:
    """The output set of a verification: verify.json and deviation_map.csv."""
    return {"verify.json": (json.dumps(result.summary(), indent=2) + "\n").encode(),
            "deviation_map.csv": result.deviation_map.encode()}
