"""The blank's lathe program as text (issue 18): a LathePlan in, one program for Siemens 840D, Fanuc lathe
(G-code system A) or LinuxCNC lathe out (no file I/O). docs/lathe.md lists every block.

Common to all three: work offset ([lathe] work_offset), metric, absolute, X as diameter, feed per revolution,
constant cutting speed (G96) under the spindle limit, coolant M8 / M9, spindle off, M30; no tool nose radius
compensation (G40): the insert is programmed at its theoretical tip, the blade at its corner toward the part.
User text (the job's name, comments) only ever appears inside one inert comment of bounded length.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from spur_cad.cam.turning import LatheError, LathePlan, LatheSection
from spur_cad.errors import require_instance, shown
from spur_cad.post.program import MAX_COORDINATE_MM, inert_comment_text

LATHE_EXTENSIONS = {"siemens": "mpf", "fanuc": "nc", "linuxcnc": "ngc"}
MAX_LINE_LENGTH = {"siemens": 200, "fanuc": 128, "linuxcnc": 250}
COORDINATE_DECIMALS = 3  # X (diameter) and Z: 1 um
FEED_DECIMALS = 3  # mm/rev
WORKPIECE_BITS = 192
"""840D WORKPIECE(...) blank of SINUMERIK Operate: the bit value 192 marks ZI and ZB as absolute (see docs/lathe.md)."""


def lathe_extension(dialect: str) -> str:
    """The program file's extension for a lathe dialect: siemens mpf, fanuc nc, linuxcnc ngc."""
    if dialect not in LATHE_EXTENSIONS:
        raise LatheError(f"[lathe] dialect = {shown(dialect)} is not known (known: {', '.join(LATHE_EXTENSIONS)})",
                         field="dialect")
    return LATHE_EXTENSIONS[dialect]


def _number(value: float, decimals: int) -> str:
    """`value` rounded to `decimals`, with at least one digit after the point: 105.0, -23.2, 0.05."""
    units = int(round(value * 10 ** decimals))
    sign = "-" if units < 0 else ""
    whole, fraction = divmod(abs(units), 10 ** decimals)
    return f"{sign}{whole}.{f'{fraction:0{decimals}d}'.rstrip('0') or '0'}"


class _Program:
    """The blocks of one lathe program in one dialect."""

    def __init__(self, lathe: LatheSection):
        self.lathe, self.d = lathe, lathe.dialect
        self.lines: list[str] = []

    def comment(self, text: str) -> str:
        width = MAX_LINE_LENGTH[self.d] - 4
        text = inert_comment_text(text, width)
        if self.d == "fanuc":
            text = text.upper()
        return f"; {text}" if self.d == "siemens" else f"({text})"

    def spindle_code(self) -> str:
        return self.lathe.spindle_direction.replace("M", "M0") if self.d == "fanuc" else self.lathe.spindle_direction

    def header(self, plan: LathePlan, title: str, comments: Sequence[str]) -> None:
        lathe, g = self.lathe, plan.geometry
        rpm = str(int(round(lathe.max_spindle_rpm)))
        if self.d == "fanuc":
            title_text = inert_comment_text(title, MAX_LINE_LENGTH["fanuc"] - 16).upper()
            self.lines += ["%", f"O{lathe.program_number:04d} ({title_text})"]
        else:
            self.lines.append(self.comment(title))
        self.lines += [self.comment(text) for text in (*comments, *_setup_comments(plan, lathe))]
        if self.d == "siemens":
            top, far = _number(plan.face_stock_mm, COORDINATE_DECIMALS), _number(
                g.end_z - lathe.parting_blade_width_mm, COORDINATE_DECIMALS)
            self.lines += [f'WORKPIECE(,,,"CYLINDER",{WORKPIECE_BITS},{top},{far},'
                           f'{_number(g.end_z, COORDINATE_DECIMALS)},{_number(g.bar_diameter, COORDINATE_DECIMALS)})',
                           "G18 G90 G71 G95 G40 DIAMON", lathe.work_offset, f"LIMS={rpm}"]
        elif self.d == "fanuc":
            self.lines += ["G21 G18 G40 G99", lathe.work_offset, f"G50 S{rpm}"]
        else:
            self.lines += ["G7", "G18 G21 G90 G40 G95", lathe.work_offset]

    def tool_call(self, tool: int) -> None:
        lathe = self.lathe
        speeds = {lathe.turning_tool_number: lathe.turning_cutting_speed_m_min,
                  lathe.parting_tool_number: lathe.parting_cutting_speed_m_min}
        if tool not in speeds:
            raise LatheError(f"the lathe plan uses tool {tool}, which [lathe] does not describe (turning insert "
                             f"{lathe.turning_tool_number}, parting blade {lathe.parting_tool_number})",
                             field="turning_tool_number")
        vc = str(max(1, int(round(speeds[tool]))))
        rpm = str(int(round(lathe.max_spindle_rpm)))
        what = "turning insert" if tool == lathe.turning_tool_number else "parting blade"
        self.lines.append(self.comment(f"T{tool}: {what}"))
        if self.d == "siemens":
            self.lines += [f"T{tool} D1", f"G96 S{vc} {self.spindle_code()}", "M8"]
        elif self.d == "fanuc":
            self.lines += [f"T{tool:02d}{tool:02d}", f"G96 S{vc} {self.spindle_code()}", "M08"]
        else:
            self.lines += [f"T{tool} M6 G43", f"G96 D{rpm} S{vc} {self.spindle_code()}", "M8"]

    def end(self) -> None:
        if self.d == "fanuc":
            self.lines += ["M09", "M05", "G97", "M30", "%"]
        else:
            self.lines += ["M9", "M5", "M30"]


