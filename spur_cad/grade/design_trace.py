"""Grading a modified gear against its design (ISO 1328-1 with a design profile and a design helix) and how much
of each flank modification was cut (ISO 21771's amounts read from the cut flank).

Traces are deviations from the MODIFIED design (+ material), so the grading's F_alpha, f_f_alpha, f_H_alpha, F_beta,
f_f_beta and f_H_beta are those left after removing the design modification: a correctly cut relief is in class.
`with_design` gives each trace its design trace (the modification along the trace, um: minus the removal), which
the K-chart draws with the tolerance band around it.

The cut modifications: deviation + design is the trace against the unmodified flank (up to a constant), so
r = -(deviation + design) is the removal as cut; it is fitted by least squares with a constant (the flank's
position, the tooth's size) and the unit shapes of spur_cad.geometry.modifications: profile traces with the profile
slope and the designed crowning and tip and root reliefs over the whole usable involute (form to tip circle), helix
traces with the helix slope and the designed crowning and end reliefs over the face width (a shape not designed
is not fitted: the few scallop valleys of a trace do not tell more shapes apart).
Each fitted coefficient is the amount as cut (C_alpha, f_Halpha, C_a, C_f; C_beta, f_Hbeta, C_I, C_II), the mean
over the flank's traces of one side.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from spur_cad.geometry.modifications import SIDES, FlankModification, FlankModifications, normal_offset_mm
from spur_cad.grade.grading import Grading, Trace

MIN_FIT_POINTS = 8
"""A trace needs this many points on the flank (and more than its shapes) to read modification amounts from it."""

Shape = tuple[str, str, float, Callable[[np.ndarray], np.ndarray]]
"""A modification fitted in a trace: name, symbol, designed amount (mm) and its unit shape along the trace (mm of
roll length or face position to mm of removal)."""


@dataclass(frozen=True)
class ModificationCut:
    """One modification of one flank side: its ISO 21771 name and symbol, the designed amount and the amount read
    from the cut flank (um, mean over the traces of that side), and how many traces gave it."""

    side: str
    name: str
    symbol: str
    designed_um: float
    cut_um: float
    traces: int

    def to_json(self) -> dict:
        return {"side": self.side, "name": self.name, "symbol": self.symbol, "designed_um": round(self.designed_um, 3),
                "cut_um": round(self.cut_um, 3), "traces": self.traces}

    @property
    def sentence(self) -> str:
        """'tip relief C_a 15.0 um designed, 14.6 um cut' (the report's line)."""
        return f"{self.name} {self.symbol} {self.designed_um:.1f} \u00b5m designed, {self.cut_um:.1f} \u00b5m cut"


def design_removal_mm(mods: FlankModifications, side: np.ndarray, roll_mm: np.ndarray,
                      x_mm: np.ndarray) -> np.ndarray:
    """The design's removal (mm, + into the tooth) at points labelled by flank side ('right', 'left'; anything else:
    no flank, 0), roll length and face position."""
    side = np.asarray(side)
    removal = np.zeros(len(side))
    for name in SIDES:
        here = side == name
        if np.any(here):
            removal[here] = normal_offset_mm(mods, name, np.asarray(roll_mm)[here], np.asarray(x_mm)[here])
    return removal


def with_design(traces: Sequence[Trace], mods: FlankModifications) -> tuple[Trace, ...]:
    """The traces with their design trace (um, -removal): a profile trace's profile modifications, a helix trace's
    lead modifications. The other direction's modification is a constant along a trace and is not charted (a
    profile trace at the face of a crowned flank is drawn against the involute moved by the crowning there)."""
    found = []
    for trace in traces:
        flank = mods.side(trace.side)
        removal = (flank.profile_offset_mm(trace.position_mm) if trace.kind == "profile"
                   else flank.lead_offset_mm(trace.position_mm))
        found.append(replace(trace, design_um=-1000.0 * removal))
    return tuple(found)


def _profile_shapes(flank: FlankModification) -> list[Shape]:
    """(name, symbol, designed um, unit shape of the roll length) of the profile modifications read from a trace."""
    unit = FlankModification(flank.form_roll_mm, flank.tip_roll_mm, flank.face_width_mm)
    shapes: list[Shape] = [("profile slope", "f_Halpha", flank.profile_slope_mm,
                            replace(unit, profile_slope_mm=1.0).profile_offset_mm)]
    if flank.profile_crowning_mm:
        shapes.append(("profile crowning", "C_alpha", flank.profile_crowning_mm,
                       replace(unit, profile_crowning_mm=1.0).profile_offset_mm))
    if flank.tip_relief_mm:
        shapes.append(("tip relief", "C_a", flank.tip_relief_mm, replace(
            unit, tip_relief_mm=1.0, tip_relief_start_roll_mm=flank.tip_relief_start_roll_mm,
            tip_relief_parabolic=flank.tip_relief_parabolic).profile_offset_mm))
    if flank.root_relief_mm:
        shapes.append(("root relief", "C_f", flank.root_relief_mm, replace(
            unit, root_relief_mm=1.0, root_relief_start_roll_mm=flank.root_relief_start_roll_mm,
            root_relief_parabolic=flank.root_relief_parabolic).profile_offset_mm))
    return shapes


def _lead_shapes(flank: FlankModification) -> list[Shape]:
    """(name, symbol, designed um, unit shape of the face position) of the lead modifications read from a trace."""
    unit = FlankModification(flank.form_roll_mm, flank.tip_roll_mm, flank.face_width_mm)
    shapes: list[Shape] = [("helix slope", "f_Hbeta", flank.helix_slope_mm,
                            replace(unit, helix_slope_mm=1.0).lead_offset_mm)]
    if flank.lead_crowning_mm:
        shapes.append(("lead crowning", "C_beta", flank.lead_crowning_mm,
                       replace(unit, lead_crowning_mm=1.0).lead_offset_mm))
    if flank.front_end_relief_mm:
        shapes.append(("end relief, front face", "C_I", flank.front_end_relief_mm, replace(
            unit, front_end_relief_mm=1.0,
            front_end_relief_length_mm=flank.front_end_relief_length_mm).lead_offset_mm))
    if flank.back_end_relief_mm:
        shapes.append(("end relief, back face", "C_II", flank.back_end_relief_mm, replace(
            unit, back_end_relief_mm=1.0, back_end_relief_length_mm=flank.back_end_relief_length_mm).lead_offset_mm))
    return shapes


def _fitted_amounts_um(position_mm: np.ndarray, removal_um: np.ndarray, shapes: list[Shape]) -> np.ndarray | None:
    """Least-squares amounts (um) of `shapes` in a removal trace, beside a constant; None for too few points."""
    if len(position_mm) < max(MIN_FIT_POINTS, len(shapes) + 2):
        return None
    columns = [np.ones_like(position_mm)] + [np.asarray(shape(position_mm), float) for *_, shape in shapes]
    amounts, *_ = np.linalg.lstsq(np.column_stack(columns), removal_um, rcond=None)
    return amounts[1:]


def _valleys(position_mm: np.ndarray, removal_um: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The trace's points where the most was removed locally (the scallops' valleys: where the tool touched the
    flank), in position order; all points when fewer than MIN_FIT_POINTS are valleys (a sparse trace)."""
    order = np.argsort(position_mm)
    position, removal = position_mm[order], removal_um[order]
    padded = np.concatenate([[-np.inf], removal, [-np.inf]])
    valley = (padded[1:-1] >= padded[:-2]) & (padded[1:-1] >= padded[2:])
    return (position[valley], removal[valley]) if np.count_nonzero(valley) >= MIN_FIT_POINTS else (position, removal)


def modifications_cut(traces: Sequence[Trace], mods: FlankModifications) -> tuple[ModificationCut, ...]:
    """Each flank side's modifications as designed and as cut (see the module docstring), from traces that carry
    their design trace (`with_design`): profile traces on the usable involute, helix traces over the face."""
    found: list[ModificationCut] = []
    for side in SIDES:
        flank = mods.side(side)
        for kind, shapes, (low, high) in (("profile", _profile_shapes(flank), (flank.form_roll_mm, flank.tip_roll_mm)),
                                          ("helix", _lead_shapes(flank), (0.0, flank.face_width_mm))):
            amounts = []
            for trace in traces:
                if trace.kind != kind or trace.side != side or trace.design_um is None:
                    continue
                inside = (trace.position_mm >= low - 1e-9) & (trace.position_mm <= high + 1e-9)
                position, removal_um = _valleys(trace.position_mm[inside],
                                                -(trace.deviation_um + trace.design_um)[inside])
                fitted = _fitted_amounts_um(position, removal_um, shapes)
                if fitted is not None:
                    amounts.append(fitted)
            if not amounts:
                continue
            mean = np.mean(amounts, axis=0)
            found.extend(ModificationCut(side, name, symbol, 1000.0 * designed, float(cut), len(amounts))
                         for (name, symbol, designed, _), cut in zip(shapes, mean))
    return tuple(found)


def against_design(grading: Grading, mods: FlankModifications | None) -> Grading:
    """A Grading of traces taken against the modified design, with their design traces and the modifications as
    cut (unchanged when the gear has no modification)."""
    if mods is None:
        return grading
    traces = with_design(grading.traces, mods)
    return replace(grading, traces=traces, modifications_cut=modifications_cut(traces, mods))
