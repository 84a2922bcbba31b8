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
from spur_cad.dialects import DIALECTS, Dialect, Dialects, LatheWords, lathe_names
from spur_cad.errors import require_instance, shown
from spur_cad.post.header import comment_line, program_head, setup_blocks
from spur_cad.post.program import MAX_COORDINATE_MM

COORDINATE_DECIMALS = 3  # X (diameter) and Z: 1 um
FEED_DECIMALS = 3  # mm/rev


def lathe_dialect(dialect: str | Dialect, dialects: Dialects = DIALECTS) -> Dialect:
    """The dialect called `dialect` in `dialects` when it has lathe words, or a LatheError listing the registry's
    lathe dialects; a `Dialect` with lathe words is returned as it is (a controller in no registry, e.g. one being
    added)."""
    found = dialect if isinstance(dialect, Dialect) else dialects.get(dialect) if isinstance(dialect, str) else None
    if found is None or found.lathe is None:
        name = dialect.name if isinstance(dialect, Dialect) else dialect
        raise LatheError(f"[lathe] dialect = {shown(name)} is not known (known: {', '.join(lathe_names(dialects))})",
                         field="dialect")
    return found


def _lathe_words(d: Dialect) -> LatheWords:
    """The lathe words of a dialect lathe_dialect returned (it has them)."""
    if d.lathe is None:
        raise LatheError(f"[lathe] dialect = {shown(d.name)} has no lathe words", field="dialect")
    return d.lathe


def lathe_extension(dialect: str | Dialect, dialects: Dialects = DIALECTS) -> str:
    """The program file's extension for a lathe dialect (siemens mpf, fanuc nc, linuxcnc ngc)."""
    return lathe_dialect(dialect, dialects).extension


def _number(value: float, decimals: int) -> str:
    """`value` rounded to `decimals`, with at least one digit after the point: 105.0, -23.2, 0.05."""
    units = int(round(value * 10 ** decimals))
    sign = "-" if units < 0 else ""
    whole, fraction = divmod(abs(units), 10 ** decimals)
    return f"{sign}{whole}.{f'{fraction:0{decimals}d}'.rstrip('0') or '0'}"


class _Program:
    """The blocks of one lathe program in one dialect (its file frame and its lathe words)."""

    def __init__(self, lathe: LatheSection, d: Dialect, words: LatheWords):
        self.lathe, self.d, self.words = lathe, d, words
        self.lines: list[str] = []

    def comment(self, text: str) -> str:
        return comment_line(self.d, text)

    def spindle_code(self) -> str:
        direction = self.lathe.spindle_direction
        return direction.replace("M", "M0") if self.words.padded_m_codes else direction

    def header(self, plan: LathePlan, title: str, comments: Sequence[str]) -> None:
        lathe, g, d, words = self.lathe, plan.geometry, self.d, self.words
        rpm = str(int(round(lathe.max_spindle_rpm)))
        self.lines += program_head(d, lathe.program_number, title, (*comments, *_setup_comments(plan, lathe)))
        workpiece = words.workpiece.format(
            top=_number(plan.face_stock_mm, COORDINATE_DECIMALS),
            far=_number(g.end_z - lathe.parting_blade_width_mm, COORDINATE_DECIMALS),
            end=_number(g.end_z, COORDINATE_DECIMALS), diameter=_number(g.bar_diameter, COORDINATE_DECIMALS))
        self.lines += setup_blocks(d, words.setup, lathe.work_offset, workpiece)
        if words.spindle_limit:
            self.lines.append(words.spindle_limit.format(rpm=rpm))

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
        self.lines += [self.comment(f"T{tool}: {what}"), self.words.tool_change.format(tool=tool),
                       self.words.constant_speed.format(vc=vc, rpm=rpm, direction=self.spindle_code()),
                       self.d.coolant_on]

    def end(self) -> None:
        d = self.d
        self.lines += [d.coolant_off, d.spindle_off, *self.words.end, d.program_end]
        if d.percent_delimited:
            self.lines.append("%")


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


def post_lathe(plan: LathePlan, lathe: LatheSection, title: str, comments: Sequence[str] = (),
               dialect: Dialect | None = None, dialects: Dialects = DIALECTS) -> str:
    """The text of the lathe program for `plan` (spur_cad.cam.turning.plan_lathe) in [lathe] dialect (of the
    registry `dialects`), or in `dialect` when given (a controller with lathe words in no registry; lathe.dialect
    is then not used).

    `title` (e.g. the job's name) and `comments` are user text: each becomes one inert comment line.
    """
    require_instance(plan, LathePlan, "plan")
    require_instance(lathe, LatheSection, "lathe")
    require_instance(title, str, "title")
    if dialect is not None:
        require_instance(dialect, Dialect, "dialect")
    d = lathe_dialect(lathe.dialect if dialect is None else dialect, dialects)
    _check_plan(plan)
    if not plan.moves:
        raise LatheError("the lathe plan has no moves")
    program = _Program(lathe, d, _lathe_words(d))
    program.header(plan, title, [str(c) for c in comments])
    tool, motion, feed = 0, "", None
    position: tuple[int | None, int | None] = (None, None)
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
    limit = d.max_line_length
    too_long = [n for n, line in enumerate(program.lines, start=1) if len(line) > limit]
    if too_long:
        raise LatheError(f"lathe program line {too_long[0]} is longer than the {d.name} limit of {limit}")
    return "\n".join(program.lines) + "\n"
