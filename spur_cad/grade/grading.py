"""One type for a gear's ISO 1328-1 grade, simulated or measured: `Grading`, computed once and read by the
summary, the report, the K-chart and `spur-cad grade` (its `to_json()` is what summary.json's `grading` and
grade.json hold).

`grade_traces` is the one place where worst deviations become classes; the simulated and the measured
grading only differ in how they obtain traces and flank positions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spur_cad.geometry.spec import GearSpec
from spur_cad.grade.iso1328 import (
    DEVIATIONS,
    KINDS,
    class5_um,
    class_of,
    evaluate_trace,
    pitch_deviations,
    tolerance_um,
    validity_problems,
)

STANDARD = "ISO 1328-1:2013"
PROFILE_DEVIATIONS = ("f_Ha", "f_fa", "F_a")
HELIX_DEVIATIONS = ("f_Hb", "f_fb", "F_b")


@dataclass(frozen=True)
class Trace:
    """One measured trace: where (space, side, X for a profile trace), positions (mm) and deviations (um) from the
    design; a modified gear's traces also carry the design trace (um: the modified design against the unmodified
    involute or helix, spur_cad.grade.design_trace), which the K-chart draws."""

    kind: str  # "profile" or "helix"
    space: int
    side: str
    x_mm: float | None
    position_mm: np.ndarray
    deviation_um: np.ndarray
    evaluation: tuple[float, float]
    design_um: np.ndarray | None = None


@dataclass(frozen=True)
class Location:
    """Where a worst deviation is: a trace's space, side and X (None for a helix trace), a single pitch
    deviation's side and space, or the side of a total cumulative pitch deviation."""

    kind: str  # "trace", "pitch" or "cumulative"
    side: str
    space: int | None = None
    x_mm: float | None = None

    def to_json(self) -> dict:
        if self.kind == "trace":
            return {"space": self.space, "side": self.side, "x_mm": self.x_mm}
        if self.kind == "pitch":
            return {"side": self.side, "space": self.space}
        return {"side": self.side}


@dataclass(frozen=True)
class SidePitch:
    """One flank side's pitch: the single pitch deviation of every space, f_pt and F_p (um)."""

    single_um: tuple[float, ...]
    f_pt_um: float
    F_p_um: float

    def to_json(self) -> dict:
        return {"single_um": list(self.single_um), "f_pt_um": self.f_pt_um, "F_p_um": self.F_p_um}


@dataclass(frozen=True)
class MeasuredFit:
    """How measured points were fitted to the design: the scan's turn, its centre, the rms deviation and the
    datum: "best-fit" (centre and turn fitted), "axis" (the file's origin is the gear's axis: turn only) or
    "probe log" (the A axis of the probing: no fit)."""

    rotation_deg: float
    centre_mm: tuple[float, float]
    rms_deviation_um: float
    datum: str = "best-fit"

    def to_json(self) -> dict:
        return {"datum": self.datum, "rotation_deg": self.rotation_deg, "centre_mm": list(self.centre_mm),
                "rms_deviation_um": self.rms_deviation_um}


@dataclass(frozen=True)
class Grading:
    """A gear's ISO 1328-1:2013 grade: worst deviations (um) and where, each one's class (None: beyond 11),
    the gear's class (the worst; None when beyond 11 or nothing graded), the validity of the formulas, and
    the traces (for charts). Simulated grading adds the class-5 tolerances and every space's pitch;
    measured grading the number of points, the fit and notes. A modified gear's grading is against the modified
    design and says how much of each modification was cut (`modifications_cut`)."""

    deviations_um: dict[str, float]
    where: dict[str, Location]
    classes: dict[str, int | None]
    overall_class: int | None
    validity: tuple[str, ...]
    traces: tuple[Trace, ...]
    class5_tolerances_um: dict[str, float] | None = None
    class5_unrounded_um: dict[str, float] | None = None
    pitch: dict[str, SidePitch] | None = None
    points: int | None = None
    fit: MeasuredFit | None = None
    notes: tuple[str, ...] = ()
    modifications_cut: tuple | None = None  # spur_cad.grade.design_trace.ModificationCut, modified gears only

    @property
    def measured(self) -> bool:
        return self.fit is not None

    @property
    def has_profile_traces(self) -> bool:
        return any(trace.kind == "profile" for trace in self.traces)

    def to_json(self) -> dict:
        """The JSON form (summary.json `grading`, grade.json): the traces are left out; a modified gear's adds
        `modifications_cut`."""
        cut = {} if self.modifications_cut is None else {
            "modifications_cut": [item.to_json() for item in self.modifications_cut]}
        where = {name: place.to_json() for name, place in self.where.items()}
        if self.fit is not None:  # measured
            return {"standard": STANDARD, "points": self.points, "notes": list(self.notes),
                    "fit": self.fit.to_json(), "deviations_um": dict(self.deviations_um), "where": where,
                    "classes": dict(self.classes), "class": self.overall_class, "validity": list(self.validity), **cut}
        tolerances, unrounded, pitch = self.class5_tolerances_um, self.class5_unrounded_um, self.pitch
        if tolerances is None or unrounded is None or pitch is None:
            raise ValueError("a simulated grading without its class 5 tolerances and pitch has no JSON form")
        return {"standard": STANDARD, "deviations_um": dict(self.deviations_um), "where": where,
                "classes": dict(self.classes), "class": self.overall_class,
                "class5_tolerances_um": dict(tolerances), "class5_unrounded_um": dict(unrounded),
                "pitch": {side: p.to_json() for side, p in pitch.items()}, "validity": list(self.validity), **cut}


