"""Read a G-code program from anywhere into the moves a controller would make (for `spur-cad verify`).

Reads the five dialects spur_cad writes, with their folded forms, and plain hand-written or legacy
programs in the same dialects:

- LinuxCNC: `oN sub` / `oN endsub`, `oN call [a] [b] ...` (arguments to #1, #2, ...), `oN repeat [n]` /
  `oN endrepeat`, `#n` and `[#n+c]` values;
- Fanuc: subprograms `O<n> ... M99` after M30, `M98 P<n> [L<count>]`, macro calls `G65 P<n> <letter
  arguments>` (A -> #1, B -> #2, C -> #3, I -> #4, ..., X -> #24, Y -> #25, Z -> #26, Fanuc's argument
  specification I), `#n` variables;
- Haas: as Fanuc, and local subprograms `M97 P<n>` jumping to block N<n> after M30;
- Siemens 840D: `R<n>=value` parameters, labels `NAME:` and `REPEAT L1 L2 P=n`, `A=R2+1.5` expressions,
  `;` comments;
- Okuma OSP: subprograms `O<n> ... RTS`, `CALL O<n> NAME=value ...` with named variables, `A=NAME-1.5`.

Modal motion (G0 / G1 stay in effect, so bare axis words move), one axis per block, G93 inverse time
and G94, F, T/M6, S. Rotary direction: in a block with M15 (positive) or M16 (negative), A is an angle
in [0, 360] (360 read as 0) reached turning that way (Okuma), and an angle already reached (within
DIRECTED_TOLERANCE_DEG) is no move; elsewhere A is the absolute, unwound axis. Anything this
reader does not execute (incremental G91, arcs, other plane or unit codes, unknown M codes, macro
statements) is an error naming the file and line, never a silent skip. Siemens `WORKPIECE(...)` blank
definitions are ignored; Okuma's work offset selection `G15 H<n>` is taken as the job's frame (like G54..G59).

Lathe mode (`read_program(..., lathe=True)`, the blank's lathe program of docs/lathe.md; siemens, fanuc
and linuxcnc): axes X (a DIAMETER) and Z only; diameter mode is required (LinuxCNC G7, Siemens DIAMON;
Fanuc lathes take X as a diameter); feed per revolution (G95, Fanuc system A G99) is required for feed
moves, F is recorded as written (mm/rev); G96 / G97, G18, the spindle limit (Fanuc G50 S, Siemens LIMS= or
G26 S, LinuxCNC's G96 D) are read; a T word changes the tool at once on Siemens and Fanuc (T0101: tool 1,
offset 1), with M6 on LinuxCNC. Moves are recorded with y = 0 and a = 0, x = the X word as written. Fanuc's
G90 (a turning cycle in system A), G50 with axes (coordinate setting), U / W (incremental) are refused.
"""

from __future__ import annotations

import io
import math
import os
import re
from array import array
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spur_cad.dialects import DIALECTS, Dialect, Dialects, lathe_names
from spur_cad.errors import SpurCadError, shown, shown_path

# The largest program read, and what reading it may do. Together they bound a verification to about a minute
# and half a gigabyte whatever the program holds (docs/verification.md, "Limits").
MAX_PROGRAM_BYTES = 64 * 1024 * 1024  # refused at once beyond this, naming the size
MAX_LINE_CHARS = 4096  # controllers take 128-256 characters a block
MAX_LINES = 20_000_000  # lines in the file (blank and comment lines included)
MAX_LINES_READ = 40_000_000  # lines read while executing (loop bodies and subprograms each time they run)
MAX_MOVES = 2_000_000  # moves recorded (about 60 bytes each)
MAX_BLOCKS = 8_000_000  # blocks executed (loops and calls counted)
MAX_CHARACTERS_READ = 100_000_000  # characters read while executing (long blocks of many words cost more)
MAX_SUBPROGRAMS = 100_000  # subprograms, loops and labels defined
MAX_VARIABLES = 10_000  # distinct variables set (LinuxCNC has 5,400 numbered parameters)
MAX_CALL_DEPTH = 8
MAX_REPEAT = 100_000
# A directed move (Okuma M15/M16) to an angle this close to where A is moves 0: far below the finest A word a
# dialect writes (4 decimals, 1e-4 deg; 1e-6 deg is 1.7 nm at 100 mm radius) and far above the rounding of
# an unwound angle (about 1e-13 deg at 10,000 deg), which made such a move a spurious full turn.
DIRECTED_TOLERANCE_DEG = 1e-6
CHECK_EVERY_BLOCKS = 100_000  # how often a long read calls its checkpoint (the CLI stops there on a signal)
LOCAL_VARIABLES = 33  # #1..#33: a call's arguments, restored when it returns

