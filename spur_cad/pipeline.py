"""The job pipeline shared by the CLI and the FreeCAD workbench: job in, output files out (in memory).

`run_job` computes every output of a job (profile, STEP, toolpath programs, simulation, report,
summary) without touching the file system, so both front ends write exactly the same bytes for
the same job. The stages: profile -> CAD -> CAM plan (spur_cad.cam.plan) -> posts -> simulation
-> summary (spur_cad.summary) -> report; see docs/architecture.md.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import os
import time
from typing import TYPE_CHECKING, Callable, TypeVar

import numpy as np

from spur_cad.cad_stage import build_cad
from spur_cad.cam.plan import CamInputs, CamPlan
from spur_cad.cam.plan import plan_cam as plan_cam_inputs
from spur_cad.cam.setups import LYING_FLAT, ROTARY_TABLE, MachineSetup
from spur_cad.cam.three_axis import ThreeAxisFinishingFacts
from spur_cad.errors import shown_path
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, GearKind
from spur_cad.geometry.sampling import ProfileSamples, sample_profile
from spur_cad.inputs import step_timestamp
from spur_cad.job import Job
from spur_cad.result import CadResult, CorrectionFacts, ErrorBudgetFacts, JobResult
from spur_cad.summary import build_result, summary_json
from spur_cad.version import __version__

if TYPE_CHECKING:
    from spur_cad.cad_worker import CadWorker
    from spur_cad.cam.restart import RestartPoint
    from spur_cad.geometry.spec import GearSpec
    from spur_cad.grade.grading import Grading
    from spur_cad.post.program import PostedProgram, ProgramInfo
    from spur_cad.sim.budget import ErrorBudget
    from spur_cad.sim.design import DesignGrid
    from spur_cad.sim.engagement import Engagement
    from spur_cad.sim.simulate import Cut, SimResult, StockCylinder

Value = TypeVar("Value")  # what a stage computes (run_job's timer returns it)


def profile_csv(samples: ProfileSamples, unmodified: np.ndarray | None = None) -> bytes:
    """Right half of one tooth space, root (x = 0) to tip, header x_mm,y_mm. A modified gear's samples come with
    the `unmodified` design points under them: columns unmodified_x_mm, unmodified_y_mm and removal_um (the
    distance between the two, positive into the tooth)."""
    buffer = io.StringIO()
    if unmodified is None:
        buffer.write("x_mm,y_mm\n")
        np.savetxt(buffer, samples.points, fmt="%.9f", delimiter=",")
        return buffer.getvalue().encode()
    away = unmodified - samples.points
    removal_um = 1000.0 * np.sign(np.einsum("ij,ij->i", away, samples.normals)) * np.hypot(*away.T)
    buffer.write("x_mm,y_mm,unmodified_x_mm,unmodified_y_mm,removal_um\n")
    np.savetxt(buffer, np.column_stack([samples.points, unmodified, removal_um]), fmt="%.9f", delimiter=",")
    return buffer.getvalue().encode()


def job_profile_csv(job: Job, samples: ProfileSamples) -> bytes:
    """profile.csv of the job: the design samples, or for a modified gear the right flank's modified profile at
    mid-face (X = b/2) with the unmodified one beside it."""
    if job.modifications is None:
        return profile_csv(samples)
    from spur_cad.geometry.modifications import modified_tooth_space_profile, sample_modified_profile

    modified = modified_tooth_space_profile(job.gear.tooth_space_profile(), job.modifications.right,
                                            job.gear.face_width_mm / 2.0)
    return profile_csv(*sample_modified_profile(modified, job.job.profile_tolerance_mm))


def modified_flank_samples(job: Job) -> dict | None:
    """Each flank side's modified profile at mid-face (X = b/2) and the unmodified points under it, for the
    report's profile figure; None for an unmodified job."""
    if job.modifications is None:
        return None
    from spur_cad.geometry.modifications import SIDES, modified_tooth_space_profile, sample_modified_profile

    flanks = {}
    for side in SIDES:
        modified = modified_tooth_space_profile(job.gear.tooth_space_profile(), job.modifications.side(side),
                                                job.gear.face_width_mm / 2.0)
        samples, design = sample_modified_profile(modified, job.job.profile_tolerance_mm)
        flanks[side] = (samples.points, design)
    return flanks


