"""The report's values as a gear maker reads them: labelled rows with units and a sensible precision, built from
the job's typed result for the report template (report/templates/report.html.j2, or a shop's own copy).

Precision: gear and tool sizes in mm to 3 decimals, inspection dimensions to 4 (micrometres matter there),
deviations in µm to 1 decimal, angles to 3 decimals, speeds and feeds whole, times in h and min. A negative
zero is shown as 0.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

from spur_cad.cam.setups import ROTARY_TABLE, MachineSetup, SheetRow
from spur_cad.geometry.kinds import EXTERNAL_HELICAL, GearKind
from spur_cad.result import FinishingFacts, RoughingFacts

if TYPE_CHECKING:
    from spur_cad.result import CorrectionFacts, JobResult, ToolFacts

MICRO = "\u00b5m"


@dataclass(frozen=True)
class Row:
    """One labelled value: the label a gear maker reads, the value as text, its unit ('' for none)."""

    label: str
    value: str
    unit: str = ""


@dataclass(frozen=True)
class Table:
    """A table with a head row and rows of text cells (the first cell a label)."""

    head: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


def number(value: float | int | None, digits: int = 3) -> str:
    """`value` with `digits` decimals; '-' for None; never '-0.000'."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value:,}"
    text = f"{value:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def signed(value: float, digits: int = 1) -> str:
    """A signed value ('+4.9', '-0.3'; 0 as '0.0')."""
    text = number(value, digits)
    return text if text.startswith("-") or float(text) == 0.0 else f"+{text}"


def duration(seconds: float | None) -> str:
    """'2 h 31 min' ('-' for None; under an hour '41 min', under a minute '12 s')."""
    if seconds is None:
        return "-"
    if seconds < 60.0:
        return f"{seconds:.0f} s"
    minutes = round(seconds / 60.0)
    return f"{minutes // 60} h {minutes % 60:02d} min" if minutes >= 60 else f"{minutes} min"


GEAR_LABELS = (  # (GearFacts field, label, unit, digits); helical rows only for a helical gear
    ("teeth", "number of teeth z", "", 0),
    ("module_mm", "module m (normal module m_n for a helical gear)", "mm", 3),
    ("pressure_angle_deg", "pressure angle", "°", 3),
    ("profile_shift_coefficient", "profile shift coefficient x", "", 3),
    ("addendum_coefficient", "addendum coefficient", "", 3),
    ("dedendum_coefficient", "dedendum coefficient", "", 3),
    ("rack_tip_radius_mm", "rack tip radius rho", "mm", 3),
    ("face_width_mm", "face width b", "mm", 3),
    ("reference_radius_mm", "reference radius", "mm", 4),
    ("base_radius_mm", "base radius", "mm", 4),
    ("tip_radius_mm", "tip radius", "mm", 4),
    ("root_radius_mm", "root radius", "mm", 4),
    ("form_radius_mm", "form radius (involute starts)", "mm", 4),
    ("tooth_thickness_mm", "tooth thickness on the reference circle", "mm", 4),
    ("space_width_mm", "space width on the reference circle", "mm", 4),
    ("tip_thickness_mm", "tooth thickness at the tip", "mm", 4),
    ("root_arc_length_mm", "root arc length", "mm", 3),
    ("undercut", "undercut", "", 0),
)
HELICAL_LABELS = (
    ("helix_angle_deg", "helix angle on the reference cylinder", "°", 3),
    ("hand", "hand of helix", "", 0),
    ("transverse_module_mm", "transverse module", "mm", 4),
    ("transverse_pressure_angle_deg", "transverse pressure angle", "°", 3),
    ("base_helix_angle_deg", "base helix angle", "°", 3),
    ("lead_mm", "lead", "mm", 3),
    ("overlap_ratio", "overlap ratio", "", 3),
)
KIND_LABELS: dict[GearKind, tuple[tuple[str, str, str, int], ...]] = {EXTERNAL_HELICAL: HELICAL_LABELS}
"""The gear rows a kind adds to GEAR_LABELS (a helical gear's helix angle, hand, lead and overlap ratio)."""
TOOL_KINDS = {"flat": "flat end mill", "bull_nose": "bull-nose end mill", "ball": "ball end mill"}
OPERATION_NAMES = {"roughing": "roughing", "roughing_bottom": "roughing, bottom of the spaces",
                   "finishing": "finishing"}


