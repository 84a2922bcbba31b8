"""The on-machine probing program as text (issue 30): a ProbePlan in, probe.<ext> out (no file I/O).

Written for the dialects with probing words (spur_cad.dialects.ProbingWords): LinuxCNC (G38.2, the
trips logged by PROBEOPEN / PROBECLOSE) and Fanuc and Haas (G31, the skip position written by DPRNT between
POPEN and PCLOS); others are refused with a message naming [post] dialect. docs/probing.md lists every block.
The ball's centre is programmed (the probe's length offset reaches it), never with radius compensation; rapids
only at the clearance height, where A indexes; every other move at a feed. User text (the job's name) only
appears inside one bounded inert comment.
"""

from __future__ import annotations

from spur_cad.cam.probing import ProbeError, ProbePlan
from spur_cad.dialects import DIALECTS, Dialect, Dialects, ProbingWords, probing_names
from spur_cad.errors import require_instance, shown
from spur_cad.post.header import comment_line, program_head, setup_blocks
from spur_cad.post.settings import PostSettings

NO_TRIP_TOLERANCE_MM = 0.001
"""Fanuc / Haas: a skip position this close to the move's end means the probe never tripped (alarm)."""

BLIND_SPOTS = (
    "WHAT PROBING IN THE CUTTING SETUP CANNOT SEE: errors the cutting and the probing share are invisible to it:",
    "the table's repeatable index error, the A axis's offsets in Y and Z, the linear axes' errors and scale.",
    "It sees what differs between the two: the cutter's size and wear, its deflection and runout.",
    "Pitch (index) deviations need an external measurement or the table's calibration.",
)
"""The header's statement of what on-machine probing cannot see (docs/probing.md)."""


def probing_dialect(name: str | Dialect, dialects: Dialects = DIALECTS) -> Dialect:
    """The dialect with probing words called `name` in `dialects`, or a ProbeError naming [post] dialect."""
    d = name if isinstance(name, Dialect) else dialects.get(name)
    if d is None or d.probing is None:
        shown_name = name.name if isinstance(name, Dialect) else name
        raise ProbeError(f"[post] dialect = {shown(shown_name)} has no probing program (probe.<ext> is written "
                         f"for {', '.join(probing_names(dialects))}); leave [probe] out or choose one of them",
                         field="dialect", section="post")
    return d


def _number(value: float, decimals: int) -> str:
    """`value` rounded to `decimals`, at least one digit after the point, no '-0.0'."""
    units = int(round(value * 10 ** decimals))
    sign = "-" if units < 0 else ""
    whole, fraction = divmod(abs(units), 10 ** decimals)
    return f"{sign}{whole}.{f'{fraction:0{decimals}d}'.rstrip('0') or '0'}"


def _header_comments(plan: ProbePlan, words: ProbingWords, gear_comment: str) -> list[str]:
    probe, points = plan.section, plan.points
    kinds = {kind: sum(p.kind == kind for p in points) for kind in ("pitch", "profile", "helix")}
    log = ("each trip's ball centre goes to probe.log as X Y Z A B C U V W, one line per point in program order"
           if not words.record else
           "each trip's ball centre is written by DPRNT as X Y Z A, one line per point in program order")
    return [
        gear_comment,
        f"probe T{probe.tool_number}: ball D {probe.stylus_diameter_mm:g} mm, stem D {probe.stem_diameter_mm:g} mm; "
        "the ball's centre is programmed (length offset to it)",
        f"points: {len(points)} ({kinds['pitch']} pitch, {kinds['profile']} profile, {kinds['helix']} helix); "
        f"traces in spaces {', '.join(str(k) for k in plan.trace_spaces)}",
        "space k at A = -k*360/z (its axis vertical); A indexed at the clearance height only",
        f"each point p along its design normal n: from p + (R + {probe.approach_mm:g}) n probe at F"
        f"{probe.feed_mm_min:g} to p + (R - {probe.overtravel_mm:g}) n, back to p + (R + {probe.retract_mm:g}) n",
        log,
        *BLIND_SPOTS,
    ]


