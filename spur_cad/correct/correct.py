"""Corrected programs from a measured gear (`spur-cad correct`, docs/correction.md): identify the machine's
errors (spur_cad.correct.identify), re-plan the job with the tool as it cuts, take the table's error e(A) (and a blank's
offset) out of every block (spur_cad.correct.apply) and post the corrected programs with correction.json."""

from __future__ import annotations

import dataclasses

import numpy as np

from spur_cad.cam.ir import Feature
from spur_cad.cam.strategies import get_strategy
from spur_cad.correct.apply import (
    ONCE_PER_TURN_MODELS,
    AppliedCorrection,
    blank_corrected,
    linuxcnc_compensation,
    table_corrected,
)
from spur_cad.correct.identify import IdealFlanks, Identified
from spur_cad.dialects import dialect
from spur_cad.geometry.kinds import EXTERNAL_SPUR, INTERNAL_SPUR
from spur_cad.grade.measured import MeasuredPoints
from spur_cad.grade.simulated import SIDES, helix_range_mm, profile_range_mm

IDEAL_RESOLUTION_MM = 0.002
CORRECTED_KINDS = frozenset({EXTERNAL_SPUR, INTERNAL_SPUR})
"""The kinds spur-cad correct corrects: prismatic teeth, one transverse section's deviation at every X (a helical
gear's measured points are refused)."""
"""The ideal cut is simulated this finely: its scallops' mean (1.6 um for the reference gear's 5 um target) must
be known to a fraction of a micrometre, since the measured mean less it is the tool's size error."""


def finishing_cut(spec, path, tool, stock, x_range_mm: tuple[float, float], stations=None,
                  resolution_mm: float = IDEAL_RESOLUTION_MM, modifications=None):
    """The finishing toolpath alone cut into the stock cylinder over `x_range_mm` (spur_cad.sim.simulate): the
    flanks are the finishing's, whatever roughing left; deviations from the modified design with `modifications`."""
    from spur_cad.sim.simulate import Cut, SimSettings, simulate

    return simulate(spec, stock, [Cut(path, tool)], SimSettings(resolution_mm=resolution_mm),
                    station_x=stations, rows_x_range=x_range_mm, modifications=modifications)


def ideal_flanks(job, plan) -> IdealFlanks:
    """What the job's finishing leaves on an ideal machine over the face, per side against roll length (the mean
    over spaces and rows at each design point), from the modified design when the job has modifications: the
    scallops alone, as identify reads the measured points."""
    from spur_cad.pipeline import job_stock

    spec = job.gear
    result = finishing_cut(spec, plan.finishing.toolpath, plan.finishing.tool, job_stock(job),
                           (0.0, spec.face_width_mm), plan.finishing.result.station_x_mm,
                           modifications=job.modifications)
    grid = result.grid
    names = grid.feature_names()
    mean = result.gear_deviation.mean(axis=(0, 2))
    radius = np.hypot(grid.points[:, 0], grid.points[:, 1])
    roll = np.sqrt(np.maximum(radius ** 2 - spec.base_radius_mm ** 2, 0.0))
    rolls, deviations = {}, {}
    for side in SIDES:
        on = np.array([name == f"{side} involute" for name in names])
        order = np.argsort(roll[on])
        rolls[side], deviations[side] = roll[on][order], mean[on][order]
    return IdealFlanks(rolls, deviations)


def corrected_job(job, identified: Identified):
    """The job with the finishing tool's diameter changed by the size error (2 x: the radius cuts each flank):
    material left (+) asks for a smaller programmed tool, which cuts deeper."""
    tools = job.tools
    finishing = dataclasses.replace(tools.finishing,
                                    diameter_mm=tools.finishing.diameter_mm - 2.0 * identified.size_um / 1000.0)
    return dataclasses.replace(job, tools=dataclasses.replace(tools, finishing=finishing))



FLANK_SIDES = {Feature.RIGHT_FLANK: "right", Feature.LEFT_FLANK: "left"}


def slope_corrected_passes(spec, passes, identified: Identified) -> tuple:
    """The generating passes with each flank pass moved along its normal (the machine's Y, toward the material it
    cuts: `side`) by what the identified slopes left at its line: the profile slope at the pass's contact roll
    length r_b t (0 at the middle of the evaluation range, so the flank's mean position is the size correction's)
    and the helix slope along X (0 at the middle of the helix range): a Y offset and a Y rate along X. Fillet, root
    and land passes keep their place."""
    start, end = profile_range_mm(spec)
    front, back = helix_range_mm(spec.face_width_mm, spec.module_mm)
    moved = []
    for p in passes:
        side = FLANK_SIDES.get(p.feature)
        if p.mode != "flank" or side is None:
            moved.append(p)
            continue
        profile_mm = identified.profile_slope_um.get(side, 0.0) / 1000.0
        helix_per_x = identified.helix_slope_um.get(side, 0.0) / 1000.0 / (back - front)
        roll_mm = spec.base_radius_mm * p.roll_rad
        remove_mm = profile_mm * (roll_mm - 0.5 * (start + end)) / (end - start) - helix_per_x * 0.5 * (front + back)
        moved.append(dataclasses.replace(p, y_mm=p.y_mm + p.side * remove_mm,
                                         dy_per_x=p.dy_per_x + p.side * helix_per_x))
    return tuple(moved)