def _value(value: object, digits: int) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, float) and digits == 0:
        return number(value, 0)
    return number(value, digits)  # type: ignore[arg-type]


def gear_rows(result: JobResult) -> tuple[Row, ...]:
    """The gear's data, labelled (helical rows for a helical gear)."""
    labels = GEAR_LABELS + KIND_LABELS.get(result.kind, ())
    return tuple(Row(label, _value(getattr(result.gear, name), digits), unit) for name, label, unit, digits in labels)


def limit_rows(result: JobResult) -> tuple[Row, ...]:
    """The gear's tool limits, labelled (0 shown as 'none fits'): those of the set-up (its tool_limit_labels; a gear
    cut lying flat shows the limits of the 3-axis variant), the rotary table's for a run without set-up facts."""
    rec = result.tools.recommendations
    labels = machine_setup(result).tool_limit_labels
    return tuple(Row(_limit_label(rec, name, label), number(getattr(rec, name), 3) if getattr(rec, name) > 0.0
                     else "none fits", "mm" if getattr(rec, name) > 0.0 else "") for name, label in labels)


def machine_setup(result: JobResult) -> MachineSetup:
    """The run's machine set-up (the rotary table's for a run without set-up facts), which the report asks."""
    return ROTARY_TABLE if result.setup is None else result.setup.machine_setup


def _limit_label(rec, name: str, label: str) -> str:
    """The label, with the finishing strategy's rule for what roughing may leave above the root."""
    if name == "plunge_allowance_mm" and rec.bottom_allowance_rule:
        return f"{label}: as much as {rec.bottom_allowance_rule}"
    return label


def advice_rows(result: JobResult) -> tuple[Row, ...]:
    """The finishing strategy's own tool advice (its fields as sentences: '_mm' names become 'mm' units)."""
    advice = result.tools.advice
    if advice is None:
        return ()
    rows = []
    for name, value in dataclasses.asdict(advice).items():
        if value is None:
            continue
        unit = "mm" if name.endswith("_mm") else ""
        label = name.removesuffix("_mm").replace("_", " ")
        rows.append(Row(label, _value(value, 3), unit))
    return tuple(rows)


def tool_cells(role: str, tool: ToolFacts) -> tuple[str, ...]:
    """A tool's row of the tool table: T number, role, type, D, corner, flat, flute length, stick-out, flutes,
    speed, feed (lengths not given shown as '-')."""
    def length(value: float) -> str:
        return number(value, 1) if value > 0.0 else "-"

    return (f"T{tool.tool_number}", role, TOOL_KINDS.get(tool.kind, tool.kind), number(tool.diameter_mm, 3),
            number(tool.corner_radius_mm, 3), number(tool.flat_width_mm, 3), length(tool.flute_length_mm),
            length(tool.stick_out_mm), str(tool.flutes), number(tool.spindle_rpm, 0), number(tool.feed_mm_min, 0))


TOOL_HEAD = ("tool", "used for", "type", "D [mm]", "corner r [mm]", "flat [mm]", "flute length [mm]",
             "stick-out [mm]", "flutes", "spindle [rpm]", "feed [mm/min]")


def program_file(result: JobResult, operation: str) -> str:
    """The operation's program file as the output set names it ('-' when no program was written)."""
    if result.post.program(operation) is None:
        return "-"
    return f"{operation}.{result.post.extension}"


def tool_table(result: JobResult) -> Table:
    """Every tool the programs load, in the order they are used."""
    tools = result.tools
    used = [("roughing", tools.roughing)]
    rough = result.roughing
    if rough is not None and rough.two_stage is not None:
        used.append(("roughing, bottom of the spaces", rough.two_stage.bottom_tool))
    used.append(("finishing", tools.finishing))
    return Table(TOOL_HEAD, tuple(tool_cells(role, tool) for role, tool in used if tool is not None))


