"""report.html: one self-contained page (images as base64 data URIs, inline CSS, no scripts, no links out).

Every value shown is read from the job's typed result (spur_cad.result.JobResult, whose serialisation is
summary.json); the figures come in as PNG bytes. Sections a job does not have (no tools, no simulation, no post)
are left out or say so.
"""

from __future__ import annotations

import base64
import dataclasses
import html
from typing import TYPE_CHECKING, Iterable

from spur_cad.cam.plan import REFERENCE_CONTACT_SPACING_MM, REFERENCE_STATION_STEP_MM

if TYPE_CHECKING:
    from spur_cad.cam.estimate import Estimate
    from spur_cad.result import FinishingFacts, JobResult, RoughingFacts

_CSS = """
body { font-family: sans-serif; margin: 2em auto; max-width: 62em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 1.8em; }
table { border-collapse: collapse; margin: 0.6em 0; } td, th { border: 1px solid #ccc; padding: 0.2em 0.6em; }
th { background: #f3f3f3; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
img { max-width: 100%; border: 1px solid #ddd; } .warn { color: #a40; } .ok { color: #070; }
"""


def _e(value: object) -> str:
    return html.escape(str(value))


def _fmt(value: object, digits: int = 4) -> str:
    if isinstance(value, bool) or value is None:
        return "-" if value is None else ("yes" if value else "no")
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def _table(rows: Iterable[tuple[str, object]], head: tuple[str, ...] = ()) -> str:
    out = ["<table>"]
    if head:
        out.append("<tr>" + "".join(f"<th>{_e(h)}</th>" for h in head) + "</tr>")
    for row in rows:
        label, *values = row
        cells = "".join(f'<td class="num">{_e(v if isinstance(v, str) else _fmt(v))}</td>' for v in values)
        out.append(f"<tr><th>{_e(label)}</th>{cells}</tr>")
    out.append("</table>")
    return "\n".join(out)


def _image(png: bytes | None, alt: str) -> str:
    if not png:
        return ""
    data = base64.b64encode(png).decode("ascii")
    return f'<p><img alt="{_e(alt)}" src="data:image/png;base64,{data}"></p>'


def _minutes(seconds: float | None) -> str:
    if seconds is None:
        return "-"
    return f"{seconds / 3600.0:.2f} h ({seconds / 60.0:.0f} min)"


GEAR_ROWS = ("teeth", "module_mm", "pressure_angle_deg", "profile_shift_coefficient", "addendum_coefficient",
             "dedendum_coefficient", "rack_tip_radius_mm", "face_width_mm", "reference_radius_mm", "base_radius_mm",
             "tip_radius_mm", "root_radius_mm", "form_radius_mm", "tooth_thickness_mm", "space_width_mm",
             "tip_thickness_mm", "root_arc_length_mm", "undercut")
HELICAL_ROWS = ("helix_angle_deg", "hand", "transverse_module_mm", "transverse_pressure_angle_deg",
                "base_helix_angle_deg", "lead_mm", "overlap_ratio")


def _gear(result: JobResult) -> str:
    gear = result.gear
    names = GEAR_ROWS + (HELICAL_ROWS if gear.is_helical else ())
    text = "<h2>Gear</h2>" + _table((name, getattr(gear, name)) for name in names)
    if gear.is_helical:
        text += ("<p>Helical gear: module, pressure angle, shift, coefficients and rack tip radius are normal-section "
                 "values; radii, thicknesses and the profile are transverse.</p>")
    return text