def run_job(job: Job, progress: Callable[[str, float], None] | None = None,
            checkpoint: Callable[[], None] | None = None, restart: RestartPoint | None = None,
            plan: CamPlan | None = None, correction: CorrectionFacts | None = None,
            cad_worker: CadWorker | None = None) -> JobResult:
    """Compute every output of the job in memory (no file I/O): the typed result with its output set in
    `files` ({name: bytes}, for spur_cad.outputs.write_output_set). `progress(stage, fraction)` is told how
    far each long stage is (the CLI draws progress bars with it); `checkpoint()` is called before every
    stage (the CLI stops there when a signal has arrived, never inside a library). `restart` adds a program
    restarting an operation there (restart_program). spur-cad correct gives its corrected `plan` (else the job's is
    planned) and its `correction` (spur-cad correct's, typed), which the report shows. `cad_worker` (a started
    spur_cad.cad_worker.CadWorker, which run_job stops before it returns) builds the CAD stage in a second process
    while this one does the rest, which then never imports OCP: the command line's choice; without it (FreeCAD:
    OCCT loaded, no Python executable to start; spur-cad correct) the CAD is built here."""
    from spur_cad.dependencies import require_jinja2, require_ocp
    from spur_cad.report.html import render_report
    from spur_cad.report.plots import tooth_space_png
    from spur_cad.report.stage import plan_images, simulation_images

    require_ocp()  # before any work: a missing package is one line, not a failure in the CAD stage
    require_jinja2()

    def tell(stage: str, fraction: float) -> None:
        if progress is not None:
            progress(stage, fraction)

    timestamp = step_timestamp(os.environ)  # checked before any work (the CLI checks it before any import)
    seconds: dict[str, float] = {}

    def timed(name: str, stage: str | None, compute: Callable[[], Value]) -> Value:
        if checkpoint is not None:
            checkpoint()
        start = time.perf_counter()
        if stage:
            tell(stage, 0.0)
        value = compute()
        if stage:
            tell(stage, 1.0)
        seconds[name] = time.perf_counter() - start
        return value

    if cad_worker is not None:
        cad_worker.submit(job, timestamp)
    with cad_worker if cad_worker is not None else contextlib.nullcontext() as worker:
        samples = timed("profile", None, lambda: sample_profile(job.gear.tooth_space_profile(),
                                                                job.job.profile_tolerance_mm))
        png = timed("plot", None, lambda: tooth_space_png(job.gear, samples, modified_flank_samples(job)))
        if worker is None:
            cad, step = timed("cad_and_step", "CAD and STEP", lambda: build_cad(job, checkpoint, timestamp))
        if plan is None:
            plan = timed("cam", "toolpaths", lambda: plan_cam(job, checkpoint))
        programs, program_files = timed("post", None, lambda: build_programs(job, plan))
        program_files.update(other_programs(job, plan, restart, timed))
        drawings = timed("export", None, lambda: export_files(job)) if job.export.dxf or job.export.svg else {}
        # The figures from the plan are drawn while the CAD worker builds; a run whose simulation loads numba then
        # waits for the worker first, so that OCP (in the worker) and numba are never resident at once: the run's
        # memory is the larger of the two processes', not their sum
        images = timed("plan_figures", None, lambda: plan_images(png, job.gear, job.stock.blank_radius_mm(job.gear),
                                                                 plan, job.modifications))
        waits_before_simulating = worker is not None and simulates_with_kernels(job, plan)
        if worker is not None and waits_before_simulating:
            cad, step = cad_from_worker(worker, timed, seconds)
        sim_result = timed("simulation", "simulation",
                           lambda: simulate_stage(job, plan, lambda fraction: tell("simulation", fraction)))
        grading = timed("grading", None, lambda: grade_stage(job, sim_result, plan))
        budget = timed("error_budget", None, lambda: budget_stage(job, plan, sim_result, grading))
        # The simulation's figures read no CAD facts either: drawn from a result without them
        result = build_result(job, samples, None, plan, job.post, programs, sim_result, grading, seconds, budget)
        images.update(timed("report", "report", lambda: simulation_images(result, job.gear, plan, sim_result)))
        if worker is not None and not waits_before_simulating:
            cad, step = cad_from_worker(worker, timed, seconds)
        result = dataclasses.replace(result, cad=cad, correction=correction)
        template_source = shown_path(job.job.report_template) if job.job.report_template else "report.html.j2"
        figures_s = seconds["report"] + seconds.pop("plan_figures")
        report = timed("report", None, lambda: render_report(result, images, job.report_template_text,
                                                             template_source))
        seconds["report"] += figures_s  # figures and page: the report stage
        result = dataclasses.replace(result, timings_s=dict(seconds))
        files = {
            "profile.csv": job_profile_csv(job, samples),
            "profile.png": png,
            **step,
            **program_files,
            **drawings,
            "report.html": report,
            "summary.json": (json.dumps(summary_json(result), indent=2, sort_keys=False) + "\n").encode(),
        }
        return dataclasses.replace(result, files=files)