def _operations(result: JobResult) -> list[tuple[str, RoughingFacts | FinishingFacts, ToolFacts | None]]:
    """(operation, facts, its tool) of the operations the job has."""
    rough, finish, tools = result.roughing, result.finishing, result.tools
    out: list[tuple[str, RoughingFacts | FinishingFacts, ToolFacts | None]] = []
    if rough is not None:
        out.append(("roughing", rough, tools.roughing))
        if rough.two_stage is not None:
            out.append(("roughing_bottom", rough.two_stage.bottom, rough.two_stage.bottom_tool))
    if finish is not None:
        out.append(("finishing", finish, tools.finishing))
    return out


def operation_table(result: JobResult) -> Table:
    """Per operation: program, strategy, tool, stock to leave, step-down / step-over, coolant, time and its share."""
    setup = result.setup
    operations = _operations(result)
    total = sum(facts.estimate.time_with_acceleration_s for _, facts, _ in operations) or 1.0
    rows = []
    for name, facts, tool in operations:
        program = program_file(result, name)
        if isinstance(facts, RoughingFacts):  # roughing and roughing_bottom
            strategy = (f"roughing by flanks, {facts.passes_per_space} passes per space"
                        if facts.passes_per_space is not None else
                        machine_setup(result).levels_roughing.format(levels=facts.levels_per_space))
            stock = (f"{number(setup.finish_stock_mm, 2)} to {number(setup.flank_allowance_mm, 2)} mm"
                     if setup is not None else "-")
            steps = (f"down {number(setup.roughing_step_down_mm, 2)} mm, "
                     f"over {number(setup.roughing_step_over_mm, 2)} mm"
                     if setup is not None and setup.roughing_step_down_mm is not None and name == "roughing" else "-")
        else:
            strategy = f"finishing, strategy {facts.strategy}"
            stock, steps = "0 (to size)", "-"
        seconds = facts.estimate.time_with_acceleration_s
        rows.append((OPERATION_NAMES.get(name, name), program, strategy,
                     f"T{tool.tool_number}" if tool is not None else "-", stock, steps,
                     ("on" if setup.coolant else "off") if setup is not None else "-", duration(seconds),
                     f"{100.0 * seconds / total:.0f} %"))
    head = ("operation", "program", "strategy", "tool", "stock to leave", "step-down / step-over", "coolant",
            "estimated time", "share")
    return Table(head, tuple(rows))


def totals_rows(result: JobResult) -> tuple[Row, ...]:
    """The job's totals: operations, tools, Z range, largest speed and feed, path lengths, estimated time."""
    operations = _operations(result)
    setup = result.setup
    tools = [tool for _, _, tool in operations if tool is not None]
    cutting = sum(facts.estimate.cutting_length_mm for _, facts, _ in operations)
    rapid = sum(facts.estimate.rapid_length_mm for _, facts, _ in operations)
    seconds = sum(facts.estimate.time_with_acceleration_s for _, facts, _ in operations)
    rows = [Row("operations", str(len(operations))),
            Row("tools", str(len({tool.tool_number for tool in tools})))]
    if setup is not None and setup.z_min_mm is not None:
        rows.append(Row(f"programmed tool-tip Z (from {setup.machine_setup.z_origin})",
                        f"{number(setup.z_min_mm, 3)} to {number(setup.z_max_mm, 3)}", "mm"))
    if tools:
        rows += [Row("largest spindle speed", number(max(t.spindle_rpm for t in tools), 0), "rpm"),
                 Row("largest feed", number(max(t.feed_mm_min for t in tools), 0), "mm/min")]
    rows += [Row("cutting path", number(cutting / 1000.0, 2), "m"), Row("rapid path", number(rapid / 1000.0, 2), "m"),
             Row("estimated machine time (with acceleration)", duration(seconds))]
    return tuple(rows)