def _inspection(result: JobResult) -> str:
    ins, sim = result.inspection, result.simulation
    nominal = ins.tooth_thickness_mm + ins.thickness_reduction_mm
    helical = result.gear.is_helical
    span_label = f"span measurement W_k over k = {ins.span_teeth_k} teeth [mm]"
    if helical:
        span_label += (f" (normal section; needs face width > {ins.span_min_face_width_mm:.2f} mm"
                       + ("" if ins.span_measurement_mm is not None else ": too narrow, measure over balls") + ")")
    rows = [
        (span_label, ins.span_measurement_mm),
        ("  anvils touch the flanks at radius [mm]", ins.span_contact_radius_mm),
        ("pin (ball) diameter [mm]", ins.pin_diameter_mm),
        ("dimension over pins [mm]", ins.dimension_over_pins_mm),
        ("  pins touch the flanks at radius [mm]", ins.pin_contact_radius_mm),
        ("normal chordal tooth thickness [mm]" if helical else "chordal tooth thickness [mm]",
         ins.chordal_thickness_mm),
        (f"  at chordal height [mm] (measuring radius {ins.chordal_measuring_radius_mm:g} mm)",
         ins.chordal_height_mm),
        ("tooth thickness on the reference circle s [mm]", ins.tooth_thickness_mm),
        ("  nominal p/2 + 2 x m tan(alpha) [mm]", nominal),
        ("  thickness allowance (upper deviation) [mm]", -ins.thickness_reduction_mm),
        ("minimum teeth without undercut", ins.min_teeth_without_undercut),
    ]
    text = "<h2>Inspection sheet</h2>" + _table(rows)
    flanks = [sim.feature(f"{side} involute") for side in ("right", "left")]
    if sim.enabled and all(flanks) and ins.span_measurement_mm is not None:
        low = -max(f.max_gouge_mm for f in flanks)
        high = max(f.max_leftover_mm for f in flanks)
        text += ("<p>Tolerance expected from the simulated cut (involute flanks, normal deviation "
                 f"{1000 * low:+.1f} to {1000 * high:+.1f} um on each flank): span measurement "
                 f"{ins.span_measurement_mm + 2 * low:.4f} to {ins.span_measurement_mm + 2 * high:.4f} mm; "
                 f"tooth thickness {ins.tooth_thickness_mm:.4f} mm "
                 f"(nominal {nominal:.4f} mm, {-ins.thickness_reduction_mm:+.4f} mm allowance).</p>")
    return text


def _tools(result: JobResult) -> str:
    tools = result.tools
    rec = dataclasses.asdict(tools.recommendations).items()
    text = "<h2>Tools</h2><h3>Recommendations</h3>" + _table(rec)
    if tools.advice is not None:
        advice = ((name, value) for name, value in dataclasses.asdict(tools.advice).items() if value is not None)
        text += f"<h3>For finishing strategy {_e(tools.advice_strategy)}</h3>" + _table(advice)
    chosen = [(role, tool.kind, tool.diameter_mm, tool.corner_radius_mm, tool.flat_width_mm, tool.spindle_rpm,
               tool.feed_mm_min) for role, tool in (("roughing", tools.roughing), ("finishing", tools.finishing))
              if tool is not None]
    if chosen:
        text += "<h3>Chosen tools</h3>" + _table(
            chosen, ("", "kind", "D [mm]", "corner r [mm]", "flat width [mm]", "spindle [rpm]", "feed [mm/min]"))
    return text