def cad_from_worker(worker: CadWorker, timed: Callable, seconds: dict[str, float]) -> tuple[CadResult,
                                                                                             dict[str, bytes]]:
    """Wait for run_job's CAD worker, timed as 'cad_wait' with the CAD stage's bar shown meanwhile; the stage's own
    time ('cad_and_step' in `seconds`) is the worker's."""
    cad, step, seconds["cad_and_step"] = timed("cad_wait", "CAD and STEP", worker.result)
    return cad, step


def other_programs(job: Job, plan: CamPlan, restart: RestartPoint | None, timed: Callable) -> dict[str, bytes]:
    """The restart, lathe and probing programs the run asks for ({name: text}); `timed(name, stage, compute)` is
    run_job's timer (the restart program is not timed)."""
    files = {}
    if restart is not None:
        name, text = restart_program(job, plan, restart)
        files[name] = text
    if job.lathe is not None:
        name, text = timed("lathe", None, lambda: lathe_program(job))
        files[name] = text
    if job.probe is not None:
        name, text = timed("probe", None, lambda: probe_program(job))
        files[name] = text
    return files


def grade_stage(job: Job, sim_result: SimResult | None, plan: CamPlan | None = None) -> Grading | None:
    """The simulated gear's ISO 1328-1 grade (None without a simulation), computed once per run; a 3-axis plan's
    profiles are evaluated from where its finishing tool leaves the involute (its form diameter)."""
    if sim_result is None:
        return None
    from spur_cad.grade.simulated import grade_simulation

    return grade_simulation(job.gear, sim_result, three_axis_profile_start_mm(plan), job.modifications)


def three_axis_profile_start_mm(plan: CamPlan | None) -> float | None:
    """Where a 3-axis plan's finishing tool leaves the involute (radius, mm); None for any other plan."""
    facts = plan.finishing.result.facts if plan is not None and plan.finishing is not None else None
    return facts.form_diameter_mm / 2.0 if isinstance(facts, ThreeAxisFinishingFacts) else None


def error_budget(job: Job, plan: CamPlan) -> ErrorBudget:
    """The job's error budget (spur_cad.sim.budget.ErrorBudget): [machine]'s accuracy keys, the calibration table
    and the finishing tool's deflection in the job's material (on the finish stock roughing leaves). On 3 axes the
    linear axes, runout and tool size only: no table indexes the spaces, and the deflection model (a corner's arc
    in the finish stock) is not the cut of a flat end mill's side over a whole step-down (docs/simulation.md)."""
    return SETUP_BUDGETS[job.machine.setup](job, plan)


def _lying_flat_budget(job: Job, plan: CamPlan) -> ErrorBudget:
    """The 3-axis machine's budget: runout, tool size and linear axes (error_budget)."""
    from spur_cad.sim.budget import ErrorBudget

    machine = job.machine
    return ErrorBudget(runout_tir_um=machine.spindle_runout_um + machine.tool_runout_um,
                       tool_radius_error_um=machine.tool_radius_error_um,
                       linear_accuracy_um=machine.linear_accuracy_um, rotary_table=False)