def setup_rows(result: JobResult) -> tuple[Row, ...]:
    """Stock, work offset and how the part sits, as a machinist sets the part up: the set-up's own rows
    (MachineSetup.setup_sheet_rows: A's zero on the rotary table, the blank's thickness lying flat), formatted here."""
    setup = result.setup
    if setup is None:
        return ()
    return tuple(sheet_row(row) for row in setup.machine_setup.setup_sheet_rows(setup, result.gear))


def sheet_row(row: SheetRow) -> Row:
    """A set-up's plain row as the report shows it: each of its numbers with its digits in place of a `{}`."""
    text = row.text.format(*(number(value, row.digits) for value in row.numbers)) if row.numbers else row.text
    return Row(row.label, text, row.unit)


def program_table(result: JobResult) -> Table:
    """The programs: file, moves, lines, size, cutting path, both estimated times."""
    rows = []
    for name, facts, _ in _operations(result):
        program = result.post.program(name)
        est = facts.estimate
        rows.append((OPERATION_NAMES.get(name, name), program_file(result, name),
                     f"{est.moves:,}", f"{program.lines:,}" if program is not None else "-",
                     f"{program.bytes / 1000:.1f} kB" if program is not None else "-",
                     f"{number(est.cutting_length_mm / 1000.0, 2)} m", duration(est.time_s),
                     duration(est.time_with_acceleration_s)))
    head = ("operation", "program", "moves", "lines", "size", "cutting path", "time at feed", "with acceleration")
    return Table(head, tuple(rows))


def inspection_rows(result: JobResult) -> tuple[Row, ...]:
    """The inspection sheet: span, pins, chordal thickness, each to 4 decimals, with the allowance."""
    ins, helical = result.inspection, result.kind.measured_in == "normal"
    nominal = ins.tooth_thickness_mm + ins.thickness_reduction_mm
    span = f"span measurement W_k over k = {ins.span_teeth_k} teeth" + (
        f" (normal section; needs face width > {number(ins.span_min_face_width_mm, 2)} mm)" if helical else "")
    rows = [
        Row(span, number(ins.span_measurement_mm, 4) if ins.span_measurement_mm is not None
            else f"face too narrow (needs more than {number(ins.span_min_face_width_mm, 2)} mm): measure over balls",
            "mm" if ins.span_measurement_mm is not None else ""),
        Row("anvils touch the flanks at radius", number(ins.span_contact_radius_mm, 3), "mm"),
        Row("pin (ball) diameter", number(ins.pin_diameter_mm, 4), "mm"),
        Row("dimension over pins (balls)", number(ins.dimension_over_pins_mm, 4), "mm"),
        Row("pins touch the flanks at radius", number(ins.pin_contact_radius_mm, 3), "mm"),
        Row(("normal " if helical else "") + "chordal tooth thickness", number(ins.chordal_thickness_mm, 4), "mm"),
        Row(f"at chordal height (measuring radius {number(ins.chordal_measuring_radius_mm, 3)} mm)",
            number(ins.chordal_height_mm, 4), "mm"),
        Row("tooth thickness on the reference circle", number(ins.tooth_thickness_mm, 4), "mm"),
        Row("nominal thickness (no allowance)", number(nominal, 4), "mm"),
        Row("thickness allowance (upper deviation)", signed(-ins.thickness_reduction_mm, 4), "mm"),
        Row("fewest teeth without undercut", str(ins.min_teeth_without_undercut)),
    ]
    if ins.pins_between:  # an internal gear: no span (anvils cannot sit on a ring's flanks), pins between, no rack
        rows = [Row("span measurement", "not for an internal gear: measure between pins"),
                Row("pin (ball) diameter", number(ins.pin_diameter_mm, 4), "mm"),
                Row("dimension between pins (balls)", number(ins.dimension_over_pins_mm, 4), "mm"),
                *rows[4:6],
                Row(f"at chordal height from the tip circle (measuring radius "
                    f"{number(ins.chordal_measuring_radius_mm, 3)} mm)", number(ins.chordal_height_mm, 4), "mm"),
                *rows[7:-1]]
    if result.modifications is not None:
        rows.extend(modification_rows(result))
    return tuple(rows)