def _program(result: JobResult) -> str:
    rough, finish, post = result.roughing, result.finishing, result.post
    if rough is None and finish is None:
        return ""
    rows = []
    bottom = rough.two_stage.bottom if rough is not None and rough.two_stage is not None else None
    operations: tuple[tuple[str, RoughingFacts | FinishingFacts | None], ...] = (
        ("roughing", rough), ("roughing_bottom", bottom), ("finishing", finish))
    for name, facts in operations:
        if facts is not None:
            program = post.program(name)
            est: Estimate = facts.estimate
            rows.append((name, est.moves, "-" if program is None else str(program.lines),
                         "-" if program is None else f"{program.bytes / 1000:.1f} kB",
                         f"{est.cutting_length_mm / 1000:.2f} m", _minutes(est.time_s),
                         _minutes(est.time_with_acceleration_s)))
    text = "<h2>Programs and cycle time</h2>"
    text += f"<p>Post: {_e(post.dialect)}" + (", folded into subprograms" if post.folded else "")
    text += "</p>"
    text += _table(rows, ("", "moves (IR)", "G-code lines", "G-code size", "cutting path", "time at feed",
                          "time with acceleration"))
    if finish is not None:
        text += finishing_comparison_html(finish)
    if rough is not None:
        text += (f"<p>Roughing: {rough.levels_per_space} levels per space, lowest level "
                 f"{rough.lowest_level_height_mm:.3f} mm above the root circle.</p>")
    if bottom is not None:
        stage = rough.two_stage
        text += (f"<p>Two-stage roughing: the bottom tool (T{stage.bottom_tool.tool_number}, D "
                 f"{stage.bottom_tool.diameter_mm:g} mm) roughs {bottom.levels_per_space} levels per space "
                 f"below {stage.split_height_above_root_mm:.3f} mm above the root circle (split chosen by "
                 f"{_e(stage.split_chosen_by)}): {_minutes(stage.two_stage_time_s)} in all, "
                 f"{_minutes(stage.time_saved_s)} less than the bottom tool alone "
                 f"({_minutes(stage.bottom_tool_alone_time_s)}).</p>")
    if finish is not None:
        text += f"<p>{html.escape(finish.report_text, quote=False)}</p>"
    return text


NOT_ESTIMATED = ("not estimated (too large to build for comparison, the tool does not fit that strategy, or the "
                 "strategy is for spur gears only)")


def finishing_comparison_html(finish: FinishingFacts) -> str:
    """This job's finishing beside perimeter finishing and the reference process's strategy (same tool)."""
    reference = (f"reference process's strategy (perimeter, {REFERENCE_CONTACT_SPACING_MM:g} mm contacts, "
                 f"{REFERENCE_STATION_STEP_MM:g} mm X step)")
    rows = [(f"this job's finishing ({_e(finish.strategy)})", finish.estimate.moves,
             _minutes(finish.estimate.time_s), _minutes(finish.estimate.time_with_acceleration_s))]
    others = [(finish.perimeter, "perimeter finishing at this job's target scallop")] \
        if finish.strategy != "perimeter" else []
    others.append((finish.reference_strategy, reference))
    for other, label in others:
        if other is None:
            rows.append((label, "-", NOT_ESTIMATED, "-"))
        else:
            rows.append((label, other.moves, _minutes(other.time_s), _minutes(other.time_with_acceleration_s)))
    return _table(rows, ("finishing (same tool)", "moves", "time at feed", "time with acceleration"))


def _simulation(result: JobResult) -> str:
    sim = result.simulation
    if not sim.enabled:
        return "<h2>Simulated cut</h2><p>Simulation disabled ([simulation] enabled = false) or no toolpaths.</p>"
    res = sim.resolution_mm
    gouge_ok = sim.max_gouge_mm <= res
    rows = [("resolution [mm]", res), ("max gouge [mm]", sim.max_gouge_mm),
            ("max leftover [mm]", sim.max_leftover_mm), ("scallop mean / p95 / p99 [um]",
                                                        f"{1000 * sim.scallop_mean_mm:.2f} / "
                                                        f"{1000 * sim.scallop_p95_mm:.2f} / "
                                                        f"{1000 * sim.scallop_p99_mm:.2f}"),
            ("removed volume [mm^3]", f"{sim.removed_volume_mm3:.1f}"),
            ("design points x rows (all spaces)", sim.design_points),
            ("simulation time [s]", f"{sim.seconds:.1f}")]
    text = "<h2>Simulated cut</h2>" + _table(rows)
    verdict = "ok" if gouge_ok else "warn"
    worst = sim.worst_leftover
    text += (f'<p class="{verdict}">Largest gouge {1000 * sim.max_gouge_mm:.2f} um '
             f'({"within" if gouge_ok else "beyond"} the resolution). Largest leftover '
             f'{1000 * sim.max_leftover_mm:.2f} um at tooth space {worst.space}, '
             f'{_e(worst.feature)}, X = {worst.x_mm:.3f} mm.</p>')
    text += _table(((f.feature, 1000 * f.max_gouge_mm, 1000 * f.max_leftover_mm, 1000 * f.mean_mm)
                    for f in sim.per_feature), ("feature", "max gouge [um]", "max leftover [um]", "mean [um]"))
    return text