def _rotary_table_budget(job: Job, plan: CamPlan) -> ErrorBudget:
    """The rotary table's budget: its index errors, runout, tool size, linear axes and the finishing deflection."""
    from spur_cad.cam.materials import MATERIALS
    from spur_cad.sim.budget import ErrorBudget, finishing_deflection

    machine, tool = job.machine, plan.finishing.tool if plan.finishing is not None else None
    deflection = None if tool is None else finishing_deflection(
        tool.diameter_mm, tool.effective_corner_radius_mm, tool.stick_out_mm, tool.feed_per_tooth_mm,
        job.roughing.finish_stock_mm, MATERIALS[job.job.material])
    return ErrorBudget(machine.rotary_accuracy_arcsec, machine.rotary_repeatability_arcsec, job.rotary_calibration,
                       machine.spindle_runout_um + machine.tool_runout_um, machine.tool_radius_error_um,
                       machine.linear_accuracy_um, deflection)


SETUP_BUDGETS: dict[MachineSetup, Callable[[Job, CamPlan], ErrorBudget]] = {
    ROTARY_TABLE: _rotary_table_budget, LYING_FLAT: _lying_flat_budget}
"""Each set-up's error budget (error_budget)."""
CONTACT_KINDS = frozenset({EXTERNAL_SPUR})
"""The kinds whose finishing contacts spur_cad.sim.contact finds in a transverse section (finishing_point_angles)."""


def finishing_point_angles(job: Job, plan: CamPlan, grid: DesignGrid) -> np.ndarray | None:
    """The commanded A that cut each involute point of the grid (spur_cad.sim.contact), or None where the finishing's
    contacts are not a transverse section's (a helical gear; an internal one, not checked) or cannot be found: the
    budget then turns each space rigidly at its index angle."""
    from spur_cad.sim.contact import contact_angles, flank_point_angles

    if plan.finishing is None or job.gear.kind not in CONTACT_KINDS:
        return None
    try:
        contacts = contact_angles(job.gear, plan.finishing.toolpath, plan.finishing.tool)
    except ValueError:
        return None
    return flank_point_angles(job.gear, grid, contacts)


def budget_stage(job: Job, plan: CamPlan, sim_result: SimResult | None,
                 grading: Grading | None) -> ErrorBudgetFacts | None:
    """The simulated gear on the budget's machine, graded (spur_cad.result.ErrorBudgetFacts; None without a
    simulation): the budget acts on the simulated flanks, the cut is not simulated again; on 3 axes the 3-axis
    machine's budget (error_budget), graded as the ideal cut is (grade_stage)."""
    if sim_result is None or grading is None:
        return None
    from spur_cad.grade.simulated import grade_simulation
    from spur_cad.sim.budget import apply_budget
    from spur_cad.summary import error_budget_facts

    budget = error_budget(job, plan)
    angles = finishing_point_angles(job, plan, sim_result.grid) if budget.rotary_table else None
    deviation, terms = apply_budget(sim_result.grid, sim_result.deviation, budget, angles)
    expected = grade_simulation(job.gear, dataclasses.replace(sim_result, deviation=deviation),
                                three_axis_profile_start_mm(plan))
    return error_budget_facts(job, terms, budget.deflection, grading, expected)


def build_programs(job: Job, plan: CamPlan, notes: tuple[str, ...] = ()) -> tuple[dict[str, PostedProgram],
                                                                                 dict[str, bytes]]:
    """G-code for each toolpath the plan has: (posted programs by operation, files roughing.<ext>, ...); `notes`
    are added to every header's comments (e.g. spur-cad correct's corrections)."""
    from spur_cad.post import post_program

    settings = job.post
    programs: dict[str, PostedProgram] = {}
    files: dict[str, bytes] = {}
    for name, operation in (("roughing", plan.roughing), ("roughing_bottom", plan.roughing_bottom),
                            ("finishing", plan.finishing)):
        if operation is None:
            continue
        info = program_info(job, plan, name)
        info = dataclasses.replace(info, comments=info.comments + notes)
        program = programs[name] = post_program(operation.toolpath, settings, info, dialects=job.dialects)
        files[f"{name}.{program.extension}"] = program.text.encode()
    return programs, files