class _Writer:
    """Numbers and words of one probing program in dialect `d` with the [post] settings' A convention."""

    def __init__(self, d: Dialect, words: ProbingWords, settings: PostSettings, plan: ProbePlan):
        self.d, self.words, self.settings, self.plan = d, words, settings, plan
        self.lines: list[str] = []
        probe = plan.section
        self.clear_z = f"Z{self.number(plan.clearance_z_mm)}"
        self.positioning = f"F{_number(probe.positioning_feed_mm_min, d.feed_decimals)}"
        self.probing = f"F{_number(probe.feed_mm_min, d.feed_decimals)}"

    def number(self, value_mm: float) -> str:
        return _number(value_mm, self.d.linear_decimals)

    def comment(self, text: str) -> None:
        self.lines.append(comment_line(self.d, text))

    def a_word(self, a_deg: float) -> str:
        decimals = self.d.rotary.decimals
        a = self.settings.rotary_sign * a_deg
        if self.settings.rotary_mode == "wrapped":
            a = a % 360.0
            a = 0.0 if round(a * 10 ** decimals) == 360 * 10 ** decimals else a
        return "A" + _number(a, decimals)

    def yz(self, position) -> str:
        return f"Y{self.number(position[0])} Z{self.number(position[1])}"

    def start(self, title: str, gear_comment: str) -> None:
        d, probe, settings = self.d, self.plan.section, self.settings
        comments = _header_comments(self.plan, self.words, gear_comment)
        self.lines += program_head(d, probe.program_number, title, comments)
        self.lines += [*setup_blocks(d, (d.setup,), settings.work_offset), d.spindle_off,
                       *(block.format(tool=probe.tool_number) for block in d.tool_change)]
        if probe.probe_on_code:
            self.lines.append(probe.probe_on_code)
        self.lines += [f"G0 {self.clear_z}", self.words.log_open]

    def point(self, number: int, point, move, leave_to_clearance: bool) -> None:
        """The blocks of one point: reach the start (from the clearance height or straight from the last
        back-off), the probe move, the record and the no-trip check where the control needs them, the back-off."""
        words, lines = self.words, self.lines
        self.comment(f"P{number} space {point.space} {point.side} {point.kind} r {point.radius_mm:.4f} "
                     f"x {point.x_mm:.4f}")
        if move.link_via_clearance:
            lines += [f"G0 X{self.number(point.x_mm)} Y{self.number(move.start[0])}",
                      f"G1 Z{self.number(move.start[1])} {self.positioning}"]
        else:
            lines.append(f"G1 X{self.number(point.x_mm)} {self.yz(move.start)} {self.positioning}")
        lines.append(f"{words.probe_move} {self.yz(move.target)} {self.probing}")
        if words.record:
            lines.append(words.record)
        if words.no_trip_check:
            lines.append(words.no_trip_check.format(y=self.number(move.target[0]), z=self.number(move.target[1]),
                                                    tol=self.number(NO_TRIP_TOLERANCE_MM)))
        lines.append(f"G1 {self.yz(move.retract)} {self.positioning}")
        if leave_to_clearance:
            lines.append(f"G1 {self.clear_z} {self.positioning}")

    def end(self) -> None:
        d, probe = self.d, self.plan.section
        self.lines.append(self.words.log_close)
        if probe.probe_off_code:
            self.lines.append(probe.probe_off_code)
        self.lines.append(d.program_end)
        if d.percent_delimited:
            self.lines.append("%")


def post_probe(plan: ProbePlan, settings: PostSettings, title: str, gear_comment: str,
               dialects: Dialects = DIALECTS) -> str:
    """The text of the probing program for `plan` (spur_cad.cam.probing.plan_probe) in [post] dialect (of the
    registry `dialects`).

    `title` (e.g. with the job's name) is user text: it becomes one inert comment. A is written with
    [post] rotary_sign, and in [0, 360) when rotary_mode is "wrapped".
    """
    require_instance(plan, ProbePlan, "plan")
    require_instance(settings, PostSettings, "settings")
    d = probing_dialect(settings.dialect, dialects)
    if d.probing is None:  # probing_dialect returns dialects with probing words only
        raise ProbeError(f"[post] dialect = {shown(d.name)} has no probing words", field="dialect", section="post")
    writer = _Writer(d, d.probing, settings, plan)
    writer.start(title, gear_comment)
    space = None
    for index, (point, move) in enumerate(zip(plan.points, plan.moves)):
        if point.space != space:  # the ball is at the clearance height here: index A
            space = point.space
            writer.comment(f"space {space}")
            writer.lines.append(f"G0 {writer.a_word(point.a_deg)}")
        last = index + 1 == len(plan.moves)
        writer.point(index + 1, point, move, last or plan.moves[index + 1].link_via_clearance)
    writer.end()
    too_long = [n for n, line in enumerate(writer.lines, start=1) if len(line) > d.max_line_length]
    if too_long:
        raise ProbeError(f"probe program line {too_long[0]} is longer than the {d.name} limit of {d.max_line_length}")
    return "\n".join(writer.lines) + "\n"