def slope_corrected_finishing(job, finishing, identified: Identified):
    """The finishing plan with its passes moved for the slopes (slope_corrected_passes), or unchanged (with the
    reason) when its strategy has no straight passes to move."""
    from spur_cad.cam.strategies.generating import passes_toolpath

    if not get_strategy(finishing.result.strategy, job.strategies).corrects_slopes:
        following = " or ".join(name for name, strategy in job.strategies.items() if strategy.corrects_slopes)
        return finishing, (f"the {finishing.result.strategy} finishing strategy's moves are not straight passes "
                           f"tangent at one roll: the slopes are not corrected ({following} finishing can follow "
                           "them)")
    spec = job.gear
    passes = slope_corrected_passes(spec, finishing.result.passes, identified)
    toolpath = passes_toolpath(spec, finishing.tool, job.machine, finishing.result.params, passes,
                               job.stock.blank_radius_mm(spec))
    return dataclasses.replace(finishing, toolpath=toolpath,
                               result=dataclasses.replace(finishing.result, passes=passes)), None


def _identify_probe_log(job, log, ideal: IdealFlanks) -> Identified:
    """identify_probed on a probe log's deviations from the job's probing plan (its [probe] section), read from the
    modified design when the job has modifications."""
    from spur_cad.cam.probing import plan_probe
    from spur_cad.correct.identify import identify_probed
    from spur_cad.errors import SpurCadError
    from spur_cad.grade.probe_log import labelled_deviations

    spec = job.gear
    if job.probe is None:
        raise SpurCadError(f"{log.source}: a probe log, but the job has no [probe] section to name its trips "
                           "(correct with the job that wrote the probing program)")
    plan = plan_probe(spec, job.stock, job.machine, job.probe)
    trips = labelled_deviations(spec, plan, log, job.post.rotary_sign, job.modifications)
    return identify_probed(spec, trips.space, trips.side, trips.roll_mm, trips.x_mm, trips.deviation_mm, ideal)


def machine_correction(identified: Identified,
                       once_per_turn: str) -> tuple[tuple[int, ...], tuple[float, float] | None]:
    """(the orders of e(A) to move out of the A words, the datum offset to move out of Y and Z (um) or None): every
    kept order in the A words, but order 1 in Y and Z when a once-per-turn error is taken for the blank's offset."""
    table = identified.table
    if table is None:
        return (), None
    orders = tuple(h.order for h in table.kept)
    if once_per_turn == "blank" and 1 in orders and identified.blank_offset_um is not None:
        cy, cz = identified.blank_offset_um  # the gear's centre as cut about the datum: the datum is at -c
        return tuple(order for order in orders if order != 1), (-cy, -cz)
    return orders, None


def corrected_plan_of(job, identified: Identified, once_per_turn: str = "table"):
    """(the corrected job, its plan with the corrections, AppliedCorrection): the job re-planned with the finishing
    tool as it cuts (its modifications kept: the finishing still cuts the modified flanks), the generating flank passes
    moved for the slopes, every block's A of every operation moved by -e(A) (spur_cad.correct.apply) and, for a
    once-per-turn error taken for the blank's offset, its Y and Z by the offset turned to its A; unfolded when a
    correction differs from block to block."""
    from spur_cad.pipeline import plan_cam

    fixed = corrected_job(job, identified)
    fixed_plan = plan_cam(fixed)
    finishing, slopes_not_corrected = slope_corrected_finishing(fixed, fixed_plan.finishing, identified)
    fixed_plan = dataclasses.replace(fixed_plan, finishing=finishing)
    orders, datum_offset = machine_correction(identified, once_per_turn)
    table = identified.table
    moved = {}
    for name in ("roughing", "roughing_bottom", "finishing"):
        planned = getattr(fixed_plan, name)
        if planned is None:
            continue
        path = table_corrected(planned.toolpath, table, orders) if orders and table is not None else planned.toolpath
        path = blank_corrected(path, datum_offset) if datum_offset is not None else path
        moved[name] = dataclasses.replace(planned, toolpath=path)
    applied = AppliedCorrection(
        job.tools.finishing.diameter_mm, fixed.tools.finishing.diameter_mm, orders, datum_offset,
        once_per_turn if identified.blank_offset_um is not None and identified.table is not None
        and any(h.order == 1 for h in identified.table.kept) else None,
        job.post.folded and (bool(orders) or datum_offset is not None), slopes_not_corrected)
    if applied.unfolded:
        fixed = dataclasses.replace(fixed, post=dataclasses.replace(fixed.post, folded=False))
    return fixed, dataclasses.replace(fixed_plan, **moved), applied