def worst_deviations(measured: list[Trace]) -> tuple[dict[str, float], dict[str, Location]]:
    """The worst (largest |value|) profile and helix slope, form and total deviation over the traces, and where
    each is; traces with fewer than three points in their evaluation range are left out, and a deviation no
    trace gave is missing from both dicts (not 0: it was not measured). f_pt and F_p start at 0."""
    worst = {name: 0.0 for name in DEVIATIONS.values()}
    where: dict[str, Location] = {}
    evaluated: set[str] = set()
    for trace in measured:
        try:
            values = evaluate_trace(trace.position_mm, trace.deviation_um, *trace.evaluation)
        except ValueError:
            continue
        names = PROFILE_DEVIATIONS if trace.kind == "profile" else HELIX_DEVIATIONS
        for name, value in zip(names, (values.slope_um, values.form_um, values.total_um)):
            evaluated.add(name)
            if abs(value) >= abs(worst[name]) and (name not in where or abs(value) > abs(worst[name])):
                worst[name] = value
                where[name] = Location("trace", trace.side, trace.space, trace.x_mm)
    return {name: value for name, value in worst.items() if name in evaluated or name in ("f_pt", "F_p")}, where


def add_pitch(worst: dict[str, float], where: dict[str, Location], side: str,
              positions_um: np.ndarray) -> SidePitch:
    """Grade one side's flank positions (every space, um): update the worst f_pt / F_p and return the side's
    pitch."""
    single, f_pt, f_p = pitch_deviations(positions_um)
    if f_pt > worst["f_pt"]:
        worst["f_pt"], where["f_pt"] = f_pt, Location("pitch", side, int(np.argmax(np.abs(single))))
    if f_p > worst["F_p"]:
        worst["F_p"], where["F_p"] = f_p, Location("cumulative", side)
    return SidePitch(tuple(round(float(v), 3) for v in single), f_pt, f_p)


def classes_of(spec: GearSpec, worst: dict[str, float], graded: set[str]) -> tuple[dict[str, int | None], int | None]:
    """Each graded deviation's class (in the tolerance order of ISO 1328-1) and the gear's (the worst; None when
    one is beyond 11 or nothing is graded)."""
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    classes = {DEVIATIONS[kind]: class_of(kind, worst[DEVIATIONS[kind]], d, b, m) for kind in KINDS
               if DEVIATIONS[kind] in graded}
    within = [c for c in classes.values() if c is not None]
    overall = None if not classes or len(within) < len(classes) else max(within)
    return classes, overall


def validity(spec: GearSpec) -> tuple[str, ...]:
    """Where the gear is outside the range of the standard's formulas."""
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    return tuple(validity_problems(spec.teeth, d, m, b, math.degrees(spec.helix_angle_rad)))


def class5(spec: GearSpec) -> tuple[dict[str, float], dict[str, float]]:
    """The gear's class-5 tolerances: rounded as the standard tabulates them, and unrounded (um)."""
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    return ({kind: tolerance_um(kind, 5, d, b, m) for kind in KINDS},
            {kind: round(value, 3) for kind, value in class5_um(d, b, m).items()})