def program_info(job: Job, plan: CamPlan, operation: str, restart_comment: str | None = None,
                 approach_z_mm: float | None = None, a_reference_deg: float | None = None) -> ProgramInfo:
    """The header, machine codes and blank box (for Siemens WORKPIECE) of one program."""
    from spur_cad.post import ProgramInfo

    spec, stock, setup = job.gear, job.stock, job.machine.setup
    box = setup.program_box_mm(stock.blank_radius_mm(spec), stock.blank_x_range_mm(spec), stock.stub_length_mm,
                               spec.face_width_mm)
    title = f"spur_cad {__version__} {operation}" + (" restart" if restart_comment else "") + f": {job.job.name}"
    comments = program_comments(job, plan, operation) + ((restart_comment,) if restart_comment else ())
    return ProgramInfo(title=title, comments=comments, rotary_clamp_code=job.machine.rotary_clamp_code,
                       rotary_unclamp_code=job.machine.rotary_unclamp_code, blank_box_mm=box,
                       approach_z_mm=approach_z_mm, first_space_a_reference_deg=a_reference_deg,
                       writes_a=setup.writes_a)


def lathe_program(job: Job) -> tuple[str, bytes]:
    """The blank's lathe program ([lathe], spur_cad.cam.turning): its file name blank.<ext> and text."""
    from spur_cad.cam.turning import plan_lathe
    from spur_cad.post.lathe import lathe_extension, post_lathe

    spec, stock, lathe = job.gear, job.stock, job.lathe
    if lathe is None:
        raise ValueError(f"job {job.job.name!r} has no [lathe] section: no lathe program")
    comments = (f"gear: z = {spec.teeth}, m = {spec.module_mm:g} mm, b = {spec.face_width_mm:g} mm, tip diameter "
                f"{2 * spec.tip_radius_mm:.4f} mm",)
    text = post_lathe(plan_lathe(spec, stock, lathe), lathe, f"spur_cad {__version__} blank: {job.job.name}",
                      comments, dialects=job.dialects)
    return f"blank.{lathe_extension(lathe.dialect, job.dialects)}", text.encode()


def probe_program(job: Job) -> tuple[str, bytes]:
    """The on-machine probing program ([probe], spur_cad.cam.probing): its file name probe.<ext> and text."""
    from spur_cad.cam.probing import plan_probe
    from spur_cad.post.probe import post_probe, probing_dialect

    spec, probe = job.gear, job.probe
    if probe is None:
        raise ValueError(f"job {job.job.name!r} has no [probe] section: no probing program")
    gear = (f"gear: z = {spec.teeth}, m = {spec.module_mm:g} mm, alpha = {spec.pressure_angle_deg:g} deg, "
            f"x = {spec.profile_shift_coefficient:g}, b = {spec.face_width_mm:g} mm, reference radius "
            f"{spec.reference_radius_mm:.4f} mm, form radius {spec.form_radius_mm:.4f} mm")
    plan = plan_probe(spec, job.stock, job.machine, probe)
    text = post_probe(plan, job.post, f"spur_cad {__version__} probe: {job.job.name}", gear, job.dialects)
    return f"probe.{probing_dialect(job.post.dialect, job.dialects).extension}", text.encode()


def export_files(job: Job) -> dict[str, bytes]:
    """[export]: gear.dxf and gear.svg, the outline (and bore) offset by offset_mm (spur_cad.outline_export)."""
    from spur_cad.outline_export import dxf_bytes, gear_layers, svg_bytes

    export, gear = job.export, job.gear_section
    if not (export.dxf or export.svg):
        return {}
    layers = gear_layers(job.gear, job.job.profile_tolerance_mm, export.offset_mm, gear.bore_diameter_mm,
                         gear.keyway_width_mm, gear.keyway_depth_mm)
    files = {}
    if export.dxf:
        files["gear.dxf"] = dxf_bytes(layers)
    if export.svg:
        title = f"spur_cad {__version__}: {job.job.name}, outline offset {export.offset_mm:g} mm"
        files["gear.svg"] = svg_bytes(layers, title)
    return files