DEVIATION_LABELS = {"f_pt": "single pitch f_pt", "F_p": "total cumulative pitch F_p", "f_Ha": "profile slope f_Ha",
                    "f_fa": "profile form f_fa", "F_a": "total profile F_a", "f_Hb": "helix slope f_Hb",
                    "f_fb": "helix form f_fb", "F_b": "total helix F_b"}


def _grading(result: JobResult) -> str:
    grading = result.grading
    if grading is None:
        return ""
    rows = ((label, f"{grading.deviations_um[name]:.2f}", grading.classes[name] or "beyond 11")
            for name, label in DEVIATION_LABELS.items())
    text = ("<h2>Grade (ISO 1328-1:2013, from the simulated cut)</h2>"
            + _table(rows, ("deviation (worst flank)", "[um]", "class")))
    overall = grading.overall_class
    text += (f'<p>Flank tolerance class of the simulated gear: <b>{overall if overall else "beyond 11"}</b> '
             "(the worst class of the deviations above; profiles from the form circle to 95 % of the roll "
             "length to the tip, helix over the face width less min(5 % b, m) at each end).</p>")
    if grading.validity:
        text += f'<p class="warn">Outside the range of the formulas: {_e("; ".join(grading.validity))}.</p>'
    return text


def _warnings(result: JobResult) -> str:
    items = list(result.warnings)
    sim = result.simulation
    if sim.enabled:
        if sim.max_gouge_mm > sim.resolution_mm:
            w = sim.worst_gouge
            items.append(f"simulation: gouge of {1000 * sim.max_gouge_mm:.1f} um at tooth space {w.space}, "
                         f"{w.feature}, X = {w.x_mm:.3f} mm (station {w.station})")
        if sim.uncut_points:
            items.append(f"simulation: {sim.uncut_points} design points keep more than "
                         f"{sim.leftover_range_mm:g} mm of material (never cut)")
    body = "".join(f"<li>{_e(w)}</li>" for w in items) if items else "<li>none</li>"
    return f"<h2>Warnings</h2><ul class=\"warn\">{body}</ul>"


def render_report(result: JobResult, images: dict[str, bytes]) -> bytes:
    """The whole report as UTF-8 HTML bytes. `images`: 'profile', 'roughing', 'finishing', 'deviation',
    'kchart' PNGs."""
    title = f"spur_cad report: {result.job.name}"
    parts = [
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">', f"<title>{_e(title)}</title>",
        f"<style>{_CSS}</style></head><body>", f"<h1>{_e(title)}</h1>",
        f"<p>Job file {_e(result.job.file)}, spur_cad {_e(result.version)}.</p>",
        _warnings(result), _gear(result), _image(images.get("profile"), "tooth space profile"),
        _inspection(result), _tools(result), _program(result),
        "<h2>Roughing levels</h2>" + _image(images.get("roughing"), "roughing levels")
        if images.get("roughing") else "",
        "<h2>Finishing contacts and cutter locations</h2>" + _image(images.get("finishing"), "finishing poses")
        if images.get("finishing") else "",
        _simulation(result), _image(images.get("deviation"), "deviation map"),
        _grading(result), _image(images.get("kchart"), "K-chart: profile and helix traces"),
        "</body></html>",
    ]
    return ("\n".join(p for p in parts if p) + "\n").encode("utf-8")