def correct_job(job, measured, measured_source: str, datum: str = "best-fit", once_per_turn: str = "table"):
    """Identify the errors in `measured` (spur_cad.grade.measured.MeasuredPoints about the datum `datum`, or a ProbeLog
    of the job's probing program: then the size and slopes only, identify_probed) and build the corrected output set:
    every program re-planned with the finishing tool as it cuts and the table's error (and a blank's offset) taken out
    of every block, correction.json, a LinuxCNC compensation file for the A joint when the table's error was seen
    (linuxcnc dialect), and report.html (the corrected job's run on its corrected plan, with the Correction section).
    Returns (Identified, AppliedCorrection, {name: bytes})."""
    import json

    from spur_cad.correct.identify import identify
    from spur_cad.correct.summary import correction_facts, correction_summary
    from spur_cad.errors import SpurCadError
    from spur_cad.pipeline import build_programs, plan_cam, run_job
    from spur_cad.sim.contact import contact_angles

    spec = job.gear
    if spec.kind not in CORRECTED_KINDS:
        raise SpurCadError(f"correcting from measured points of an {spec.kind.name} gear is not supported yet (spur "
                           "gears only)")
    if job.tools.finishing is None:
        raise SpurCadError("the job has no [tools.finishing]: there is no finishing program to correct")
    if once_per_turn not in ONCE_PER_TURN_MODELS:
        raise SpurCadError(f"--once-per-turn must be one of {', '.join(ONCE_PER_TURN_MODELS)}, got {once_per_turn!r}")
    plan = plan_cam(job)
    finishing = plan.finishing
    if finishing is None:
        raise SpurCadError("the job plans no finishing: there is no finishing program to correct")
    try:
        if isinstance(measured, MeasuredPoints):
            contacts = contact_angles(spec, finishing.toolpath, finishing.tool)
            identified = identify(spec, measured, contacts, ideal_flanks(job, plan), job.modifications, datum)
        else:
            identified = _identify_probe_log(job, measured, ideal_flanks(job, plan))
    except ValueError as exc:
        raise SpurCadError(f"{measured_source}: {exc}") from None
    fixed, corrected_plan, applied = corrected_plan_of(job, identified, once_per_turn)
    changes = [f"finishing tool programmed as D {fixed.tools.finishing.diameter_mm:.4f} mm (size error "
               f"{identified.size_um:+.2f} um)"]
    if applied.table_orders:
        plural = "s" if len(applied.table_orders) > 1 else ""
        changes.append(f"every block's A moved by -e(A), the table's error of order{plural} "
                       + ", ".join(map(str, applied.table_orders)))
    if applied.blank_offset_um is not None:
        changes.append("every block's Y and Z moved by the blank's offset turned to its A")
    if applied.unfolded:
        changes.append("unfolded (the correction differs per block)")
    if applied.slopes_not_corrected is None:
        changes.append("flank passes moved for the profile and helix slopes")
    notes = (f"corrected from {measured_source}: " + "; ".join(changes) + " (correction.json)",)
    _, files = build_programs(fixed, corrected_plan, notes)
    summary = correction_summary(spec, identified, applied, measured_source)
    if applied.table_orders and identified.table is not None \
            and dialect(job.post.dialect, job.dialects).rs274_checkable:  # a LinuxCNC control
        a_values = np.concatenate([planned.toolpath.a for planned in (corrected_plan.roughing,
                                                                      corrected_plan.roughing_bottom,
                                                                      corrected_plan.finishing)
                                   if planned is not None])
        files[COMPENSATION_FILE] = linuxcnc_compensation(identified.table, applied.table_orders,
                                                         (float(a_values.min()), float(a_values.max()))).encode()
        summary["corrections"]["compensation_file"] = {
            "file": COMPENSATION_FILE,
            "how": "for the user who would rather fix the machine than the program: LinuxCNC's joint compensation "
                   "for the A joint ([JOINT_n] COMP_FILE = a_axis.comp with COMP_FILE_TYPE = 1, which must be set: "
                   "nominal, forward and reverse trim in degrees, trim = nominal - actual = -e(A), which LinuxCNC "
                   "adds to the commanded A; nominal is the joint's machine position, the programs' A with a zero A "
                   "work offset); with it loaded, run the original programs, not the corrected ones (their A words "
                   "already carry the correction)"}
    files["correction.json"] = (json.dumps(summary, indent=2) + "\n").encode()
    # the report's own simulation would cut the corrected programs on an ideal machine, where the corrections show
    # as deviations (a warned "gouge" of the size error): it is left out; the Correction section predicts the gear
    # on the measured machine instead
    unsimulated = dataclasses.replace(fixed, simulation=dataclasses.replace(fixed.simulation, enabled=False))
    files["report.html"] = run_job(unsimulated, plan=corrected_plan,
                                   correction=correction_facts(summary)).files["report.html"]
    return identified, applied, files


COMPENSATION_FILE = "a_axis.comp"
"""The LinuxCNC joint compensation file of the corrected set (when the table's error was seen and corrected)."""
