"""Perimeter finishing (docs/method.md): at each transverse station along X the tool goes once
around the gear, both flanks cut downward with the corner, root and tip land with the flat
bottom while Y and A move together (inverse-time feeds)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.common import PLUNGE_FEED_FRACTION, apply_inverse_time, check_moves, safe_height_mm
from spur_cad.cam.contacts import (
    SpacePoses,
    TransversePoses,
    contact_counts,
    modified_space_poses,
    space_poses,
    station_positions,
    station_step_mm,
)
from spur_cad.cam.estimate import Estimate, estimate
from spur_cad.cam.ir import Feature, MoveKind, Toolpath, ToolpathBuilder
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies.base import (
    ContactStrategy,
    FinishingResult,
    ScallopParams,
    check_flat_fits_root_arc,
    finishing_builder,
)
from spur_cad.cam.tools import Tool
from spur_cad.geometry.modifications import SIDES, FlankModifications
from spur_cad.geometry.spec import GearSpec


@dataclass(frozen=True)
class PerimeterParams(ScallopParams):
    """[finishing] keys the perimeter strategy uses (step_over_mm: X step between stations)."""

    contact_spacing_mm: float | None = None  # fixed arc-length contact spacing (the reference process's)


class PerimeterStrategy(ContactStrategy):
    """See the module docstring."""

    name = "perimeter"
    description = "transverse stations along X, once around the gear at each (simultaneous Y/Z/A)"
    params_type = PerimeterParams
    simultaneous_rotary = True
    helical = False  # transverse contacts of a spur gear
    follows_modifications = True  # each station's contacts on the flanks modified at its X
    corrects_slopes = False
    lying_flat = False

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        """A round corner (the scallop is bounded by it) and a flat within the root arc."""
        check_flat_fits_root_arc(spec, tool, self.name)

    def estimate_moves(self, spec: GearSpec, tool: Tool, params: PerimeterParams) -> int:
        counts = contact_counts(spec, tool, params.target_scallop_mm, params.contact_spacing_mm)
        stations = math.ceil(spec.face_width_mm / station_step_mm(tool, params.target_scallop_mm,
                                                                   params.step_over_mm)) + 1
        return stations * spec.teeth * (counts.per_space + 4)

    def generate(self, spec: GearSpec, tool: Tool, machine: Machine, params: PerimeterParams,
                 blank_radius_mm: float, modifications: FlankModifications | None = None,
                 profile_tolerance_mm: float = 0.001) -> tuple[Toolpath, FinishingResult]:
        """The stations' toolpath; with flank `modifications` each station's contacts lie on the flanks modified
        at its X (contacts.modified_space_poses; the result's poses are those of the middle station). The
        profile tolerance is not used: a station's contacts are placed exactly."""
        poses, stations = self._poses_and_stations(spec, tool, params)
        if modifications is None:
            path = self._stations_path(spec, tool, machine, params, blank_radius_mm, [poses], stations)
        else:
            at_station = _modified_poses_of_stations(spec, tool, params, modifications, stations)
            # modified flanks take more contacts than the design's the work check counted (reliefs split and
            # curve them: 95 against 72 per flank on the test gear): the moves counted again before building
            moves = spec.teeth * sum(len(_space_sequence(p, 0.0)) for p in at_station)
            check_moves("finishing", moves, "finishing",
                        "step_over_mm" if params.step_over_mm > 0.0 else "target_scallop_mm")
            path = self._stations_path(spec, tool, machine, params, blank_radius_mm, at_station, stations)
            poses = at_station[len(stations) // 2]
        step = float(stations[1] - stations[0]) if len(stations) > 1 else 0.0
        return path, FinishingResult(self.name, params, poses, len(stations), step, stations)

    def estimate(self, spec: GearSpec, tool: Tool, machine: Machine, params: PerimeterParams,
                 blank_radius_mm: float) -> Estimate:
        """The estimate of `generate`'s toolpath without building it (a comparison figure of millions of moves
        in the memory of a few thousand). Stations are evenly spaced and each repeats the first one X step
        on, its A turned on (or unwound) by the same angle: the whole is the first station's estimate plus
        (stations - 1) times what a second station adds, the transition between them included. Equal to
        the full toolpath's estimate but for rounding and the look-ahead's coupling across stations
        (tests/test_work_limits.py compares them)."""
        poses, stations = self._poses_and_stations(spec, tool, params)
        first = estimate(self._stations_path(spec, tool, machine, params, blank_radius_mm, [poses], stations[:1]),
                         machine)
        if len(stations) == 1:
            return first
        two = estimate(self._stations_path(spec, tool, machine, params, blank_radius_mm, [poses], stations[:2]),
                       machine)
        more = len(stations) - 1
        return Estimate(first.moves + more * (two.moves - first.moves),
                        first.cutting_length_mm + more * (two.cutting_length_mm - first.cutting_length_mm),
                        first.rapid_length_mm + more * (two.rapid_length_mm - first.rapid_length_mm),
                        first.time_s + more * (two.time_s - first.time_s),
                        first.time_with_acceleration_s + more * (two.time_with_acceleration_s
                                                                 - first.time_with_acceleration_s))

    @staticmethod
    def _poses_and_stations(spec: GearSpec, tool: Tool, params: PerimeterParams) -> tuple[SpacePoses, np.ndarray]:
        poses = space_poses(spec, tool, params.target_scallop_mm, params.contact_spacing_mm)
        stations = station_positions(spec.face_width_mm,
                                     station_step_mm(tool, params.target_scallop_mm, params.step_over_mm))
        return poses, stations

    @staticmethod
    def _stations_path(spec: GearSpec, tool: Tool, machine: Machine, params: PerimeterParams,
                       blank_radius_mm: float, poses: list[SpacePoses], stations: np.ndarray) -> Toolpath:
        """The toolpath of `stations`: `poses` holds one space's poses for all of them, or one for each."""
        builder = finishing_builder(tool, machine)
        feed, safe_z = tool.feed_mm_min(machine), safe_height_mm(blank_radius_mm, machine)
        if len(poses) == 1:
            _tile_stations(builder, spec, machine, poses[0], stations, feed, safe_z)
        else:
            for index, station_poses in enumerate(poses):
                _tile_stations(builder, spec, machine, station_poses, stations[index:index + 1], feed, safe_z, index)
        return apply_inverse_time(builder.build(), machine)


def _modified_poses_of_stations(spec: GearSpec, tool: Tool, params: PerimeterParams,
                                modifications: FlankModifications, stations: np.ndarray) -> list[SpacePoses]:
    """Each station's poses on the flanks modified at its X; stations whose lead removal is the same on both sides
    (all of them without lead modifications, mirrored pairs under lead crowning) share theirs."""
    computed: dict[tuple[float, float], SpacePoses] = {}
    out = []
    for x in stations:
        right, left = (round(float(modifications.side(side).lead_offset_mm(x)), 12) for side in SIDES)
        key = (right, left)
        if key not in computed:
            computed[key] = modified_space_poses(spec, tool, params.target_scallop_mm, modifications, float(x),
                                                 params.contact_spacing_mm)
        out.append(computed[key])
    return out


def _space_sequence(poses: SpacePoses, safe_z: float) -> list[tuple]:
    """(kind, y, z, a_rel, feature, plunge) rows of one space at one station, in cutting order."""
    rows = []

    def approach(p: TransversePoses, feature: Feature):
        rows.append((MoveKind.RAPID, p.y[0], safe_z, p.a[0], Feature.NONE, False))
        rows.append((MoveKind.LINEAR, p.y[0], p.z[0], p.a[0], Feature.NONE, True))
        for y, z, a in zip(p.y[1:], p.z[1:], p.a[1:]):
            rows.append((MoveKind.LINEAR, y, z, a, feature, False))

    def retract():
        _, y, _, a, _, _ = rows[-1]
        rows.append((MoveKind.LINEAR, y, safe_z, a, Feature.NONE, False))

    approach(poses.right_flank, Feature.RIGHT_FLANK)
    for y, z, a in zip(poses.root.y[1:], poses.root.z[1:], poses.root.a[1:]):
        rows.append((MoveKind.LINEAR, y, z, a, Feature.ROOT, False))
    retract()
    approach(poses.left_flank, Feature.LEFT_FLANK)
    retract()
    approach(poses.tip, Feature.TIP)
    retract()
    return rows


def _tile_stations(builder: ToolpathBuilder, spec: GearSpec, machine: Machine, poses: SpacePoses,
                   stations: np.ndarray, feed: float, safe_z: float, first_station: int = 0) -> None:
    """Every station (numbered from `first_station`): once around the gear, space by space; stations tiled with
    numpy."""
    rows = _space_sequence(poses, safe_z)
    kind = np.array([r[0] for r in rows], dtype=np.int8)
    y = np.array([r[1] for r in rows])
    z = np.array([r[2] for r in rows])
    a_rel = np.array([r[3] for r in rows])
    feature = np.array([r[4] for r in rows], dtype=np.int8)
    plunge = np.array([r[5] for r in rows])
    teeth, pitch_deg = spec.teeth, 360.0 / spec.teeth
    per_space, per_station = len(rows), len(rows) * teeth
    n_total = per_station * len(stations)
    space_index = np.tile(np.repeat(np.arange(teeth), per_space), len(stations))
    station_index = first_station + np.repeat(np.arange(len(stations)), per_station)
    turns = station_index * teeth if machine.rotary_continuous else np.zeros(n_total, int)
    # Space k is brought up by A = -k * pitch; continuous tables keep turning the same way.
    a = np.tile(a_rel, teeth * len(stations)) - (space_index + turns) * pitch_deg
    feeds = np.where(np.tile(plunge, teeth * len(stations)), PLUNGE_FEED_FRACTION * feed, feed)
    feeds = np.where(np.tile(kind, teeth * len(stations)) == MoveKind.RAPID, np.nan, feeds)
    builder.extend(np.tile(kind, teeth * len(stations)), stations[station_index - first_station],
                   np.tile(y, teeth * len(stations)), np.tile(z, teeth * len(stations)), a, feeds, False,
                   space_index, station_index, np.tile(feature, teeth * len(stations)))
