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
from collections.abc import Callable
from typing import BinaryIO

from spur_cad.dialects import DIALECTS, Dialect, Dialects, lathe_names
from spur_cad.errors import shown, shown_path
from spur_cad.verify.controller import Controller, ProgramMoves, move_columns
from spur_cad.verify.limits import (
    CHECK_EVERY_BLOCKS,
    DIRECTED_TOLERANCE_DEG,
    LOCAL_VARIABLES,
    MAX_BLOCKS,
    MAX_CALL_DEPTH,
    MAX_CHARACTERS_READ,
    MAX_LINE_CHARS,
    MAX_LINES,
    MAX_LINES_READ,
    MAX_MOVES,
    MAX_PROGRAM_BYTES,
    MAX_REPEAT,
    MAX_SUBPROGRAMS,
    MAX_VARIABLES,
)
from spur_cad.verify.program_text import (
    LABEL,
    LINUXCNC_REPEAT,
    LINUXCNC_SUB,
    Line,
    LineSource,
    Position,
    ProgramReadError,
    Structure,
    Syntax,
    clean_line,
    index_program,
    line_error,
)

__all__ = ["CHECK_EVERY_BLOCKS", "DIALECTS", "DIRECTED_TOLERANCE_DEG", "MAX_BLOCKS", "MAX_CALL_DEPTH",
           "MAX_CHARACTERS_READ", "MAX_LINE_CHARS", "MAX_LINES", "MAX_LINES_READ", "MAX_MOVES", "MAX_PROGRAM_BYTES",
           "MAX_REPEAT", "MAX_SUBPROGRAMS", "MAX_VARIABLES", "ProgramMoves", "ProgramReadError", "move_columns",
           "open_program_file", "read_program", "read_program_file"]

