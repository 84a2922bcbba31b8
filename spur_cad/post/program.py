"""The post: a toolpath (IR) in, the text of one G-code program out (no file I/O).

One data-driven post serves every dialect (dialects.py). Coordinates are rounded to integer
units of each axis's last digit. A is written as the run's base angle plus the angle relative
to it, each rounded, so a flat program and its folded twin command exactly the same numbers
(error to the exact pose <= one unit of the last digit).

Folding: the IR is cut into runs of consecutive moves on one tooth space (`Toolpath.space`).
Runs whose text, written relative to their X and A base, is identical become one subprogram
(or repeat section) called once per run with that base; other runs are written inline.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cam.ir import MoveKind, Toolpath
from spur_cad.cam.machine import check_rotary_code
from spur_cad.dialects import DIALECTS, Dialect, Dialects, FoldStyle
from spur_cad.dialects import dialect as dialect_named
from spur_cad.errors import PostError, require_instance, shown
from spur_cad.post.header import program_head, setup_blocks
from spur_cad.post.settings import PostSettings

MAX_COORDINATE_MM = 100_000.0
"""Largest |X|, |Y|, |Z| a program may command (100 m: beyond any machining centre, far inside every
control's number format); larger or non-finite values are refused."""

@dataclass(frozen=True)
class ProgramInfo:
    """What the header says and the machine codes the body needs."""

    title: str  # e.g. "spur_cad finishing"
    comments: tuple[str, ...]  # gear data, tool, strategy, estimated time
    rotary_clamp_code: str = ""
    rotary_unclamp_code: str = ""
    blank_box_mm: tuple[float, float, float, float, float, float] | None = None  # x, y, z min then max (WORKPIECE)
    approach_z_mm: float | None = None  # restart programs: a Z-only rapid to this height before the first move
    first_space_a_reference_deg: float | None = None  # restart programs: A of the full program's run (see _runs)
    writes_a: bool = True  # False: a set-up without a rotary axis (MachineSetup.writes_a): no A words (A stays 0)


@dataclass(frozen=True)
class PostedProgram:
    text: str
    extension: str
    lines: int
    bytes: int
    subprograms: int
    calls: int


@dataclass(frozen=True)
class _Run:
    start: int
    stop: int
    x_base: int | None  # X in units when every move of the run has the same X, else None
    a_base: int  # A of the run's first move, in units (rotary sign applied)
    a_reference: float  # the exact A (degrees, sign applied) the run's A words are written relative to


@dataclass(frozen=True)
class _Call:
    """A run written as a call of subprogram `index` (of the program's subprogram bodies) with its base."""

    index: int
    run: _Run


def post_program(path: Toolpath, settings: PostSettings, info: ProgramInfo,
                 dialect: Dialect | None = None, dialects: Dialects = DIALECTS) -> PostedProgram:
    """Write `path` as one program in the settings' dialect (of the registry `dialects`), or in `dialect` when
    given (a controller in no registry, e.g. one being added: docs/post.md; settings.dialect is then not used)."""
    if dialect is not None:
        require_instance(dialect, Dialect, "dialect")
    d = dialect_named(settings.dialect if dialect is None else dialect, dialects)
    if len(path) == 0:
        raise PostError(f"{shown(info.title)}: the toolpath is empty")
    _check_numbers(path, info)
    if settings.rotary_mode == "wrapped" and d.rotary.direction_codes is None:
        _check_shortest_path(path)
    lin, rot = 10 ** d.linear_decimals, 10 ** d.rotary.decimals
    x = np.rint(path.x * lin).astype(np.int64)
    y = np.rint(path.y * lin).astype(np.int64)
    z = np.rint(path.z * lin).astype(np.int64)
    a_signed = settings.rotary_sign * path.a
    feed = _program_feeds(path, d, settings.rotary_sign)
    runs = _runs(path, x, a_signed, rot, settings.rotary_sign * info.first_space_a_reference_deg
                 if info.first_space_a_reference_deg is not None else None)
    centers = None
    if path.center_x is not None and path.center_y is not None:
        centers = (np.rint(np.nan_to_num(path.center_x) * lin).astype(np.int64),
                   np.rint(np.nan_to_num(path.center_y) * lin).astype(np.int64))
    columns = _Columns(path.kind, x, y, z, a_signed, path.inverse_time, feed, rot, centers)
    writer = _Writer(d, settings, info, columns, path.tool_number, int(round(path.spindle_rpm)))

    body: list[list[str] | _Call] = []  # inline blocks, or a call of subprogram `index` for a run
    sub_bodies: list[list[str]] = []
    if settings.folded:
        keys = [writer.run_key(run) if path.space[run.start] >= 0 else None for run in runs]
        counts: dict[bytes, int] = {}
        for key in keys:
            if key is not None:
                counts[key] = counts.get(key, 0) + 1
        subs: dict[bytes, int] = {}
        for run, key in zip(runs, keys):
            if key is not None and counts[key] > 1:
                if key not in subs:
                    subs[key] = len(sub_bodies)
                    sub_bodies.append(writer.run_lines(run, folded=True))
                body.append(_Call(subs[key], run))
            else:
                body.append(writer.run_lines(run, folded=False))
    else:
        body = [writer.run_lines(run, folded=False) for run in runs]
    text = writer.program(body, sub_bodies)
    return PostedProgram(text=text, extension=d.extension, lines=text.count("\n"), bytes=len(text.encode()),
                         subprograms=len(sub_bodies), calls=sum(1 for item in body if isinstance(item, _Call)))


ARC_RADIUS_TOLERANCE_MM = 1e-4
"""Largest difference of an arc's radius at its end from its start (LinuxCNC refuses 0.002 mm and 0.1 %)."""

MAX_FEED_VALUE = 1e9
"""Largest feed word value accepted (mm/min, or 1/min in inverse time): far beyond any machine, small
enough to be written without overflow."""


def _check_numbers(path: Toolpath, info: ProgramInfo) -> None:
    """Refuse what a control must never be given: non-finite, absurd or missing feeds and coordinates, a tool
    number outside 1..9999, a spindle speed below 1 rpm, clamp codes that are more than one M code."""
    for axis in ("x", "y", "z", "a"):
        values = getattr(path, axis)
        limit = MAX_COORDINATE_MM if axis != "a" else 360.0 * 1e6
        if not np.all(np.isfinite(values)) or np.abs(values).max() > limit:
            raise PostError(f"{shown(info.title)}: the toolpath has an {axis.upper()} value that is not a finite "
                            f"number within +-{limit:g}")
    feeds = path.feed[path.feed_mask]
    bad = ~(np.isfinite(feeds) & (feeds > 0.0) & (feeds <= MAX_FEED_VALUE))
    if bad.any():
        index = int(np.nonzero(path.feed_mask)[0][np.argmax(bad)])
        raise PostError(f"{shown(info.title)}: move {index} has no usable feed ({float(path.feed[index])!r})")
    if not 1 <= path.tool_number <= 9999:
        raise PostError(f"{shown(info.title)}: tool number {path.tool_number} must be in 1..9999")
    if not (math.isfinite(path.spindle_rpm) and path.spindle_rpm >= 1.0):
        raise PostError(f"{shown(info.title)}: spindle speed {path.spindle_rpm:g} rpm would be written as S0")
    arcs = path.arc_mask
    if arcs.any():
        if path.center_x is None or path.center_y is None:
            raise PostError(f"{shown(info.title)}: the toolpath has arcs without centres")
        _check_arcs(path, path.center_x, path.center_y, arcs, info)
    check_rotary_code(info.rotary_clamp_code, "rotary_clamp_code")
    check_rotary_code(info.rotary_unclamp_code, "rotary_unclamp_code")
    if not info.writes_a and (np.any(path.a) or np.any(path.kind == MoveKind.CLAMP_ROTARY)
                                 or np.any(path.kind == MoveKind.UNCLAMP_ROTARY)):
        raise PostError(f"{shown(info.title)}: the toolpath turns or clamps A, and the machine has no rotary axis")


def _check_arcs(path: Toolpath, center_x: np.ndarray, center_y: np.ndarray, arcs: np.ndarray,
                info: ProgramInfo) -> None:
    """Refuse arcs a control would refuse or misread: a centre that is not a finite number within range, A turned,
    an end off the start's circle, an end at the start (read as a full turn)."""
    cx, cy, starts = center_x[arcs], center_y[arcs], path.start_poses()[arcs]
    if not (np.all(np.isfinite(cx)) and np.all(np.isfinite(cy)) and max(np.abs(cx).max(), np.abs(cy).max())
            <= MAX_COORDINATE_MM) or np.any(path.a[arcs]):
        raise PostError(f"{shown(info.title)}: an arc has a centre that is not a finite number within "
                        f"+-{MAX_COORDINATE_MM:g}, or turns A (arcs are in the XY plane of a 3-axis program)")
    off = np.abs(np.hypot(path.x[arcs] - cx, path.y[arcs] - cy) - np.hypot(starts[:, 0] - cx, starts[:, 1] - cy))
    if off.max() > ARC_RADIUS_TOLERANCE_MM:
        raise PostError(f"{shown(info.title)}: an arc ends {off.max():.4f} mm off its circle (a control refuses it)")
    if np.any((starts[:, 0] == path.x[arcs]) & (starts[:, 1] == path.y[arcs])):
        raise PostError(f"{shown(info.title)}: an arc ends where it starts (a full turn); split it in two")


def _check_shortest_path(path: Toolpath) -> None:
    moves = path.kind <= MoveKind.LINEAR
    steps = np.abs(np.diff(path.a[moves]))
    if len(steps) and steps.max() >= 180.0:
        raise PostError(f"rotary_mode = 'wrapped': an A move of {steps.max():.3f} deg is not the shortest way "
                        "round, and this dialect has no direction codes; use rotary_mode = 'unwound'")


def _program_feeds(path: Toolpath, d: Dialect, rotary_sign: int) -> np.ndarray:
    """F per move: mm/min, or 1/min under G93. Without G93, the controller is taken to read F on a
    simultaneous move as the rate along sqrt(dX^2+dY^2+dZ^2+dA^2) (A in degrees), so F is that
    length times the intended 1/time."""
    feed = path.feed.copy()
    if d.inverse_time or not path.inverse_time.any():
        return feed
    prev = lambda v: np.concatenate([v[:1], v[:-1]])  # noqa: E731 - start pose of each move
    length = np.sqrt((path.x - prev(path.x)) ** 2 + (path.y - prev(path.y)) ** 2 + (path.z - prev(path.z)) ** 2
                     + (path.a - prev(path.a)) ** 2)
    return np.where(path.inverse_time, length * path.feed, feed)


def _runs(path: Toolpath, x: np.ndarray, a_signed: np.ndarray, rot: int,
          first_space_reference: float | None = None) -> list[_Run]:
    """Maximal runs of consecutive moves on one tooth space (moves on no space form their own runs). Each run's
    A words are relative to its first move's A; the first run on a space uses `first_space_reference` instead
    when given (a restart: the A its run has in the full program, so both round alike)."""
    space = path.space
    cuts = np.flatnonzero(np.diff(space) != 0) + 1
    bounds = np.concatenate([[0], cuts, [len(space)]])
    runs = []
    for start, stop in zip(bounds[:-1], bounds[1:]):
        xs = x[start:stop]
        x_base = int(xs[0]) if np.all(xs == xs[0]) else None
        reference = float(a_signed[start])
        if first_space_reference is not None and space[start] >= 0:
            reference, first_space_reference = first_space_reference, None
        runs.append(_Run(int(start), int(stop), x_base, int(round(reference * rot)), reference))
    return runs


@dataclass(frozen=True)
class _Columns:
    kind: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    a: np.ndarray  # degrees, rotary sign applied
    inverse: np.ndarray
    feed: np.ndarray
    rot: int
    centers: tuple[np.ndarray, np.ndarray] | None = None  # arcs' centres in output units (None: no arcs)


@functools.lru_cache(maxsize=1 << 16)
def _number(units: int, decimals: int) -> str:
    """Integer units of 10^-decimals as a decimal with at least one digit after the point."""
    sign = "-" if units < 0 else ""
    whole, frac = divmod(abs(units), 10 ** decimals)
    digits = f"{frac:0{decimals}d}".rstrip("0") or "0"
    return f"{sign}{whole}.{digits}"


@dataclass
class _Modal:
    """What the control holds between blocks of one run: motion and feed mode, F, the last position."""

    motion: str | None = None
    feed_mode: str | None = None
    feed_units: int | None = None
    position: tuple = (None, None, None, None)  # X, Y, Z, A-relative in output units
    a_exact: float | None = None


class _Writer:
    """Writes runs and the program frame for one dialect (holds no state between calls)."""

    def __init__(self, d: Dialect, settings: PostSettings, info: ProgramInfo, c: _Columns, tool: int, rpm: int):
        self.d, self.settings, self.info, self.c = d, settings, info, c
        self.tool, self.rpm = tool, rpm

    def run_key(self, run: _Run) -> bytes:
        """Everything a run's folded text depends on, as bytes: equal keys give equal subprogram text."""
        c, sl = self.c, slice(run.start, run.stop)
        a_rel = np.rint((c.a[sl] - run.a_reference) * c.rot).astype(np.int64)
        x = c.x[sl] - run.x_base if run.x_base is not None else c.x[sl]
        decimals = np.where(c.inverse[sl] & self.d.inverse_time, self.d.inverse_feed_decimals, self.d.feed_decimals)
        feed = np.rint(np.nan_to_num(c.feed[sl]) * 10.0 ** decimals).astype(np.int64)
        flag = b"x" if run.x_base is not None else b"-"
        centers = [] if c.centers is None else [c.centers[0][sl].tobytes(), c.centers[1][sl].tobytes()]
        return b"".join([flag, c.kind[sl].tobytes(), x.tobytes(), c.y[sl].tobytes(), c.z[sl].tobytes(),
                         a_rel.tobytes(), c.inverse[sl].tobytes(), feed.tobytes(), *centers])

    def run_lines(self, run: _Run, *, folded: bool) -> list[str]:
        """One run's blocks; folded: X and A written relative to the dialect's base parameters."""
        c = self.c
        lines: list[str] = []
        modal = _Modal()
        sl = slice(run.start, run.stop)
        a_rels = np.rint((c.a[sl] - run.a_reference) * c.rot).astype(np.int64).tolist()
        rows = zip(range(run.start, run.stop), c.kind[sl].tolist(), c.x[sl].tolist(), c.y[sl].tolist(),
                   c.z[sl].tolist(), a_rels, c.a[sl].tolist(), c.inverse[sl].tolist(), c.feed[sl].tolist())
        for i, kind, x, y, z, a_rel, a_exact, inverse_move, feed in rows:
            if kind == MoveKind.CLAMP_ROTARY or kind == MoveKind.UNCLAMP_ROTARY:
                code = self.info.rotary_clamp_code if kind == MoveKind.CLAMP_ROTARY else self.info.rotary_unclamp_code
                if code:
                    lines.append(code)
                continue
            arc = kind == MoveKind.ARC_CW or kind == MoveKind.ARC_CCW
            if arc:
                words, direction = self._arc_words(i, modal, (x, y, z, a_rel)), None
            else:
                words, direction = self._position_words(run, folded, modal, (x, y, z, a_rel), a_exact)
            if not words:
                continue  # nothing moves at the output's precision
            modal.position, modal.a_exact = (x, y, z, a_rel), a_exact
            head = self._motion_words(kind, inverse_move, feed, i, modal, words)
            if direction:
                words.append(direction)
            lines.append(" ".join(head + words))
        if modal.feed_mode == "G93":
            lines.append("G94")
        return lines

    def _arc_words(self, index: int, modal: "_Modal", position: tuple[int, int, int, int]) -> list[str]:
        """An arc's words: X and Y always (an arc without them is a full turn), Z when it changes, and the centre as
        I and J from the arc's start as written (G17, incremental centre in every dialect). [] for an arc shorter
        than the output's precision."""
        lin_dec = self.d.linear_decimals
        x, y, z, _ = position
        last_x, last_y, last_z, _ = modal.position
        if last_x is None or last_y is None:
            raise PostError(f"{shown(self.info.title)}: move {index} is an arc from an unknown position")
        if self.c.centers is None:
            raise PostError(f"{shown(self.info.title)}: move {index} is an arc without a centre")
        i, j = int(self.c.centers[0][index]) - last_x, int(self.c.centers[1][index]) - last_y
        if (x, y) == (last_x, last_y):
            return []  # shorter than the precision (a full turn, which this would be read as, is refused before)
        words = ["X" + _number(x, lin_dec), "Y" + _number(y, lin_dec)]
        if z != last_z:
            words.append("Z" + _number(z, lin_dec))
        return words + ["I" + _number(i, lin_dec), "J" + _number(j, lin_dec)]

    def _position_words(self, run: _Run, folded: bool, modal: "_Modal", position: tuple[int, int, int, int],
                        a_exact: float) -> tuple[list[str], str | None]:
        """The X/Y/Z/A words of a move (only the axes that change) and the rotary direction code, if any."""
        d, subs = self.d, self.d.subprograms
        lin_dec, rot_dec = d.linear_decimals, d.rotary.decimals
        x, y, z, a_rel = position
        last_x, last_y, last_z, last_a = modal.position
        words: list[str] = []
        if x != last_x:
            words.append(subs.param_word.format(address="X", param=subs.x_param)
                         if folded and run.x_base is not None else "X" + _number(x, lin_dec))
        if y != last_y:
            words.append("Y" + _number(y, lin_dec))
        if z != last_z:
            words.append("Z" + _number(z, lin_dec))
        direction = None
        if a_rel != last_a and self.info.writes_a:
            if folded:
                offset = ("+" if a_rel > 0 else "") + _number(a_rel, rot_dec)
                words.append(subs.param_word.format(address="A", param=subs.a_param) if a_rel == 0 else
                             subs.param_offset_word.format(address="A", param=subs.a_param, offset=offset))
            else:
                wrapped = self.settings.rotary_mode == "wrapped"
                total = run.a_base + a_rel
                words.append("A" + _number(total % (360 * self.c.rot) if wrapped else total, rot_dec))
                codes = d.rotary.direction_codes
                if wrapped and codes and modal.a_exact is not None:
                    direction = codes[0] if a_exact > modal.a_exact else codes[1]
        return words, direction

    def _motion_words(self, kind: int, inverse_move: bool, feed: float, index: int, modal: "_Modal",
                      words: list[str]) -> list[str]:
        """The modal G words a move needs in front (G0/G1, G93/G94); appends its F word to `words`."""
        d = self.d
        head: list[str] = []
        if kind == MoveKind.RAPID:
            if modal.motion != "G0":
                head.append("G0")
                modal.motion = "G0"
            return head
        inverse = inverse_move and d.inverse_time
        mode = "G93" if inverse else "G94"
        if mode != modal.feed_mode:
            head.append(mode)
            modal.feed_mode = mode
            modal.feed_units = None
        motion = {int(MoveKind.ARC_CW): "G2", int(MoveKind.ARC_CCW): "G3"}.get(kind, "G1")
        if modal.motion != motion:
            head.append(motion)
            modal.motion = motion
        decimals = d.inverse_feed_decimals if inverse else d.feed_decimals
        if not (math.isfinite(feed) and feed > 0.0):
            raise PostError(f"{shown(self.info.title)}: move {index} has no usable feed ({feed!r})")
        f = int(round(feed * 10 ** decimals))
        if f < 1:
            raise PostError(f"{shown(self.info.title)}: move {index}'s feed {feed:g} would be written as F0")
        if inverse or f != modal.feed_units:  # G93 needs F in every feed block
            words.append("F" + _number(f, decimals))
            modal.feed_units = f
        return head

    def program(self, body: list[list[str] | _Call], sub_bodies: list[list[str]]) -> str:
        """The whole program: header, subprogram definitions (before or after the main body, per dialect),
        the main body with its calls, the end; block numbers and the line-length check last."""
        d, s, info = self.d, self.settings, self.info
        subs = d.subprograms
        sub_ids = self._sub_ids(len(sub_bodies))
        head = program_head(d, s.program_number, info.title, info.comments)
        definitions = [] if subs.after_end or subs.fold_style == FoldStyle.REPEATED_SECTION else \
            self._definitions(sub_bodies, sub_ids)
        main = self._start_blocks() + self._main_body(body, sub_bodies, sub_ids)
        if s.coolant:
            main.append(d.coolant_off)
        main += [d.spindle_off, d.program_end]
        tail = self._definitions(sub_bodies, sub_ids) if subs.after_end else []
        if d.percent_delimited:
            tail.append("%")
        lines = head + definitions + main + tail
        if s.line_numbers:
            lines = self._numbered(lines, min(sub_ids) - 1 if subs.fold_style == FoldStyle.LOCAL_LABEL and sub_ids
                                   else s.max_line_number)
        too_long = [n for n, line in enumerate(lines, start=1) if len(line) > d.max_line_length]
        if too_long:
            raise PostError(f"{shown(info.title)}: line {too_long[0]} would have {len(lines[too_long[0] - 1])} "
                            f"characters, more than the {d.name} limit of {d.max_line_length}")
        return "\n".join(lines) + "\n"

    def _start_blocks(self) -> list[str]:
        """Blank description, setup, work offset, tool, spindle, coolant, and a restart's move to the clearance
        height (up or down, Z alone, before moving across)."""
        d, s, info = self.d, self.settings, self.info
        lines = [*setup_blocks(d, (d.setup,), s.work_offset, self._workpiece()),
                 *[t.format(tool=self.tool) for t in d.tool_change], d.spindle_on.format(rpm=self.rpm)]
        if s.coolant:
            lines.append(d.coolant_on)
        if info.approach_z_mm is not None:
            lines.append("G0 Z" + _number(int(round(info.approach_z_mm * 10 ** d.linear_decimals)), d.linear_decimals))
        return lines

    def _workpiece(self) -> str:
        """The dialect's blank description for the control's simulation (Siemens WORKPIECE), "" for none."""
        box = self.info.blank_box_mm
        if not self.d.workpiece or box is None:
            return ""
        names = ("x_min", "y_min", "z_min", "x_max", "y_max", "z_max")
        units = 10 ** self.d.linear_decimals
        return self.d.workpiece.format(**{n: _number(int(round(v * units)), self.d.linear_decimals)
                                          for n, v in zip(names, box)})

    def _definitions(self, sub_bodies: list[list[str]], sub_ids: list[int]) -> list[str]:
        """Every subprogram, framed by the dialect's start and end blocks."""
        subs = self.d.subprograms
        lines: list[str] = []
        for index, body in enumerate(sub_bodies):
            lines += [subs.start.format(sub=sub_ids[index]), *body, subs.end.format(sub=sub_ids[index])]
        return lines

    def _main_body(self, body: list[list[str] | _Call], sub_bodies: list[list[str]], sub_ids: list[int]) -> list[str]:
        """Inline runs and subprogram calls in order; a repeat-style dialect writes each section at its first use."""
        d, subs = self.d, self.d.subprograms
        lin_dec, rot_dec = d.linear_decimals, d.rotary.decimals
        main: list[str] = []
        written: set[int] = set()
        for item in body:
            if not isinstance(item, _Call):
                main += item
                continue
            index, run = item.index, item.run
            if subs.fold_style == FoldStyle.REPEATED_SECTION and index not in written:  # first use: the section itself
                written.add(index)
                main += [subs.call[0].format(x=_number(run.x_base or 0, lin_dec), a=_number(run.a_base, rot_dec)),
                         subs.start.format(sub=sub_ids[index]), *sub_bodies[index],
                         subs.end.format(sub=sub_ids[index])]
            else:
                x = _number(run.x_base if run.x_base is not None else 0, lin_dec)
                main += [line.format(sub=sub_ids[index], x=x, a=_number(run.a_base, rot_dec)) for line in subs.call]
        return main

    def _sub_ids(self, count: int) -> list[int]:
        """Subprogram numbers: after the program number; Haas labels (N numbers) at the top of the range."""
        if self.d.subprograms.fold_style == FoldStyle.LOCAL_LABEL:
            top = self.settings.max_line_number
            return [top - count + 1 + i for i in range(count)]
        first = self.settings.program_number + 1
        if count and first + count - 1 > 9999:
            raise PostError(f"[post] program_number = {self.settings.program_number}: {count} subprograms "
                            "would be numbered past 9999; choose a lower program_number")
        return [first + i for i in range(count)]

    def _numbered(self, lines: list[str], limit: int) -> list[str]:
        """N words on every block that may carry one, never past `limit`."""
        step, overflow = self.settings.line_number_step, self.settings.line_number_overflow
        if limit < step:
            raise PostError(f"[post] max_line_number = {self.settings.max_line_number} leaves no block numbers "
                            "below the subprogram labels")
        out, n, numbering = [], step, True
        for line in lines:
            first = line[:1]
            if not numbering or first in ("%", "(", ";", "O", "o", "N", "#") or line.endswith(":"):
                out.append(line)
                continue
            out.append(f"N{n} {line}")
            n += step
            if n > limit:
                if overflow == "stop":
                    numbering = False
                n = step
        return out