def modification_rows(result: JobResult) -> list[Row]:
    """The flank modifications (right / left flank, ISO 21771 names) and where span and pins touch them."""
    mods = result.modifications
    if mods is None:
        return []

    def pair(values: tuple[float, float], digits: int) -> str:
        return f"{number(values[0], digits)} / {number(values[1], digits)}"

    rows = [Row(f"flank modification {name} (right / left)", pair(amounts, 1), MICRO)
            for name, amounts in mods.amounts_um.items()]
    for kind, diameters in (("tip", mods.tip_relief_start_diameters_mm), ("root", mods.root_relief_start_diameters_mm)):
        if any(diameters):
            rows.append(Row(f"{kind} relief starts at diameter (right / left)", pair(diameters, 3), "mm"))
    if mods.measured_unmodified:
        rows.append(Row("span and pins", "measured where the flanks are unmodified (outside every relief)"))
        return rows
    rows.append(Row("warning: the span anvils touch modified flanks, removal (right / left)",
                    pair(mods.span_removal_um, 1), MICRO))
    if mods.span_modified_mm is not None:
        rows.append(Row("span measurement the modified gear reads", number(mods.span_modified_mm, 4), "mm"))
    rows.append(Row("warning: the pins (balls) touch modified flanks, removal (right / left)",
                    pair(mods.pin_removal_um, 1), MICRO))
    return rows


def expected_tolerance(result: JobResult) -> str | None:
    """The span and thickness the simulated cut leaves (from the involute flanks' deviations), or None."""
    ins, sim = result.inspection, result.simulation
    found = [sim.feature(f"{side} involute") for side in ("right", "left")]
    flanks = [f for f in found if f is not None]
    if not (sim.enabled and len(flanks) == len(found) and ins.span_measurement_mm is not None):
        return None
    low = -max(f.max_gouge_mm for f in flanks)
    high = max(f.max_leftover_mm for f in flanks)
    return (f"The simulated cut leaves each involute flank {signed(1000 * low)} to {signed(1000 * high)} {MICRO} "
            f"from the design: span measurement {number(ins.span_measurement_mm + 2 * low, 4)} to "
            f"{number(ins.span_measurement_mm + 2 * high, 4)} mm.")


def simulation_rows(result: JobResult) -> tuple[Row, ...]:
    """The simulated cut's figures in µm."""
    sim = result.simulation
    if not sim.enabled:
        return ()
    return (Row("resolution", number(1000 * sim.resolution_mm, 1), MICRO),
            Row("largest gouge (material cut below the design)", number(1000 * sim.max_gouge_mm, 1), MICRO),
            Row("largest leftover (material left above the design)", number(1000 * sim.max_leftover_mm, 1), MICRO),
            Row("leftover: mean / 95 % / 99 % of the finished points",
                f"{number(1000 * sim.scallop_mean_mm, 1)} / {number(1000 * sim.scallop_p95_mm, 1)} / "
                f"{number(1000 * sim.scallop_p99_mm, 1)}", MICRO),
            Row("removed volume", number(sim.removed_volume_mm3, 0), "mm³"),
            Row("design points measured (all spaces and rows)", f"{sim.design_points:,}")) + engagement_rows(result)


def engagement_rows(result: JobResult) -> tuple[Row, ...]:
    """The roughing engagement measured on the simulated stock (none without roughing or simulation)."""
    rough = result.roughing
    if rough is None or rough.max_radial_engagement_fraction is None:
        return ()
    return (Row("roughing: largest radial engagement (width met / tool diameter)",
                number(rough.max_radial_engagement_fraction, 2), "x D"),
            Row("roughing: largest axial depth met", number(rough.max_axial_depth_mm, 3), "mm"),
            Row("roughing: mean material removal rate (while removing)", number(rough.mean_removal_rate_mm3_min, 0),
                "mm³/min"))


def feature_table(result: JobResult) -> Table:
    """Per feature of the tooth space: largest gouge and leftover, mean deviation (µm)."""
    sim = result.simulation
    rows = tuple((f.feature, number(1000 * f.max_gouge_mm, 1), number(1000 * f.max_leftover_mm, 1),
                  signed(1000 * f.mean_mm, 1)) for f in sim.per_feature) if sim.enabled else ()
    return Table(("feature", f"largest gouge [{MICRO}]", f"largest leftover [{MICRO}]", f"mean [{MICRO}]"), rows)