# Fanuc's argument specification I: the letter of a G65 argument -> the local variable it sets.
FANUC_ARGUMENTS = {"A": 1, "B": 2, "C": 3, "I": 4, "J": 5, "K": 6, "D": 7, "E": 8, "F": 9, "H": 11, "M": 13,
                   "Q": 17, "R": 18, "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24, "Y": 25, "Z": 26}
_UNSIGNED = r"(?:\d+\.?\d*|\.\d+)"
_TERM = re.compile(rf"\s*([-+]?)\s*(#\d+|R\d+|[A-Z_][A-Z0-9_]*|{_UNSIGNED})\s*")
_PLAIN_NUMBER = re.compile(rf"[-+]?{_UNSIGNED}")
_LINUXCNC_CALL = re.compile(r"O(\d+)\s*CALL((?:\s*\[[^\]]*\])*)")
_ASSIGNMENT = re.compile(r"(#\d+)\s*=\s*(.+)")
_PROGRAM_NUMBER = re.compile(r"O\d+")
_R_PARAMETER = re.compile(r"R\d+=\S+")


class _Reader:
    """Executes one program's flow: variables, subprogram calls, loops and labels; every other block goes to the
    controller (spur_cad.verify.controller), which keeps the machine state and records the moves."""

    def __init__(self, handle: BinaryIO, d: Dialect, source: str, checkpoint: Callable[[], None] | None = None,
                 lathe: bool = False) -> None:
        self.d, self.source, self.checkpoint = d, source, checkpoint
        self.syntax, self.subprograms = Syntax.of(d), d.subprograms
        self.blocks = 0
        self.lines_read = 0
        self.characters_read = 0
        self.handle = handle
        self.lines = LineSource(handle)
        self.structure = Structure()
        self.variables: dict[str, float] = {}
        self.controller = Controller(d, source, self.value, lathe)

    def error(self, line: Line, message: str) -> ProgramReadError:
        return line_error(self.source, line, message)

    # --- values -----------------------------------------------------------------------------
    def _set(self, name: str, value: float, line: Line) -> None:
        """A variable set, at most MAX_VARIABLES of them."""
        if name not in self.variables and len(self.variables) >= MAX_VARIABLES:
            raise self.error(line, f"more than {MAX_VARIABLES:,} variables set")
        self.variables[name] = value

    def value(self, text: str, line: Line) -> float:
        """A number, a variable, or a sum of them: '12.5', '#2', '[#2+2.5]', 'R2+2.5', 'ASP-23.9'."""
        if _PLAIN_NUMBER.fullmatch(text):
            total = float(text)
        else:
            total = self._sum(text.strip(), line)
        if not math.isfinite(total) or abs(total) > 1e6:
            raise self.error(line, f"value {shown(text)} = {total:g} is not a finite coordinate")
        return total

    def _sum(self, text: str, line: Line) -> float:
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
        self.structure = index_program(self.handle, self.syntax, self.source)
        self.handle.seek(0)
        self.execute((0, 0), self.structure.end, 0)
        if not self.controller.ended:
            raise ProgramReadError(f"{self.source}: the program never reaches its end (M30 or M2)")
        return self.controller.moves()

    def execute(self, start: Position, stop: int, depth: int) -> None:
        """Run the lines from `start` up to (not including) the line at offset `stop`."""
        offset, number = start
        lines, syntax = self.lines, self.syntax
        while offset < stop and not self.controller.ended:
            raw, after = lines.line(offset)
            if not raw:
                break
            here, offset, number = offset, after, number + 1
            self.lines_read += 1
            self.characters_read += len(raw)
            if self.lines_read % CHECK_EVERY_BLOCKS == 0:
                self._limits(number)
            text = clean_line(raw, syntax)
            if not text:
                continue
            self.blocks += 1
            line = Line(number, text, here)
            if not text.isascii():  # e.g. a digit of another script, which Python would read as a number
                raise self.error(line, "a character outside a comment that is not ASCII (a controller reads none)")
            jump = self.control(line, (offset, number), depth) if _may_be_control(text, syntax.structure) else None
            if jump is not None:
                offset, number = jump
                continue
            self.controller.block(line)

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

    def _repeat(self, count: int, body: Callable[[], None], line: Line) -> None:
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
        return self.blocks, self.lines_read, self.characters_read, len(self.controller.columns[0])

    def control(self, line: Line, after: Position, depth: int) -> Position | None:
        """Subprogram definitions, calls, repeats and labels; the position to go on at, or None for a block."""
        structure = self.syntax.structure
        if structure == "o_words":
            return self._o_word_control(line, after, depth)
        if structure == "labels":
            return self._label_control(line, after, depth)
        return self._numbered_control(line, after, depth)

    def _label_control(self, line: Line, after: Position, depth: int) -> Position | None:
        text = line.text
        if LABEL.fullmatch(text) or re.fullmatch(r'WORKPIECE\([^()]*\)', text):
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

    def _count(self, text: str | None, line: Line) -> int:
        count = int(text) if text and len(text) <= 12 else 1 if not text else MAX_REPEAT + 1
        if not 0 <= count <= MAX_REPEAT:
            raise self.error(line, f"repeat count {_digits(text or '')} outside 0..{MAX_REPEAT}")  # text given
        return count

    def _call(self, number: str, line: Line, depth: int, count: int = 1, local: bool = False,
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

    def _o_word_control(self, line: Line, after: Position, depth: int) -> Position | None:
        text = line.text
        if text[0] == "#":
            found = _ASSIGNMENT.fullmatch(text)
            if found:
                self._set(found.group(1), self.value(found.group(2), line), line)
                return after
            return None
        if LINUXCNC_SUB.fullmatch(text):
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
        found = LINUXCNC_REPEAT.fullmatch(text)
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

    def _numbered_control(self, line: Line, after: Position, depth: int) -> Position | None:
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


def _digits(text: str) -> str:
    """A number or a name from a program (digits, letters, '#', '_'), as a message shows it (cut when long)."""
    return text if len(text) <= 24 else shown(text)


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


def read_program(text: str, dialect: str | Dialect, source: str = "program",
                 checkpoint: Callable[[], None] | None = None, lathe: bool = False,
                 dialects: Dialects = DIALECTS) -> ProgramMoves:
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


def open_program_file(path: str | os.PathLike, source: str | None = None) -> BinaryIO:
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


def read_program_file(path: str | os.PathLike, dialect: str | Dialect, source: str | None = None,
                      checkpoint: Callable[[], None] | None = None, lathe: bool = False,
                      dialects: Dialects = DIALECTS) -> ProgramMoves:
    """`read_program` of a file, read as a stream: a regular file of at most MAX_PROGRAM_BYTES (a FIFO, a device
    or a larger file is refused before reading); memory holds a line at a time besides the moves."""
    d = _dialect(dialect, lathe, dialects)
    source = source if source is not None else shown_path(path)
    with open_program_file(path, source) as handle:
        return _Reader(handle, d, source, checkpoint, lathe).run()