def _setup_comments(plan: LathePlan, lathe: LatheSection) -> list[str]:
    g = plan.geometry
    stub = (f", stub dia {g.stub_diameter:g} x {g.stub_length:g}" if g.has_stub else ", no stub")
    return [f"bar dia {g.bar_diameter:g}, blank dia {g.blank_diameter:.3f} x {g.blank_length:g}{stub}",
            f"Z0 = faced front face ({plan.face_stock_mm:g} mm faced off), X = diameter",
            f"part end Z {g.end_z:g}: " + ("parted off" if plan.part_off else "left on the bar"),
            f"T{lathe.turning_tool_number}: program point = theoretical tip, nose radius "
            f"{lathe.turning_nose_radius_mm:g}, no compensation (45 deg chamfers short by the nose radius effect)",
            f"T{lathe.parting_tool_number}: blade {lathe.parting_blade_width_mm:g} wide, program point = its corner "
            "toward the part (+Z)"]


def _check_plan(plan: LathePlan) -> None:
    for index, move in enumerate(plan.moves):
        if not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE_MM for v in (move.x, move.z)):
            raise LatheError(f"lathe move {index} ({move.operation}) has a coordinate that is not a finite number "
                             f"within +-{MAX_COORDINATE_MM:g}")
        if not move.rapid and not (math.isfinite(move.feed) and round(move.feed * 10 ** FEED_DECIMALS) >= 1
                                   and move.feed <= 100.0):
            raise LatheError(f"lathe move {index} ({move.operation}) has no usable feed ({move.feed!r} mm/rev)")
        if not 1 <= move.tool <= 99:
            raise LatheError(f"lathe move {index} uses tool {move.tool}, outside 1..99")


def post_lathe(plan: LathePlan, lathe: LatheSection, title: str, comments: Sequence[str] = ()) -> str:
    """The text of the lathe program for `plan` (spur_cad.cam.turning.plan_lathe) in [lathe] dialect.

    `title` (e.g. the job's name) and `comments` are user text: each becomes one inert comment line.
    """
    require_instance(plan, LathePlan, "plan")
    require_instance(lathe, LatheSection, "lathe")
    require_instance(title, str, "title")
    lathe.validate()
    _check_plan(plan)
    if not plan.moves:
        raise LatheError("the lathe plan has no moves")
    program = _Program(lathe)
    program.header(plan, title, [str(c) for c in comments])
    tool, motion, position, feed = 0, "", (None, None), None
    for move in plan.moves:
        if move.tool != tool:
            program.tool_call(move.tool)
            tool, motion, position, feed = move.tool, "", (None, None), None  # both axes after a change
        x = int(round(move.x * 10 ** COORDINATE_DECIMALS))
        z = int(round(move.z * 10 ** COORDINATE_DECIMALS))
        words = []
        if x != position[0]:
            words.append("X" + _number(move.x, COORDINATE_DECIMALS))
        if z != position[1]:
            words.append("Z" + _number(move.z, COORDINATE_DECIMALS))
        if not words:
            continue
        position = (x, z)
        head = "G0" if move.rapid else "G1"
        if head != motion:
            words.insert(0, head)
            motion = head
        if not move.rapid:
            f = int(round(move.feed * 10 ** FEED_DECIMALS))
            if f != feed:
                words.append("F" + _number(move.feed, FEED_DECIMALS))
                feed = f
        program.lines.append(" ".join(words))
    program.end()
    limit = MAX_LINE_LENGTH[lathe.dialect]
    too_long = [n for n, line in enumerate(program.lines, start=1) if len(line) > limit]
    if too_long:
        raise LatheError(f"lathe program line {too_long[0]} is longer than the {lathe.dialect} limit of {limit}")
    return "\n".join(program.lines) + "\n"