def restart_program(job: Job, plan: CamPlan, point: RestartPoint) -> tuple[str, bytes]:
    """A program that restarts `point.operation` at the point (spur_cad.cam.restart): its file name
    (e.g. roughing_space5.ngc) and text."""
    from spur_cad.cam.common import safe_height_mm
    from spur_cad.cam.restart import RestartError, restart_toolpath, run_reference_a_deg
    from spur_cad.post import post_program

    planned = getattr(plan, point.operation)
    if planned is None:
        raise RestartError(f"--restart {point.text()}: the job has no {point.operation} (no [tools.{point.operation}])",
                           field="restart")
    clearance = safe_height_mm(job.stock.blank_radius_mm(job.gear), job.machine)
    path, start = restart_toolpath(planned.toolpath, point, clearance)
    comment = (f"restart at {point.text()}: the full program's moves from move {start} on, after a move to the "
               f"clearance height Z {clearance:.3f} mm and to the first move's X, Y and A")
    reference = run_reference_a_deg(planned.toolpath, start) if planned.toolpath.space[start] >= 0 else None
    program = post_program(path, job.post, program_info(job, plan, point.operation, comment, clearance, reference),
                           dialects=job.dialects)
    return f"{point.label()}.{program.extension}", program.text.encode()


def program_comments(job: Job, plan: CamPlan, operation: str) -> tuple[str, ...]:
    """Header comments of a program: gear data, tool, strategy, estimated time (no date: outputs are reproducible)."""
    return SETUP_COMMENTS[job.machine.setup](job, plan, operation)


def _rotary_table_comments(job: Job, plan: CamPlan, operation: str) -> tuple[str, ...]:
    """Header comments of a program on the rotary table (program_comments)."""
    spec = job.gear
    if operation in ("roughing", "roughing_bottom"):
        planned = getattr(plan, operation)
        strategy = (f"strategy: {len(planned.levels.heights_mm)} levels per space, flank allowance "
                    f"{job.roughing.flank_allowance_mm:g} mm")
        if planned.flank is not None:
            turns = ", ".join(f"{abs(s.turn_deg):.1f}" for s in planned.flank.segments)
            strategy = (f"strategy: by flanks, {len(planned.flank.passes)} passes per space, A turned +-{turns} "
                        f"deg, flank allowance {job.roughing.flank_allowance_mm:g} mm")
        if plan.two_stage is not None and planned.flank is not None:
            stage = "the upper part, then roughing_bottom" if operation == "roughing" else \
                "what roughing leaves, after roughing"
            strategy += f"; two-stage ({stage}), the roughing tool down to " \
                f"{plan.two_stage.split_height_above_root_mm:.3f} mm above the root"
        elif plan.two_stage is not None:
            stage = "upper levels, then roughing_bottom" if operation == "roughing" else "bottom levels, after roughing"
            strategy += (f"; two-stage ({stage}), split {plan.two_stage.split_height_above_root_mm:.3f} mm above "
                         "the root")
    else:
        planned = plan.finishing
        if planned is None:
            raise ValueError(f"the plan has no finishing for the {operation} program's header")
        result = planned.result
        strategy = (f"strategy: {result.strategy}, {result.describe()}, target scallop "
                    f"{job.finishing.target_scallop_mm * 1000:g} um")
    tool = planned.tool
    minutes = planned.estimate.time_s / 60.0
    kind_lines = KIND_HEADER_LINES.get(spec.kind)  # spur headers stay as they were (byte-identical outputs)
    helix = kind_lines(spec) if kind_lines is not None else ()
    return (
        f"gear: z = {spec.teeth}, m = {spec.module_mm:g} mm, alpha = {spec.pressure_angle_deg:g} deg, "
        f"x = {spec.profile_shift_coefficient:g}, b = {spec.face_width_mm:g} mm, rho = {spec.rack_tip_radius_mm:g} mm",
        *helix,
        f"radii: tip {spec.tip_radius_mm:.4f} mm, root {spec.root_radius_mm:.4f} mm",
        f"tool T{tool.tool_number}: {tool.kind} D {tool.diameter_mm:g} mm, "
        f"corner radius {tool.effective_corner_radius_mm:g} mm, "
        f"S {tool.spindle_rpm(job.machine):.0f} rpm, F {tool.feed_mm_min(job.machine):.0f} mm/min",
        strategy,
        f"estimated time: {minutes:.1f} min ({planned.estimate.moves} moves)",
        "frame: X = gear axis (front face X0), Y0 Z0 on the A axis, tool tip centre programmed",
    )