DEVIATION_LABELS = {"f_pt": "single pitch f_pt", "F_p": "total cumulative pitch F_p", "f_Ha": "profile slope f_Ha",
                    "f_fa": "profile form f_fa", "F_a": "total profile F_a", "f_Hb": "helix slope f_Hb",
                    "f_fb": "helix form f_fb", "F_b": "total helix F_b"}


def grading_table(result: JobResult) -> Table:
    """ISO 1328-1 deviations of the worst flank (µm) and their classes: on the ideal machine, and with the
    machine's error budget (expected) and the budget's share, when the run has one."""
    grading, budget = result.grading, result.error_budget
    if grading is None:
        return Table(("deviation (worst flank)", f"[{MICRO}]", "class"), ())
    ideal = {name: (number(grading.deviations_um[name], 1), str(grading.classes[name] or "beyond 11"))
             for name in DEVIATION_LABELS}
    if budget is None:
        return Table(("deviation (worst flank)", f"[{MICRO}]", "class"),
                     tuple((label, *ideal[name]) for name, label in DEVIATION_LABELS.items()))
    expected = budget.grading
    rows = tuple((label, *ideal[name], number(expected.deviations_um[name], 1),
                  str(expected.classes[name] or "beyond 11"), signed(budget.share_um[name], 1))
                 for name, label in DEVIATION_LABELS.items())
    return Table(("deviation (worst flank)", f"ideal machine [{MICRO}]", "class", f"with the budget [{MICRO}]",
                  "class", f"budget's share [{MICRO}]"), rows)


def modifications_cut_table(result: JobResult) -> Table:
    """A modified gear's flank modifications as designed and as cut (ISO 21771 amounts read from the simulated
    flanks, spur_cad.grade.design_trace), one row per modification and flank side; no rows for an unmodified gear."""
    cuts = () if result.grading is None else result.grading.modifications_cut or ()
    return Table(("modification (ISO 21771)", "flank", f"designed [{MICRO}]", f"cut [{MICRO}]", "traces"),
                 tuple((f"{cut.name} {cut.symbol}", cut.side, number(cut.designed_um, 1), number(cut.cut_um, 1),
                        str(cut.traces)) for cut in cuts))


def error_budget_text(result: JobResult) -> str:
    """The report's sentence on the error budget: what it holds and the expected class."""
    budget = result.error_budget
    if budget is None:
        return ""
    terms, shift = budget.terms, budget.terms.flank_shift_um
    deflection = budget.deflection
    bent = (f"the finishing tool bent {number(deflection.deflection_um, 1)} {MICRO} by "
            f"{number(deflection.force_n, 2)} N "
            f"({deflection.material}, k_c1.1 {number(deflection.kc11_n_mm2, 0)} N/mm², m_c {number(deflection.mc, 2)})"
            if deflection is not None else "no tool deflection (no finishing tool with a stick-out)")
    places = {name: signed(shift[name], 1) for name in ("total", "runout", "tool_radius", "linear", "deflection")}
    return machine_setup(result).error_budget_text.format(
        klass=budget.grading.overall_class or "beyond 11", index_source=terms.index_source, seed=terms.random_seed,
        largest_index=number(max((abs(e) for e in terms.index_error_arcsec), default=0.0), 1), bent=bent,
        thickness=signed(budget.tooth_thickness_change_um, 1), micro=MICRO, **places) + eccentric_gear_text(terms)


def eccentric_gear_text(terms) -> str:
    """What a once-per-turn table error applied at each flank point's cutting A makes (an eccentric gear), and that a
    best-fit measurement does not show it; empty when the budget was applied per space or has none."""
    if terms.eccentricity_um < 0.05:
        return ""
    return (f" Its once-per-turn part makes an eccentric gear, the teeth about a centre "
            f"{number(terms.eccentricity_um, 1)} {MICRO} off the axis they were cut on: the expected F_p counts it "
            "about that axis (the datum, the bore); a best-fit measurement, which fits the centre to the teeth, "
            "will not show it (spur-cad grade --datum axis does).")