# Fanuc's argument specification I: the letter of a G65 argument -> the local variable it sets.
FANUC_ARGUMENTS = {"A": 1, "B": 2, "C": 3, "I": 4, "J": 5, "K": 6, "D": 7, "E": 8, "F": 9, "H": 11, "M": 13,
                   "Q": 17, "R": 18, "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24, "Y": 25, "Z": 26}
# Codes that set up the machine without moving it; anything else is refused.
# G54..G59 select work offsets: the program's frame is taken as the job's (one offset for all of them).
SETUP_G = {"17", "21", "40", "49", "54", "55", "56", "57", "58", "59", "64", "80", "90", "43", "61"}
QUIET_M = {"0", "1", "3", "4", "5", "7", "8", "9", "10", "11", "2", "30", "6", "68", "69"}
# ProgramMoves columns: rapid, x, y, z, a, feed, inverse_time, line, tool, spindle_rpm (array typecode, dtype)
_COLUMNS = (("b", np.int8), ("d", np.float64), ("d", np.float64), ("d", np.float64), ("d", np.float64),
            ("d", np.float64), ("b", np.int8), ("l", np.int_), ("l", np.int_), ("d", np.float64))


class ProgramReadError(SpurCadError):
    """A program this reader cannot execute: the message names the file, the line and what is wrong."""


@dataclass(frozen=True)
class ProgramMoves:
    """The moves a program commands, in program order (arrays of equal length).

    `line` is the 1-based source line of each move; `tool` the tool number in the spindle (0: none yet).
    """

    source: str
    rapid: np.ndarray  # bool
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    a: np.ndarray  # degrees, unwound
    feed: np.ndarray  # mm/min, or 1/min under inverse time; NaN for rapids
    inverse_time: np.ndarray  # bool
    line: np.ndarray  # int
    tool: np.ndarray  # int
    spindle_rpm: np.ndarray

    def __len__(self) -> int:
        return len(self.x)

    @classmethod
    def from_columns(cls, source: str, columns: list) -> "ProgramMoves":
        """Moves from the columns rapid, x, y, z, a, feed, inverse_time, line, tool, spindle_rpm (sequences; the
        arrays of `move_columns` are taken without copying)."""
        arrays = []
        for column, (code, dtype) in zip(columns, _COLUMNS):
            if isinstance(column, array) and column.typecode == code:
                values = np.frombuffer(column, dtype) if len(column) else np.zeros(0, dtype)
            else:
                values = np.array(column, dtype)
            arrays.append(values)
        return cls(source, arrays[0].astype(bool), *arrays[1:6], arrays[6].astype(bool), *arrays[7:])


def move_columns() -> list:
    """Empty compact columns for moves (Python arrays: about 60 bytes a move)."""
    return [array(code) for code, _ in _COLUMNS]


@dataclass
class _Line:
    number: int  # 1-based line in the file
    text: str  # without comments and block number
    offset: int = 0  # byte offset of the line in the file


Position = tuple[int, int]  # (byte offset of a line's start, number of lines before it)

_ENDS = re.compile(r"(^|\s)M0*(30|2)(\s|$)")  # M30 or M2, anywhere in a block
_UNSIGNED = r"(?:\d+\.?\d*|\.\d+)"
_TERM = re.compile(rf"\s*([-+]?)\s*(#\d+|R\d+|[A-Z_][A-Z0-9_]*|{_UNSIGNED})\s*")
_PLAIN_NUMBER = re.compile(rf"[-+]?{_UNSIGNED}")
_COMMENT = re.compile(r"\([^)]*\)")
_BLOCK_NUMBER = re.compile(r"^N\d+\s*")
_HAAS_LOCAL = re.compile(r"N\d+")
_CANDIDATE = re.compile(rb"[OoMm:]")  # what a line needs to hold to end the program or open a structure
_LINUXCNC_SUB = re.compile(r"O(\d+)\s*SUB")
_LINUXCNC_ENDSUB = re.compile(r"O(\d+)\s*ENDSUB")
_LINUXCNC_REPEAT = re.compile(r"O(\d+)\s*REPEAT\s*\[([^\]]*)\]")
_LINUXCNC_ENDREPEAT = re.compile(r"O(\d+)\s*ENDREPEAT")
_LINUXCNC_CALL = re.compile(r"O(\d+)\s*CALL((?:\s*\[[^\]]*\])*)")
_ASSIGNMENT = re.compile(r"(#\d+)\s*=\s*(.+)")
_LABEL = re.compile(r"[A-Z_][A-Z0-9_]*:")
_SUB_HEAD = re.compile(r"O(\d+)|N(\d+)")
_PROGRAM_NUMBER = re.compile(r"O\d+")
_WORDS = re.compile(r"([A-Z])\s*(\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))")
_WORDS_ASSIGNED = re.compile(r"([A-Z])\s*(=\s*[^\s]+|\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))")
_R_PARAMETER = re.compile(r"R\d+=\S+")
_ORDER = {"T": 0, "S": 0, "G": 1, "F": 2, "M": 3}  # T and S before M, G before F, then the rest in order


@dataclass(frozen=True, slots=True)
class _Syntax:
    """What reading every line needs from the dialect table (spur_cad.dialects), in flat fields."""

    paren: bool  # ( ... ) is a comment
    semicolon: bool  # ; starts a comment to the end of the line
    local_labels: bool  # a line N<n> heads a local subprogram (Haas), not a block number
    structure: str  # "o_words", "labels" or "numbered" (Subprograms.structure)
    closing: re.Pattern  # "numbered": the block closing a subprogram

    @classmethod
    def of(cls, d: Dialect) -> "_Syntax":
        subs = d.subprograms
        return cls("paren" in d.comments.reads, "semicolon" in d.comments.reads, subs.local_labels,
                   subs.structure, re.compile(subs.closing))


def _clean(raw: bytes, syntax: _Syntax) -> str:
    """A line without comments, block number and surrounding blanks; upper case (LinuxCNC's o-words too);
    '' for a line with nothing to execute ('%' delimits Fanuc and Haas programs)."""
    line = raw.decode("utf-8")  # checked while indexing
    if syntax.paren and "(" in line:
        line = _COMMENT.sub("", line)
    if syntax.semicolon:
        line = line.split(";", 1)[0]
    line = line.strip().upper()
    if line[:1] == "N" and (not syntax.local_labels or not _HAAS_LOCAL.fullmatch(line)):  # N<n> heads a local sub
        line = _BLOCK_NUMBER.sub("", line, count=1)
    return "" if line == "%" else line


class _Source:
    """The program's lines read by byte offset from a seekable binary file: nothing but the current line and the
    file's buffer is held, however long the program."""

    def __init__(self, handle):
        self.handle = handle
        self.at = 0

    def line(self, offset: int) -> tuple[bytes, int]:
        """The raw line starting at `offset` and the offset of the next line."""
        if offset != self.at:
            self.handle.seek(offset)
        raw = self.handle.readline()
        self.at = offset + len(raw)
        return raw, self.at


@dataclass
class _Structure:
    """Where the main program ends and where every subprogram, loop and label is (byte offsets and positions)."""

    end: int = -1  # offset just after the main program's last line (its M30 or M2)
    subs: dict = None  # O<n> (and LinuxCNC o<n> sub): n -> (body start Position, offset of the closing line)
    local_subs: dict = None  # Haas N<n> local subprograms (M97), alike
    skips: dict = None  # LinuxCNC: offset of an 'o<n> sub' line -> Position after its 'endsub'
    repeats: dict = None  # LinuxCNC: offset of an 'o<n> repeat' line -> (offset of its 'endrepeat', Position after)
    labels: dict = None  # Siemens: label -> (Position after its line, offset of its line)

    opened: int = 0  # subprograms, loops and labels met (closed or not): bounds what the index holds

    def __post_init__(self):
        self.subs, self.local_subs, self.skips, self.repeats, self.labels = {}, {}, {}, {}, {}


def _index(handle, syntax: _Syntax, source: str) -> _Structure:
    """One pass over the file: check every line (UTF-8, no NUL, length, count) and find the structure; linear in
    the file's length (a line that cannot end or open a structure is not even decoded)."""
    found = _Structure()
    open_subs: list[tuple[int, Position, int]] = []  # LinuxCNC: (number, body start, line offset)
    open_repeats: dict[int, list[int]] = {}  # LinuxCNC: number -> offsets of its open repeats
    fanuc_family = syntax.structure == "numbered"
    o_words, labels = syntax.structure == "o_words", syntax.structure == "labels"
    closing = syntax.closing
    current_sub: tuple[re.Match, Position, int] | None = None  # Fanuc family after the end: the open subprogram
    offset, number = 0, 0
    for raw in iter(lambda: handle.readline(MAX_LINE_CHARS + 3), b""):  # a line read is bounded too
        number += 1
        here, offset = offset, offset + len(raw)
        _check_raw_line(raw, number, source)
        after_end = found.end >= 0
        if not (after_end and fanuc_family) and not _CANDIDATE.search(raw):
            continue
        text = _clean(raw, syntax)
        if not text:
            continue
        line = _Line(number, text, here)
        if not after_end and _ENDS.search(text):
            found.end = offset
            continue
        if o_words:
            _index_o_words(found, line, (offset, number), open_subs, open_repeats)
        elif labels and _LABEL.fullmatch(text):
            found.labels[text[:-1]] = ((offset, number), here)
            found.opened += 1
        elif fanuc_family and after_end:
            current_sub = _index_subprogram(found, line, (offset, number), current_sub, closing, source)
        if found.opened > MAX_SUBPROGRAMS:
            raise _error(source, line, f"more than {MAX_SUBPROGRAMS:,} subprograms, loops and labels")
    if found.end < 0:
        raise ProgramReadError(f"{source}: no end of program (M30 or M2)")
    if current_sub is not None:
        head, _, first = current_sub
        raise ProgramReadError(f"{source}:{first}: nothing closes this subprogram ({closing.pattern}) "
                               f"(in {shown(head.group(0))})")
    if open_subs:
        sub_number, _, _ = open_subs[-1]
        raise ProgramReadError(f"{source}: nothing closes subprogram o{sub_number} (o{sub_number} endsub)")
    return found


def _check_raw_line(raw: bytes, number: int, source: str) -> None:
    """A line of a text program: bounded length and count, UTF-8, no NUL byte."""
    if len(raw) > MAX_LINE_CHARS + 2:
        raise ProgramReadError(f"{source}:{number}: a line of more than {MAX_LINE_CHARS:,} characters; a "
                               "controller's block is a few hundred at most")
    if number > MAX_LINES:
        raise ProgramReadError(f"{source}: more than {MAX_LINES:,} lines; verify reads at most {MAX_LINES:,}")
    if not raw.isascii():
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ProgramReadError(f"{source}:{number}: not a text file (byte {exc.start + 1} of the line is "
                                   "not UTF-8)") from None
    if b"\x00" in raw:
        raise ProgramReadError(f"{source}:{number}: not a text file (a NUL byte)")


def _index_subprogram(found: _Structure, line: _Line, after: Position, current_sub, closing: re.Pattern,
                      source: str):
    """Fanuc family after the end of the program: subprograms O<n> (Haas N<n>) ... M99 (Okuma RTS) and nothing
    else; returns the subprogram still open (its head, body start, line number) or None."""
    if current_sub is None:
        head = _SUB_HEAD.fullmatch(line.text)
        if head is None:
            raise _error(source, line, "a block after the end of the program that is not a subprogram")
        found.opened += 1
        return (head, after, line.number)
    if closing.fullmatch(line.text):
        head, start, _ = current_sub
        target = found.subs if head.group(1) else found.local_subs
        target[int(head.group(1) or head.group(2))] = (start, line.offset)
        return None
    return current_sub


def _index_o_words(found: _Structure, line: _Line, after: Position, open_subs: list, open_repeats: dict) -> None:
    """LinuxCNC o-word structure, paired with stacks (each opening is closed by the nearest closing of its number)."""
    text = line.text
    if text[:1] != "O":
        return
    if (head := _LINUXCNC_SUB.fullmatch(text)) is not None:
        open_subs.append((int(head.group(1)), after, line.offset))
        found.opened += 1
    elif (head := _LINUXCNC_ENDSUB.fullmatch(text)) is not None:
        sub_number = int(head.group(1))
        for i in range(len(open_subs) - 1, -1, -1):
            if open_subs[i][0] == sub_number:
                _, start, opening = open_subs.pop(i)
                found.subs[sub_number] = (start, line.offset)
                found.skips[opening] = after
                break
    elif (head := _LINUXCNC_REPEAT.fullmatch(text)) is not None:
        open_repeats.setdefault(int(head.group(1)), []).append(line.offset)
        found.opened += 1
    elif (head := _LINUXCNC_ENDREPEAT.fullmatch(text)) is not None and open_repeats.get(int(head.group(1))):
        found.repeats[open_repeats[int(head.group(1))].pop()] = (line.offset, after)


def _error(source: str, line: _Line, message: str) -> ProgramReadError:
    return ProgramReadError(f"{source}:{line.number}: {message} (in {shown(line.text)})")


class _Reader:
    """Executes one program: machine state, variables, subprogram calls, recorded moves."""

    def __init__(self, handle, d: Dialect, source: str, checkpoint=None, lathe: bool = False):
        self.d, self.source, self.checkpoint, self.lathe = d, source, checkpoint, lathe
        self.syntax, self.subprograms = _Syntax.of(d), d.subprograms
        self.lathe_words = d.lathe if lathe else None  # checked to be there (_dialect)
        self.lathe_keywords = self.lathe_words is not None and self.lathe_words.keywords
        self.spindle_limit_code = self.lathe_words.spindle_limit_code if self.lathe_words is not None else None
        self.offset_code = None if lathe else d.work_offsets.numbered_code  # G15 (H<n>) on Okuma
        # The rotary direction codes without M and leading zeros -> True for the positive one (Okuma M15, M16).
        self.directions = {code[1:].lstrip("0") or "0": index == 0
                           for index, code in enumerate(d.rotary.direction_codes or ())}
        self.axes = "XZ" if lathe else "XYZA"
        # lathe X as a diameter: from the start where no word sets it (Fanuc), else G7 (LinuxCNC), DIAMON (Siemens)
        self.diameter = self.lathe_words is not None and self.lathe_words.diameter_word is None
        self.per_rev = False  # lathe feed per revolution: G95 (G99 on Fanuc)
        self.block_codes: set[str] = set()  # G codes of the block whose words are checked together
        self.blocks = 0
        self.lines_read = 0
        self.characters_read = 0
        self.handle = handle
        self.lines = _Source(handle)
        self.structure = _Structure()
        self.variables: dict[str, float] = {}
        self.pose = [math.nan, 0.0, math.nan, 0.0] if lathe else [math.nan, math.nan, math.nan, math.nan]
        self.motion: str | None = None
        self.inverse = False
        self.feed = math.nan
        self.tool = 0
        self.pending_tool = 0
        self.spindle = 0.0
        self.feed_in_block = False
        self.columns = move_columns()
        self.ended = False
        self.words_pattern = _WORDS_ASSIGNED if d.assigned_words else _WORDS

    def error(self, line: _Line, message: str) -> ProgramReadError:
        return _error(self.source, line, message)

    # --- values -----------------------------------------------------------------------------
    def _set(self, name: str, value: float, line: _Line) -> None:
        """A variable set, at most MAX_VARIABLES of them."""
        if name not in self.variables and len(self.variables) >= MAX_VARIABLES:
            raise self.error(line, f"more than {MAX_VARIABLES:,} variables set")
        self.variables[name] = value

    def value(self, text: str, line: _Line) -> float:
        """A number, a variable, or a sum of them: '12.5', '#2', '[#2+2.5]', 'R2+2.5', 'ASP-23.9'."""
        if _PLAIN_NUMBER.fullmatch(text):
            total = float(text)
        else:
            total = self._sum(text.strip(), line)
        if not math.isfinite(total) or abs(total) > 1e6:
            raise self.error(line, f"value {shown(text)} = {total:g} is not a finite coordinate")
        return total

    def _sum(self, text: str, line: _Line) -> float:
        if text.startswith("[") and text.endswith("]"):
            text = text[1:-1]
        total, position = 0.0, 0
        while position < len(text):
            found = _TERM.match(text, position)
            if found is None or found.end() == position:
                raise self.error(line, f"cannot evaluate {shown(text)}")
            sign, term = found.groups()
            if position > 0 and not sign:
                raise self.error(line, f"cannot evaluate {shown(text)}: terms need + or - between them")
            if term[0].isdigit() or term[0] == ".":
                number = float(term)
            elif term not in self.variables:
                raise self.error(line, f"variable {_digits(term)} is used before it is set")
            else:
                number = self.variables[term]
            total += -number if sign == "-" else number
            position = found.end()
        return total

    # --- execution ------------------------------------------------------------------------------
    def run(self) -> ProgramMoves:
        self.structure = _index(self.handle, self.syntax, self.source)
        self.handle.seek(0)
        self.execute((0, 0), self.structure.end, 0)
        if not self.ended:
            raise ProgramReadError(f"{self.source}: the program never reaches its end (M30 or M2)")
        columns, self.columns = self.columns, move_columns()
        return ProgramMoves.from_columns(self.source, columns)

    def execute(self, start: Position, stop: int, depth: int) -> None:
        """Run the lines from `start` up to (not including) the line at offset `stop`."""
        offset, number = start
        lines, syntax = self.lines, self.syntax
        while offset < stop and not self.ended:
            raw, after = lines.line(offset)
            if not raw:
                break
            here, offset, number = offset, after, number + 1
            self.lines_read += 1
            self.characters_read += len(raw)
            if self.lines_read % CHECK_EVERY_BLOCKS == 0:
                self._limits(number)
            text = _clean(raw, syntax)
            if not text:
                continue
            self.blocks += 1
            line = _Line(number, text, here)
            if not text.isascii():  # e.g. a digit of another script, which Python would read as a number
                raise self.error(line, "a character outside a comment that is not ASCII (a controller reads none)")
            jump = self.control(line, (offset, number), depth) if _may_be_control(text, syntax.structure) else None
            if jump is not None:
                offset, number = jump
                continue
            self.block(line)

    def _limits(self, number: int) -> None:
        """The reading limits (checked every CHECK_EVERY_BLOCKS lines read) and the caller's checkpoint."""
        if self.blocks > MAX_BLOCKS:
            raise ProgramReadError(f"{self.source}:{number}: the program executes more than {MAX_BLOCKS:,} blocks "
                                   "(loops and calls counted); refused before reading further")
        for what, count, limit in (("lines", self.lines_read, MAX_LINES_READ),
                                   ("characters", self.characters_read, MAX_CHARACTERS_READ)):
            if count > limit:
                raise ProgramReadError(f"{self.source}:{number}: the program reads more than {limit:,} {what} (loops "
                                       "and calls counted); refused before reading further")
        if self.checkpoint is not None:
            self.checkpoint()

    def _repeat(self, count: int, body: Callable[[], None], line: _Line) -> None:
        """`body` run `count` times; after the first run the rest is estimated, and refused at once when it would
        pass the limits on blocks, lines or moves (three nested loops of 99,999 are refused in a second)."""
        if count <= 0:
            return
        before = self._work_done()
        body()
        if count == 1:
            return
        after = self._work_done()
        for (what, verb, limit), first, now in zip(((("blocks", "executes", MAX_BLOCKS),
                                                     ("lines", "reads", MAX_LINES_READ),
                                                     ("characters", "reads", MAX_CHARACTERS_READ),
                                                     ("moves", "makes", MAX_MOVES))), before, after):
            estimate = now + (count - 1) * (now - first)
            if estimate > limit:
                raise self.error(line, f"the program {verb} more than {limit:,} {what} (this loop: {count:,} times "
                                       f"{now - first:,} {what}, about {estimate:,}); refused before reading further")
        for _ in range(count - 1):
            body()

    def _work_done(self) -> tuple[int, int, int, int]:
        return self.blocks, self.lines_read, self.characters_read, len(self.columns[0])

    def control(self, line: _Line, after: Position, depth: int) -> Position | None:
        """Subprogram definitions, calls, repeats and labels; the position to go on at, or None for a block."""
        structure = self.syntax.structure
        if structure == "o_words":
            return self._o_word_control(line, after, depth)
        if structure == "labels":
            return self._label_control(line, after, depth)
        return self._numbered_control(line, after, depth)

    def _label_control(self, line: _Line, after: Position, depth: int) -> Position | None:
        text = line.text
        if _LABEL.fullmatch(text) or re.fullmatch(r'WORKPIECE\([^()]*\)', text):
            return after  # a label, or the blank for the control's simulation (ignored)
        found = re.fullmatch(r"REPEAT\s+([A-Z_][A-Z0-9_]*)\s+([A-Z_][A-Z0-9_]*)(?:\s*P\s*=\s*(\d+))?", text)
        if found:
            first, last = (self.structure.labels.get(found.group(k)) for k in (1, 2))
            if first is None or last is None or last[1] <= first[1]:
                raise self.error(line, "REPEAT names labels that do not enclose a section")
            if depth + 1 > MAX_CALL_DEPTH:
                raise self.error(line, f"loops and calls nested deeper than {MAX_CALL_DEPTH}")
            self._repeat(self._count(found.group(3), line), lambda: self.execute(first[0], last[1], depth + 1), line)
            return after
        if all(_R_PARAMETER.fullmatch(token) for token in text.split()):  # (no nested quantifier: linear time)
            for name, value in re.findall(r"(R\d+)=(\S+)", text):
                self._set(name, self.value(value, line), line)
            return after
        return None

    def _count(self, text: str | None, line: _Line) -> int:
        count = int(text) if text and len(text) <= 12 else 1 if not text else MAX_REPEAT + 1
        if not 0 <= count <= MAX_REPEAT:
            raise self.error(line, f"repeat count {_digits(text)} outside 0..{MAX_REPEAT}")
        return count

    def _call(self, number: str, line: _Line, depth: int, count: int = 1, local: bool = False,
              arguments: dict[str, float] | None = None) -> None:
        """Run subprogram `number` `count` times; `arguments` set local variables (#1...), restored after it
        returns (LinuxCNC o-call and Fanuc G65 make them local to the call)."""
        table = self.structure.local_subs if local else self.structure.subs
        if len(number) > 12 or int(number) not in table:
            raise self.error(line, f"calls subprogram {_digits(number)}, which the program does not define")
        if depth + 1 > MAX_CALL_DEPTH:
            raise self.error(line, f"subprogram calls nested deeper than {MAX_CALL_DEPTH}")
        saved = None
        if arguments is not None:
            saved = {f"#{n}": self.variables.get(f"#{n}") for n in range(1, LOCAL_VARIABLES + 1)}
            self.variables.update(arguments)
        start, stop = table[int(number)]
        self._repeat(count, lambda: self.execute(start, stop, depth + 1), line)
        if saved is not None:
            for name, value in saved.items():
                if value is None:
                    self.variables.pop(name, None)
                else:
                    self.variables[name] = value

    def _o_word_control(self, line: _Line, after: Position, depth: int) -> Position | None:
        text = line.text
        if text[0] == "#":
            found = _ASSIGNMENT.fullmatch(text)
            if found:
                self._set(found.group(1), self.value(found.group(2), line), line)
                return after
            return None
        if _LINUXCNC_SUB.fullmatch(text):
            skip = self.structure.skips.get(line.offset)
            if skip is None:
                raise self.error(line, "nothing closes this subprogram (o<n> endsub)")
            return skip  # a definition: skipped in the flow
        found = _LINUXCNC_CALL.fullmatch(text)
        if found:
            arguments = {f"#{index}": self.value(argument, line)
                         for index, argument in enumerate(re.findall(r"\[([^\]]*)\]", found.group(2)), start=1)}
            self._call(found.group(1), line, depth, arguments=arguments)
            return after
        found = _LINUXCNC_REPEAT.fullmatch(text)
        if found:
            closing = self.structure.repeats.get(line.offset)
            if closing is None:
                raise self.error(line, "nothing closes this loop (o<n> endrepeat)")
            if depth + 1 > MAX_CALL_DEPTH:
                raise self.error(line, f"loops and calls nested deeper than {MAX_CALL_DEPTH}")
            count = self._count(str(int(self.value(found.group(2), line))), line)
            self._repeat(count, lambda: self.execute(after, closing[0], depth + 1), line)
            return closing[1]
        return None

    def _numbered_control(self, line: _Line, after: Position, depth: int) -> Position | None:
        text = line.text
        if _PROGRAM_NUMBER.fullmatch(text):
            return after  # the program's own number (its title was a comment)
        found = _ASSIGNMENT.fullmatch(text)
        if found:
            self._set(found.group(1), self.value(found.group(2), line), line)
            return after
        if self.subprograms.named_calls:
            found = re.fullmatch(r"CALL\s*O(\d+)((?:\s+[A-Z][A-Z0-9]*\s*=\s*\S+)*)", text)
            if found:
                for name, value in re.findall(r"([A-Z][A-Z0-9]*)\s*=\s*(\S+)", found.group(2)):
                    self._set(name, self.value(value, line), line)
                self._call(found.group(1), line, depth)
                return after
            return None
        found = re.fullmatch(r"G0*65\s*P\s*(\d+)((?:\s*[A-Z]\s*[^\sA-Z]+)*)", text)
        if found:
            arguments, count = {}, 1
            for letter, value in re.findall(r"([A-Z])\s*([^\sA-Z]+)", found.group(2)):
                if letter == "L":
                    count = self._count(str(int(self.value(value, line))), line)
                elif letter not in FANUC_ARGUMENTS:
                    raise self.error(line, f"G65 argument {letter} has no local variable")
                else:
                    arguments[f"#{FANUC_ARGUMENTS[letter]}"] = self.value(value, line)
            self._call(found.group(1), line, depth, count, arguments=arguments)
            return after
        found = re.fullmatch(r"M0*9([78])\s*P\s*(\d+)(?:\s*L\s*(\d+))?", text)
        if found:
            if found.group(1) == "7" and not self.subprograms.local_labels:
                raise self.error(line, "M97 (local subprogram) is a Haas code")
            self._call(found.group(2), line, depth, self._count(found.group(3), line), local=found.group(1) == "7")
            return after
        return None


    # --- one block --------------------------------------------------------------------------------
    def block(self, line: _Line) -> None:
        if self.lathe_keywords:
            line = self._lathe_keywords(line)
        words = self.words(line)
        if len(words) > 1:
            words.sort(key=_word_order)  # T and S before M (M6 loads the tool the block names), G before F
        target = list(self.pose)
        direction = None
        self.feed_in_block = False
        self.block_codes = set()
        moves = False
        for letter, value in words:
            if letter == "M":
                direction = self._m_code(value, line) or direction
            else:
                if letter in "XYZA":
                    moves = True
                self._word(letter, value, line, target)
        if self.block_codes:
            self._check_block_codes(words, line)
        if direction is not None and any(letter == "A" for letter, _ in words):  # M15/M16 turn this block's A
            target[3] = _directed(self.pose[3], target[3], direction, self, line)
        if moves:
            self._move(target, line)

    def _word(self, letter: str, value: str, line: _Line, target: list[float]) -> None:
        """One word other than M: G codes, axes, F, T, S; offsets and tolerances are skipped."""
        if letter == "G":
            self._g_code(value, line)
        elif letter in self.axes:
            target["XYZA".index(letter)] = self.value(value, line)
        elif letter == "F":
            self.feed = self.value(value, line)
            self.feed_in_block = True
        elif letter == "T":
            self._t_word(value, line)
        elif letter == "S":
            self.spindle = self.value(value, line)
        elif letter in self.d.ignored_words:
            return  # tool offset numbers, G64 P tolerance, G96 D spindle limit, G15 H work offset (Siemens: N)
        elif self.lathe and letter in "YAUW":
            raise self.error(line, f"word {letter}{value}: a lathe program moves X and Z only (absolute, no U/W)")
        else:
            raise self.error(line, f"word {letter}{value} is not supported by this reader")

    def _t_word(self, value: str, line: _Line) -> None:
        """T: the tool M6 loads; on a lathe with a turret (Siemens, Fanuc) it indexes at once (Fanuc T0101: tool 1,
        offset 1)."""
        words = self.lathe_words
        if words is None or not words.turret:
            self.pending_tool = int(self.value(value, line))
            return
        if words.tool_offset_t:
            if not re.fullmatch(r"\d{3,4}", value):
                raise self.error(line, f"T{value}: a {self.d.title} lathe T word gives the tool and its offset "
                                       "(T0101)")
            self.tool = self.pending_tool = int(value) // 100
        else:
            self.tool = self.pending_tool = int(self.value(value, line))

    def _lathe_keywords(self, line: _Line) -> _Line:
        """Siemens lathe words that are not address + number: LIMS=<rpm> (spindle limit under G96), DIAMON /
        DIAM90 (X as diameter) and DIAMOF (X as radius); the rest of the block is returned."""
        text = line.text
        for value in re.findall(r"\bLIMS\s*=\s*(\S+)", text):
            self.value(value, line)  # a number (or parameter) it must be
        for mode in re.findall(r"\bDIAM(ON|OF|90)\b", text):
            self.diameter = mode != "OF"
        text = re.sub(r"\bLIMS\s*=\s*\S+|\bDIAM(?:ON|OF|90)\b", " ", text)
        return _Line(line.number, text.strip())

    def _check_block_codes(self, words: list[tuple[str, str]], line: _Line) -> None:
        """G codes read only with certain words: Fanuc G50 S and Siemens G26 S (spindle limits; with axes they
        would set a coordinate system or a working area), Okuma G15 H<n> (work offset n >= 1)."""
        letters = {letter for letter, _ in words}
        for code in self.block_codes:
            if code == self.spindle_limit_code and (letters & set("XZUWY") or "S" not in letters):
                raise self.error(line, f"G{code} is read only as the spindle speed limit G{code} S<rpm> "
                                       "(with axes it sets a coordinate system or a working area)")
            if code == self.offset_code:
                numbers = [value for letter, value in words if letter == "H"]
                if len(numbers) != 1 or not re.fullmatch(r"\d+", numbers[0]) or int(numbers[0]) < 1 \
                        or letters & set("XYZA"):
                    raise self.error(line, f"G{code} is read only as {self.d.title}'s work offset selection "
                                           f"G{code} H<n> (n = 1, 2, ...) in a block of its own")

    def words(self, line: _Line) -> list[tuple[str, str]]:
        text = line.text
        found = self.words_pattern.findall(text)
        if self.words_pattern.sub("", text).strip():
            raise self.error(line, "cannot read this block")
        if self.words_pattern is _WORDS:
            return found
        return [(letter, value.lstrip("=").strip()) for letter, value in found]

    def _g_code(self, value: str, line: _Line) -> None:
        code = value.lstrip("0") or "0"
        if code in ("0", "1"):
            self.motion = code
        elif self.lathe and self._lathe_g_code(code, line):
            return
        elif code == self.offset_code:
            self.block_codes.add(code)  # G15 H<n>: Okuma's work offset n
        elif code in ("93", "94"):
            if self.inverse != (code == "93"):
                self.feed = math.nan  # a feed mode change leaves no F in effect (LinuxCNC, Fanuc)
            self.inverse = code == "93"
        elif code in ("2", "3"):
            raise self.error(line, f"G{value} (an arc) is not read: spur-cad verify reads the rotary-table programs "
                                   "(G0/G1); a 3-axis program with arcs is checked by LinuxCNC's rs274 (docs/cam.md)")
        elif code not in SETUP_G and code not in self.d.extra_setup_g:  # e.g. G71: metric on the 840D
            raise self.error(line, f"G{value} is not supported by this reader (it reads G0/G1 moves, G90, G93/G94)")

    def _lathe_g_code(self, code: str, line: _Line) -> bool:
        """Lathe G codes; False for the codes milling and turning share (G21, G40, G54...)."""
        words = self.lathe_words
        per_rev, per_minute = words.feed_codes
        if code in (per_rev, per_minute):
            if self.per_rev != (code == per_rev):
                self.feed = math.nan  # a new feed mode needs a new F
            self.per_rev = code == per_rev
        elif code in ("96", "97", "18"):
            pass  # constant cutting speed (S in m/min) or rpm, the ZX plane
        elif words.diameter_codes is not None and code in words.diameter_codes:
            self.diameter = code == words.diameter_codes[0]
        elif code == self.spindle_limit_code:
            self.block_codes.add(code)
        elif code == "93" or code in words.cycle_codes:
            raise self.error(line, f"G{code} is not read in a lathe program (Fanuc's G90 and G94 are turning "
                                   "cycles in system A, G93 is inverse time)")
        else:
            return False
        return True

    def _m_code(self, value: str, line: _Line) -> str | None:
        code = value.lstrip("0") or "0"
        if code in ("30", "2"):
            self.ended = True
        elif code == "6":
            self.tool = self.pending_tool
        elif code in self.directions:
            return code  # Okuma's rotary direction (other controls use M15/M16 for other things)
        elif code not in QUIET_M:
            raise self.error(line, f"M{value} is not supported by this reader")
        return None

    def _move(self, target: list[float], line: _Line) -> None:
        if self.motion is None:
            raise self.error(line, "an axis word before any G0 or G1")
        if self.lathe:
            self._check_lathe_move(line)
        rapid = self.motion == "0"
        if math.isnan(target[0] + target[1] + target[2] + target[3]):
            if rapid:  # e.g. a restart's Z-only move to the clearance height: known from here on, not a move
                self.pose = target
                return
            missing = "".join(axis for axis, t in zip("XYZA", target) if math.isnan(t))
            hint = "; a 3-axis program (no A)? spur-cad verify reads rotary-table programs" if missing == "A" else ""
            raise self.error(line, f"a feed move before every axis is known ({missing} unknown{hint})")
        if not rapid and not (math.isfinite(self.feed) and self.feed > 0.0):
            raise self.error(line, "a feed move without a positive F")
        if not rapid and self.inverse and not self.feed_in_block:
            raise self.error(line, "an inverse-time (G93) feed move needs its own F")
        if len(self.columns[0]) >= MAX_MOVES:
            raise self.error(line, f"the program has more than {MAX_MOVES:,} moves; split it")
        columns = self.columns
        columns[0].append(rapid)
        columns[1].append(target[0])
        columns[2].append(target[1])
        columns[3].append(target[2])
        columns[4].append(target[3])
        columns[5].append(math.nan if rapid else self.feed)
        columns[6].append(self.inverse and not rapid)
        columns[7].append(line.number)
        columns[8].append(self.tool)
        columns[9].append(self.spindle)
        self.pose = target


    def _check_lathe_move(self, line: _Line) -> None:
        if not self.diameter:
            raise self.error(line, "X is a radius here; this reader reads lathe programs in diameter mode "
                                   + f"({self.lathe_words.diameter_word})")
        if self.motion == "1" and not self.per_rev:
            raise self.error(line, "a lathe feed move without feed per revolution ("
                                   + f"G{self.lathe_words.feed_codes[0]})")



def _directed(current: float, target: float, direction: str, reader: _Reader, line: _Line) -> float:
    """The unwound A reached from `current` turning positively (M15) or negatively (M16) to the angle `target`
    in [0, 360] (360 is 0, as legacy Okuma programs write it); `direction` is the code without M (a key of
    reader.directions). A target within DIRECTED_TOLERANCE_DEG of where A is moves 0, not a full turn."""
    if not 0.0 <= target <= 360.0:
        raise reader.error(line, f"with M{direction}, A must be an angle in [0, 360], got {target:g}")
    target %= 360.0
    if math.isnan(current):
        return target
    step = (target - current) % 360.0  # in [0, 360]: rounding of an unwound `current` may give 359.99999999999994
    if min(step, 360.0 - step) <= DIRECTED_TOLERANCE_DEG:
        return current
    reached = current + step if reader.directions[direction] else current - (360.0 - step)
    return target + 360.0 * round((reached - target) / 360.0)  # the angle as written plus whole turns: no drift


def _digits(text: str) -> str:
    """A number or a name from a program (digits, letters, '#', '_'), as a message shows it (cut when long)."""
    return text if len(text) <= 24 else shown(text)


def _word_order(word: tuple[str, str]) -> int:
    return _ORDER.get(word[0], 4)


def _may_be_control(text: str, structure: str) -> bool:
    """False for a block that no control statement of the structure can be (most blocks: moves)."""
    if structure == "labels":  # labels, R<n>= parameters, REPEAT, WORKPIECE
        return ":" in text or "=" in text or text[0] in "RW"
    if structure == "o_words":
        return text[0] in "O#"
    return text[0] in "O#C" or "P" in text  # numbered: O, #n =, CALL (Okuma), G65 P, M98 P, M97 P


def _dialect(dialect: str | Dialect, lathe: bool, dialects: Dialects) -> Dialect:
    """The dialect called `dialect` in the registry `dialects` (a Dialect is taken as it is: a controller in no
    registry); in lathe mode one with lathe words."""
    if isinstance(dialect, Dialect):
        found = dialect
    elif not isinstance(dialect, str) or dialect not in dialects:
        raise ProgramReadError(f"unknown dialect {shown(dialect)} (known: {', '.join(dialects)})")
    else:
        found = dialects[dialect]
    if lathe and found.lathe is None:
        raise ProgramReadError(f"no lathe dialect {shown(found.name)} (known: {', '.join(lathe_names(dialects))})")
    return found


def read_program(text: str, dialect: str | Dialect, source: str = "program", checkpoint=None,
                 lathe: bool = False, dialects: Dialects = DIALECTS) -> ProgramMoves:
    """The moves of a program's text in `dialect` (a name in the registry `dialects`, or a Dialect of
    spur_cad.dialects: a controller in no registry); raises ProgramReadError naming `source`'s line.
    `checkpoint()` is called every CHECK_EVERY_BLOCKS lines read (the CLI stops there when a signal arrived).
    `lathe`: a lathe program (a dialect with lathe words; the module docstring says what is read): x is the
    diameter as written, y = a = 0, feed in mm/rev as written. Lines end with LF (or CR LF)."""
    d = _dialect(dialect, lathe, dialects)
    data = text.encode("utf-8", "surrogatepass")
    if len(data) > MAX_PROGRAM_BYTES:
        raise ProgramReadError(f"{source}: the program has {len(data):,} bytes; verify reads at most "
                               f"{MAX_PROGRAM_BYTES:,} ({MAX_PROGRAM_BYTES // 2**20} MiB)")
    return _Reader(io.BytesIO(data), d, source, checkpoint, lathe).run()


def open_program_file(path: str | os.PathLike, source: str | None = None):
    """A program file opened for reading: a regular file of at most MAX_PROGRAM_BYTES (a FIFO, a device or a
    larger file is refused with one line, before reading)."""
    from spur_cad.inputs import open_regular_file

    source = source if source is not None else shown_path(path)
    handle = open_regular_file(path, "program", ProgramReadError)
    size = os.fstat(handle.fileno()).st_size
    if size > MAX_PROGRAM_BYTES:
        handle.close()
        raise ProgramReadError(f"{source}: the program has {size:,} bytes; verify reads at most "
                               f"{MAX_PROGRAM_BYTES:,} ({MAX_PROGRAM_BYTES // 2**20} MiB)")
    return handle


def read_program_file(path: str | os.PathLike, dialect: str | Dialect, source: str | None = None, checkpoint=None,
                      lathe: bool = False, dialects: Dialects = DIALECTS) -> ProgramMoves:
    """`read_program` of a file, read as a stream: a regular file of at most MAX_PROGRAM_BYTES (a FIFO, a device
    or a larger file is refused before reading); memory holds a line at a time besides the moves."""
    d = _dialect(dialect, lathe, dialects)
    source = source if source is not None else shown_path(path)
    with open_program_file(path, source) as handle:
        return _Reader(handle, d, source, checkpoint, lathe).run()