def _helix_lines(spec: GearSpec) -> tuple[str, ...]:
    """A helical gear's header line: its helix, and how A follows it along X."""
    return (f"helix: beta = {spec.helix_angle_deg:g} deg {spec.hand} hand (m and alpha normal), lead "
            f"{spec.lead_mm:.4f} mm: along it A changes by {-spec.hand_sign * 360.0 / spec.lead_mm:+.6f} deg "
            "per mm of X",)


KIND_HEADER_LINES: dict[GearKind, Callable[[GearSpec], tuple[str, ...]]] = {EXTERNAL_HELICAL: _helix_lines}
"""The header lines a kind adds after the gear's (rotary-table programs)."""


def _three_axis_comments(job: Job, plan: CamPlan, operation: str) -> tuple[str, ...]:
    """Header comments of a 3-axis program ([machine] axes = 3): gear, tool, what it does, the set-up."""
    spec, planned = job.gear, getattr(plan, operation)
    tool = planned.tool
    if operation == "roughing" and spec.kind.has_rim:
        entry = "a plunge in the blank's bore" if job.stock.inner_diameter_mm > 0.0 else "a helix at the centre"
        what = (f"3-axis roughing of the ring's hole: {len(planned.levels.heights_mm)} levels, {entry}, concentric "
                f"passes from the centre out to {job.roughing.finish_stock_mm:g} mm from the outline; the rim's "
                "outside is not cut")
    elif operation == "roughing":
        what = (f"3-axis roughing: {len(planned.levels.heights_mm)} levels, concentric passes from the blank to "
                f"{job.roughing.finish_stock_mm:g} mm from the outline")
    else:
        facts = planned.result.facts
        what = (f"3-axis finishing: the outline as arcs offset by the tool radius, {facts.step_downs} step-downs, "
                f"climb; form diameter {facts.form_diameter_mm:.3f} mm, root fillet >= "
                f"{facts.root_fillet_radius_mm:.3f} mm")
    holding = job.three_axis
    if holding.tabs:
        what += (f"; {holding.tabs} holding tabs on tips ({holding.tab_width_mm:g} mm wide, {holding.tab_height_mm:g} "
                 "mm high from the bottom face): break them off and file them after the cut")
    elif holding.onion_skin_mm > 0.0:
        what += f"; an onion skin of {holding.onion_skin_mm:g} mm left on the bottom face"
    return (
        f"gear: z = {spec.teeth}, m = {spec.module_mm:g} mm, alpha = {spec.pressure_angle_deg:g} deg, "
        f"x = {spec.profile_shift_coefficient:g}, b = {spec.face_width_mm:g} mm, tip diameter "
        f"{2 * spec.tip_radius_mm:.4f} mm",
        f"tool: T{tool.tool_number} {tool.kind} D {tool.diameter_mm:g} mm",
        what,
        f"estimated time: {planned.estimate.time_s / 60.0:.1f} min ({planned.estimate.moves} moves)",
        "frame: gear axis = Z, X0 Y0 on it, Z0 on the blank's top face, blank clamped flat; tool tip centre "
        "programmed",
    )


SETUP_COMMENTS: dict[MachineSetup, Callable[[Job, CamPlan, str], tuple[str, ...]]] = {
    ROTARY_TABLE: _rotary_table_comments, LYING_FLAT: _three_axis_comments}
"""Each set-up's program header comments (program_comments)."""


def cam_inputs(job: Job) -> CamInputs:
    """The part of a job the CAM stage reads."""
    return CamInputs(job.gear, job.stock, job.tools.roughing, job.tools.finishing, job.roughing, job.finishing,
                     job.machine, job.tools.bottom, top_tool=job.tools.roughing_top, strategies=job.strategies,
                     profile_tolerance_mm=job.job.profile_tolerance_mm, three_axis=job.three_axis,
                     modifications=job.modifications, levels_fallback=job.roughing_strategy_left_out,
                     outline_export=job.export.dxf or job.export.svg, pair=job.pair)


def plan_cam(job: Job, checkpoint: Callable[[], None] | None = None) -> CamPlan:
    """The job's CAM plan (spur_cad.cam.plan.plan_cam on the job's inputs)."""
    return plan_cam_inputs(cam_inputs(job), checkpoint)