def warning_lines(result: JobResult) -> tuple[str, ...]:
    """The run's warnings and the simulation's own (a gouge beyond the resolution, points never cut)."""
    items = list(result.warnings)
    sim = result.simulation
    if sim.enabled:
        w = sim.worst_gouge
        if sim.max_gouge_mm > sim.resolution_mm and w is not None:  # a gouge has its place
            items.append(f"simulation: gouge of {number(1000 * sim.max_gouge_mm, 1)} {MICRO} at tooth space "
                         f"{w.space}, {w.feature}, X = {number(w.x_mm, 3)} mm")
        if sim.uncut_points:
            items.append(f"simulation: {sim.uncut_points:,} design points keep more than "
                         f"{number(sim.leftover_range_mm, 1)} mm of material (never cut)")
    return tuple(items)


def correction_table(correction: CorrectionFacts | None) -> Table | None:
    """The corrected set's errors (spur-cad correct's correction): each one identified with its uncertainty, what the
    programs change for it, and the deviation before and as predicted after on the machine that cut the measured
    gear. None for a run that is not a correction."""
    if correction is None:
        return None
    c = correction
    rows = [(f"flank position (tool size) [{MICRO}]", signed(c.size_um, 1), number(c.size_uncertainty_um, 1),
             f"finishing tool programmed as D {number(c.tool_programmed_mm, 4)} mm (D {number(c.tool_before_mm, 4)} "
             "mm in the tool table)", signed(c.flank_position_before_um, 1), signed(c.flank_position_after_um, 1))]
    if c.table_kept is None:
        rows.append(("table error e(A) [arcsec]", "not seen", "", "not corrected (below): a probe log turns on the "
                     "table that cut the gear", "", ""))
    else:
        how = "every block's A moved by -e(A)" if c.a_words_moved else "not corrected"
        if c.y_z_words_moved:
            how += "; order 1 as the blank's offset: every block's Y, Z moved"
        if c.unfolded:
            how += " (programs unfolded)"
        rows += [(f"table error e(A), order {h.order} [arcsec]",
                  f"{number(h.amplitude_arcsec, 1)} \u00d7 sin({h.order}A {signed(h.phase_deg, 1)}\u00b0)",
                  number(h.uncertainty_arcsec, 1), how, "", "") for h in c.table_kept]
        if not c.table_kept:
            lowest, highest = c.table_orders_tested if c.table_orders_tested is not None else ("", "")
            rows.append(("table error e(A) [arcsec]", "none found", "", f"orders {lowest} to {highest} tested", "",
                         ""))
    rows += [(f"F_p, {p.side} flanks [{MICRO}]", "", "", "by the table's correction", number(p.before_um, 1),
              number(p.after_um, 1)) for p in c.pitch]
    for slopes, label, symbol in ((c.profile_slopes, "profile slope", "f_H\u03b1"),
                                  (c.helix_slopes, "helix slope", "f_H\u03b2")):
        for found in slopes:
            how = "not corrected (below)"
            if c.slopes_corrected:
                how = "flank passes moved along their normal"
                if found.pressure_angle_change_deg is not None:
                    how += f" (pressure angle as cut {signed(found.pressure_angle_change_deg, 4)} deg)"
            rows.append((f"{label} {symbol}, {found.side} flanks [{MICRO}]", signed(found.value_um, 1),
                         number(found.uncertainty_um, 1), how, signed(found.before_um, 1), signed(found.after_um, 1)))
    return Table(("error", "identified", "uncertainty (1 s.d.)", "corrected by", "before", "predicted after"),
                 tuple(rows))


def correction_notes(correction: CorrectionFacts | None) -> tuple[str, ...]:
    """What the corrected programs do not correct, and why, one line each; first, for a once-per-turn error, which
    model was assumed and what the user checks."""
    return () if correction is None else correction.notes