def job_stock(job: Job) -> StockCylinder:
    """The blank cylinder of the job's stock (front margin to back margin; the holding stub is not cut)."""
    from spur_cad.sim.simulate import StockCylinder

    spec, stock = job.gear, job.stock
    return StockCylinder(stock.blank_radius_mm(spec), *stock.blank_x_range_mm(spec))


def simulates_with_kernels(job: Job, plan: CamPlan) -> bool:
    """Whether simulate_stage runs the 4-axis simulation, whose kernels load numba (a job lying flat is simulated
    by spur_cad.sim.flat, in numpy)."""
    cuts = any(planned is not None for planned in (plan.roughing, plan.roughing_bottom, plan.finishing))
    return job.simulation.enabled and cuts and SETUP_SIMULATIONS[job.machine.setup] is _simulate_turned


def simulate_stage(job: Job, plan: CamPlan, progress: Callable[[float], None] | None = None) -> SimResult | None:
    """The job's stock cut by its roughing then finishing toolpaths (None when disabled or nothing to cut)."""
    from spur_cad.sim.simulate import Cut

    operations = [Cut(planned.toolpath, planned.tool) for planned in (plan.roughing, plan.roughing_bottom,
                                                                      plan.finishing) if planned is not None]
    if not job.simulation.enabled or not operations:
        return None
    return SETUP_SIMULATIONS[job.machine.setup](job, plan, operations, progress)


def _simulate_lying_flat(job: Job, plan: CamPlan, operations: list[Cut],
                         progress: Callable[[float], None] | None) -> SimResult:
    """Lying flat (a ring's blank: the rim's disc, its bore): spur_cad.sim.flat, in numpy."""
    from spur_cad.sim.flat import simulate_flat
    from spur_cad.sim.simulate import SimSettings

    depths = -plan.finishing.toolpath.z[plan.finishing.toolpath.motion_mask] if plan.finishing is not None \
        else np.zeros(0)
    result = simulate_flat(job.gear, job.stock.blank_radius_mm(job.gear), operations,
                           SimSettings(resolution_mm=job.simulation.resolution_mm), np.unique(depths),
                           job.stock.inner_diameter_mm / 2.0)
    if progress is not None:
        progress(1.0)
    return result


def _simulate_turned(job: Job, plan: CamPlan, operations: list[Cut],
                     progress: Callable[[float], None] | None) -> SimResult:
    """On the rotary table: the 4-axis simulation (spur_cad.sim.simulate, its kernels in numba)."""
    from spur_cad.sim.simulate import SimSettings, simulate

    stations = plan.finishing.result.station_x_mm if plan.finishing is not None else np.zeros(0)
    result = simulate(job.gear, job_stock(job), operations, SimSettings(resolution_mm=job.simulation.resolution_mm),
                      station_x=stations, progress=progress, modifications=job.modifications)
    return dataclasses.replace(result, engagement=roughing_engagement(job, plan))


SETUP_SIMULATIONS: dict[MachineSetup, Callable[[Job, CamPlan, list[Cut], Callable[[float], None] | None],
                                              SimResult]] = {
    ROTARY_TABLE: _simulate_turned, LYING_FLAT: _simulate_lying_flat}
"""Each set-up's simulation (simulate_stage)."""


def roughing_engagement(job: Job, plan: CamPlan) -> Engagement | None:
    """a_e, a_p and removal rate of every roughing move, on the material it meets (spur_cad.sim.engagement; the
    flank strategy's turned passes on the section model, spur_cad.sim.section_engagement)."""
    from spur_cad.sim.engagement import MeasuredCut, measure_engagement
    from spur_cad.sim.section_engagement import measure_section_engagement

    cuts = [MeasuredCut(name, planned.toolpath, planned.tool) for name, planned in
            (("roughing", plan.roughing), ("roughing_bottom", plan.roughing_bottom)) if planned is not None]
    if not cuts:
        return None
    stock = job_stock(job)
    by_flanks = plan.roughing is not None and plan.roughing.flank is not None  # roughing_bottom comes with roughing
    measure = measure_section_engagement if by_flanks else measure_engagement
    return measure(job.gear.teeth, stock.radius_mm, (stock.x_min, stock.x_max), cuts, job.gear.section_turn_rad(1.0))
