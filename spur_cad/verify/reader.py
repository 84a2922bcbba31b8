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
in [0, 360) reached turning that way (Okuma); elsewhere A is the absolute, unwound axis. Anything this
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

import math
import re
from dataclasses import dataclass

import numpy as np

from spur_cad.errors import SpurCadError

DIALECTS = ("linuxcnc", "fanuc", "haas", "siemens", "okuma")
LATHE_DIALECTS = ("linuxcnc", "fanuc", "siemens")
MAX_PROGRAM_BYTES = 256 * 1024 * 1024
MAX_MOVES = 10_000_000  # about 0.6 GB of move columns: refuse before reading further
MAX_BLOCKS = 50_000_000  # blocks executed (loops and calls counted): some minutes of reading at most
MAX_CALL_DEPTH = 8
MAX_REPEAT = 100_000
CHECK_EVERY_BLOCKS = 100_000  # how often a long read calls its checkpoint (the CLI stops there on a signal)
LOCAL_VARIABLES = 33  # #1..#33: a call's arguments, restored when it returns

# Fanuc's argument specification I: the letter of a G65 argument -> the local variable it sets.
FANUC_ARGUMENTS = {"A": 1, "B": 2, "C": 3, "I": 4, "J": 5, "K": 6, "D": 7, "E": 8, "F": 9, "H": 11, "M": 13,
                   "Q": 17, "R": 18, "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24, "Y": 25, "Z": 26}
# Codes that set up the machine without moving it; anything else is refused.
# G54..G59 select work offsets: the program's frame is taken as the job's (one offset for all of them).
SETUP_G = {"17", "21", "40", "49", "54", "55", "56", "57", "58", "59", "64", "80", "90", "43", "61"}
QUIET_M = {"0", "1", "3", "4", "5", "7", "8", "9", "10", "11", "2", "30", "6", "68", "69"}
_COLUMN_TYPES = ("b", "d", "d", "d", "d", "d", "b", "q", "q", "d")  # ProgramMoves.from_columns


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
        """Moves from the columns rapid, x, y, z, a, feed, inverse_time, line, tool, spindle_rpm (sequences)."""
        return cls(source, np.array(columns[0], bool), *(np.array(c, float) for c in columns[1:6]),
                   np.array(columns[6], bool), np.array(columns[7], int), np.array(columns[8], int),
                   np.array(columns[9], float))


def move_columns() -> list:
    """Empty compact columns for moves (Python arrays: about 60 bytes a move)."""
    from array import array

    return [array(code) for code in _COLUMN_TYPES]


@dataclass
class _Line:
    number: int  # 1-based line in the file
    text: str  # without comments and block number


_ENDS = re.compile(r"(^|\s)M0*(30|2)(\s|$)")  # M30 or M2, anywhere in a block
_UNSIGNED = r"(?:\d+\.?\d*|\.\d+)"
_TERM = re.compile(rf"\s*([-+]?)\s*(#\d+|R\d+|[A-Z_][A-Z0-9_]*|{_UNSIGNED})\s*")


class _Reader:
    """Executes one program: machine state, variables, subprogram calls, recorded moves."""

    def __init__(self, text: str, dialect: str, source: str, checkpoint=None, lathe: bool = False):
        self.dialect, self.source, self.checkpoint, self.lathe = dialect, source, checkpoint, lathe
        self.axes = "XZ" if lathe else "XYZA"
        self.diameter = dialect == "fanuc"  # lathe X as a diameter: G7 (LinuxCNC), DIAMON (Siemens)
        self.per_rev = False  # lathe feed per revolution: G95 (G99 on Fanuc)
        self.block_codes: set[str] = set()  # G codes of the block whose words are checked together
        self.blocks = 0
        self.lines = _clean_lines(text, dialect)
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
        self.subs: dict[int, tuple[int, int]] = {}  # O<n> (and LinuxCNC o<n> sub) by program number
        self.local_subs: dict[int, tuple[int, int]] = {}  # Haas N<n> local subprograms (M97)
        self.labels: dict[str, int] = {}

    def error(self, line: _Line, message: str) -> ProgramReadError:
        return ProgramReadError(f"{self.source}:{line.number}: {message} (in {line.text!r})")

    # --- structure ------------------------------------------------------------------------
    def index_structure(self) -> int:
        """Find subprograms and labels; returns the index where the main program ends (exclusive)."""
        lines = self.lines
        end = next((i for i, line in enumerate(lines) if _ENDS.search(line.text)), None)
        if end is None:
            raise ProgramReadError(f"{self.source}: no end of program (M30 or M2)")
        for i, line in enumerate(lines):
            if self.dialect == "linuxcnc":
                found = re.fullmatch(r"O(\d+)\s*SUB", line.text)
                if found:
                    self.subs[int(found.group(1))] = (i + 1, self._closing(i, rf"O0*{int(found.group(1))}\s*ENDSUB"))
            elif self.dialect == "siemens" and re.fullmatch(r"[A-Z_][A-Z0-9_]*:", line.text):
                self.labels[line.text[:-1]] = i
        if self.dialect in ("fanuc", "haas", "okuma"):
            i = end + 1
            while i < len(lines):
                head = re.fullmatch(r"O(\d+)|N(\d+)", lines[i].text)
                if head is None:
                    raise self.error(lines[i], "a block after the end of the program that is not a subprogram")
                j = self._closing(i, "RTS" if self.dialect == "okuma" else "M0*99")
                target = self.subs if head.group(1) else self.local_subs
                target[int(head.group(1) or head.group(2))] = (i + 1, j)
                i = j + 1
        return end

    def _closing(self, start: int, pattern: str) -> int:
        for j in range(start + 1, len(self.lines)):
            if re.fullmatch(pattern, self.lines[j].text):
                return j
        raise self.error(self.lines[start], f"nothing closes this subprogram or loop ({pattern})")

    # --- values -----------------------------------------------------------------------------
    def value(self, text: str, line: _Line) -> float:
        """A number, a variable, or a sum of them: '12.5', '#2', '[#2+2.5]', 'R2+2.5', 'ASP-23.9'."""
        text = text.strip()
        if text.startswith("[") and text.endswith("]"):
            text = text[1:-1]
        total, position = 0.0, 0
        while position < len(text):
            found = _TERM.match(text, position)
            if found is None or found.end() == position:
                raise self.error(line, f"cannot evaluate {text!r}")
            sign, term = found.groups()
            if position > 0 and not sign:
                raise self.error(line, f"cannot evaluate {text!r}: terms need + or - between them")
            if term[0].isdigit() or term[0] == ".":
                number = float(term)
            elif term not in self.variables:
                raise self.error(line, f"variable {term} is used before it is set")
            else:
                number = self.variables[term]
            total += -number if sign == "-" else number
            position = found.end()
        if not math.isfinite(total) or abs(total) > 1e6:
            raise self.error(line, f"value {text!r} = {total:g} is not a finite coordinate")
        return total

    # --- execution ------------------------------------------------------------------------------
    def run(self) -> ProgramMoves:
        end = self.index_structure()
        self.execute(0, end + 1, 0)
        if not self.ended:
            raise ProgramReadError(f"{self.source}: the program never reaches its end (M30 or M2)")
        return ProgramMoves.from_columns(self.source, self.columns)

    def execute(self, start: int, stop: int, depth: int) -> None:
        if depth > MAX_CALL_DEPTH:
            raise self.error(self.lines[start], f"subprogram calls nested deeper than {MAX_CALL_DEPTH}")
        i = start
        while i < stop and not self.ended:
            line = self.lines[i]
            i += 1
            self.blocks += 1
            if self.blocks % CHECK_EVERY_BLOCKS == 0:
                if self.blocks > MAX_BLOCKS:
                    raise self.error(line, f"the program executes more than {MAX_BLOCKS:,} blocks (loops and "
                                           "calls counted); refused before reading further")
                if self.checkpoint is not None:
                    self.checkpoint()
            jump = self.control(line, i, depth)
            if jump is not None:
                i = jump
                continue
            self.block(line)

    def control(self, line: _Line, after: int, depth: int) -> int | None:
        """Subprogram definitions, calls, repeats and labels; the index to go on at, or None for a block."""
        if self.dialect == "linuxcnc":
            return self._linuxcnc_control(line, after, depth)
        if self.dialect == "siemens":
            return self._siemens_control(line, after, depth)
        return self._fanuc_family_control(line, after, depth)

    def _siemens_control(self, line: _Line, after: int, depth: int) -> int | None:
        text = line.text
        if re.fullmatch(r"[A-Z_][A-Z0-9_]*:", text) or re.fullmatch(r'WORKPIECE\([^()]*\)', text):
            return after  # a label, or the blank for the control's simulation (ignored)
        found = re.fullmatch(r"REPEAT\s+([A-Z_][A-Z0-9_]*)\s+([A-Z_][A-Z0-9_]*)(?:\s*P\s*=\s*(\d+))?", text)
        if found:
            first, last = (self.labels.get(found.group(k)) for k in (1, 2))
            if first is None or last is None or last <= first:
                raise self.error(line, "REPEAT names labels that do not enclose a section")
            for _ in range(self._count(found.group(3), line)):
                self.execute(first + 1, last, depth + 1)
            return after
        if re.fullmatch(r"(R\d+=\S+\s*)+", text):
            for name, value in re.findall(r"(R\d+)=(\S+)", text):
                self.variables[name] = self.value(value, line)
            return after
        return None

    def _count(self, text: str | None, line: _Line) -> int:
        count = int(text) if text else 1
        if not 0 <= count <= MAX_REPEAT:
            raise self.error(line, f"repeat count {count} outside 0..{MAX_REPEAT}")
        return count

    def _call(self, number: str, line: _Line, depth: int, count: int = 1, local: bool = False,
              arguments: dict[str, float] | None = None) -> None:
        """Run subprogram `number` `count` times; `arguments` set local variables (#1...), restored after it
        returns (LinuxCNC o-call and Fanuc G65 make them local to the call)."""
        table = self.local_subs if local else self.subs
        if int(number) not in table:
            raise self.error(line, f"calls subprogram {number}, which the program does not define")
        saved = None
        if arguments is not None:
            saved = {f"#{n}": self.variables.get(f"#{n}") for n in range(1, LOCAL_VARIABLES + 1)}
            self.variables.update(arguments)
        first, last = table[int(number)]
        for _ in range(count):
            self.execute(first, last, depth + 1)
        if saved is not None:
            for name, value in saved.items():
                if value is None:
                    self.variables.pop(name, None)
                else:
                    self.variables[name] = value

    def _linuxcnc_control(self, line: _Line, after: int, depth: int) -> int | None:
        text = line.text
        found = re.fullmatch(r"O(\d+)\s*SUB", text)
        if found:
            return self.subs[int(found.group(1))][1] + 1  # a definition: skipped in the flow
        found = re.fullmatch(r"O(\d+)\s*CALL((?:\s*\[[^\]]*\])*)", text)
        if found:
            arguments = {f"#{index}": self.value(argument, line)
                         for index, argument in enumerate(re.findall(r"\[([^\]]*)\]", found.group(2)), start=1)}
            self._call(found.group(1), line, depth, arguments=arguments)
            return after
        found = re.fullmatch(r"O(\d+)\s*REPEAT\s*\[([^\]]*)\]", text)
        if found:
            close = self._closing(after - 1, rf"O0*{int(found.group(1))}\s*ENDREPEAT")
            for _ in range(self._count(str(int(self.value(found.group(2), line))), line)):
                self.execute(after, close, depth + 1)
            return close + 1
        found = re.fullmatch(r"(#\d+)\s*=\s*(.+)", text)
        if found:
            self.variables[found.group(1)] = self.value(found.group(2), line)
            return after
        return None

    def _fanuc_family_control(self, line: _Line, after: int, depth: int) -> int | None:
        text = line.text
        if re.fullmatch(r"O\d+", text):
            return after  # the program's own number (its title was a comment)
        found = re.fullmatch(r"(#\d+)\s*=\s*(.+)", text)
        if found:
            self.variables[found.group(1)] = self.value(found.group(2), line)
            return after
        if self.dialect == "okuma":
            found = re.fullmatch(r"CALL\s*O(\d+)((?:\s+[A-Z][A-Z0-9]*\s*=\s*\S+)*)", text)
            if found:
                for name, value in re.findall(r"([A-Z][A-Z0-9]*)\s*=\s*(\S+)", found.group(2)):
                    self.variables[name] = self.value(value, line)
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
            if found.group(1) == "7" and self.dialect != "haas":
                raise self.error(line, "M97 (local subprogram) is a Haas code")
            self._call(found.group(2), line, depth, self._count(found.group(3), line), local=found.group(1) == "7")
            return after
        return None

    # --- one block --------------------------------------------------------------------------------
    def block(self, line: _Line) -> None:
        if self.lathe and self.dialect == "siemens":
            line = self._siemens_lathe_words(line)
        # T and S before M (M6 loads the tool the block names, whatever the order), G before F (a feed mode
        # change resets F), then the rest in order
        words = sorted(self.words(line), key=lambda word: {"T": 0, "S": 0, "G": 1, "F": 2, "M": 3}.get(word[0], 4))
        target = list(self.pose)
        direction = None
        self.feed_in_block = False
        self.block_codes = set()
        for letter, value in words:
            if letter == "M":
                direction = self._m_code(value, line) or direction
            else:
                self._word(letter, value, line, target)
        if self.block_codes:
            self._check_block_codes(words, line)
        if direction is not None and not math.isnan(target[3]):
            target[3] = _directed(self.pose[3], target[3], direction, self, line)
        if any(letter in "XYZA" for letter, _ in words):
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
        elif letter in "HDP" or (letter == "N" and self.dialect == "siemens"):
            return  # tool offset numbers, G64 P tolerance, G96 D spindle limit, G15 H work offset
        elif self.lathe and letter in "YAUW":
            raise self.error(line, f"word {letter}{value}: a lathe program moves X and Z only (absolute, no U/W)")
        else:
            raise self.error(line, f"word {letter}{value} is not supported by this reader")

    def _t_word(self, value: str, line: _Line) -> None:
        """T: the tool M6 loads; on a Siemens or Fanuc lathe the turret indexes at once (Fanuc T0101: tool 1,
        offset 1)."""
        if not (self.lathe and self.dialect in ("siemens", "fanuc")):
            self.pending_tool = int(self.value(value, line))
            return
        if self.dialect == "fanuc":
            if not re.fullmatch(r"\d{3,4}", value):
                raise self.error(line, f"T{value}: a Fanuc lathe T word gives the tool and its offset (T0101)")
            self.tool = self.pending_tool = int(value) // 100
        else:
            self.tool = self.pending_tool = int(self.value(value, line))

    def _siemens_lathe_words(self, line: _Line) -> _Line:
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
            if code in ("50", "26") and (letters & set("XZUWY") or "S" not in letters):
                raise self.error(line, f"G{code} is read only as the spindle speed limit G{code} S<rpm> "
                                       "(with axes it sets a coordinate system or a working area)")
            if code == "15":
                numbers = [value for letter, value in words if letter == "H"]
                if len(numbers) != 1 or not re.fullmatch(r"\d+", numbers[0]) or int(numbers[0]) < 1 \
                        or letters & set("XYZA"):
                    raise self.error(line, "G15 is read only as Okuma's work offset selection G15 H<n> "
                                           "(n = 1, 2, ...) in a block of its own")

    def words(self, line: _Line) -> list[tuple[str, str]]:
        text = line.text
        pattern = (r"([A-Z])\s*(=\s*[^\s]+|\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))"
                   if self.dialect in ("siemens", "okuma") else
                   r"([A-Z])\s*(\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))")
        found = list(re.finditer(pattern, text))
        covered = "".join(text[m.start():m.end()] for m in found)
        if re.sub(r"\s", "", covered) != re.sub(r"\s", "", text):
            raise self.error(line, "cannot read this block")
        return [(m.group(1), m.group(2).lstrip("=").strip()) for m in found]

    def _g_code(self, value: str, line: _Line) -> None:
        code = value.lstrip("0") or "0"
        if code in ("0", "1"):
            self.motion = code
        elif self.lathe and self._lathe_g_code(code, line):
            return
        elif code == "15" and self.dialect == "okuma" and not self.lathe:
            self.block_codes.add(code)  # G15 H<n>: Okuma's work offset n
        elif code in ("93", "94"):
            if self.inverse != (code == "93"):
                self.feed = math.nan  # a feed mode change leaves no F in effect (LinuxCNC, Fanuc)
            self.inverse = code == "93"
        elif code not in SETUP_G and not (code == "71" and self.dialect == "siemens"):  # G71: metric on 840D
            raise self.error(line, f"G{value} is not supported by this reader (it reads G0/G1 moves, G90, G93/G94)")

    def _lathe_g_code(self, code: str, line: _Line) -> bool:
        """Lathe G codes; False for the codes milling and turning share (G21, G40, G54...)."""
        per_rev, per_minute = ("99", "98") if self.dialect == "fanuc" else ("95", "94")
        if code in (per_rev, per_minute):
            if self.per_rev != (code == per_rev):
                self.feed = math.nan  # a new feed mode needs a new F
            self.per_rev = code == per_rev
        elif code in ("96", "97", "18"):
            pass  # constant cutting speed (S in m/min) or rpm, the ZX plane
        elif code in ("7", "8") and self.dialect == "linuxcnc":
            self.diameter = code == "7"
        elif (code, self.dialect) in (("50", "fanuc"), ("26", "siemens")):
            self.block_codes.add(code)
        elif code == "93" or (code in ("90", "94") and self.dialect == "fanuc"):
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
        elif code in ("15", "16") and self.dialect == "okuma":
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
        if any(math.isnan(t) for t in target):
            if rapid:  # e.g. a restart's Z-only move to the clearance height: known from here on, not a move
                self.pose = target
                return
            missing = "".join(axis for axis, t in zip("XYZA", target) if math.isnan(t))
            raise self.error(line, f"a feed move before every axis is known ({missing} unknown)")
        if not rapid and not (math.isfinite(self.feed) and self.feed > 0.0):
            raise self.error(line, "a feed move without a positive F")
        if not rapid and self.inverse and not self.feed_in_block:
            raise self.error(line, "an inverse-time (G93) feed move needs its own F")
        if len(self.columns[0]) >= MAX_MOVES:
            raise self.error(line, f"the program has more than {MAX_MOVES:,} moves; split it")
        row = (rapid, *target, math.nan if rapid else self.feed, self.inverse and not rapid, line.number,
               self.tool, self.spindle)
        for column, value in zip(self.columns, row):
            column.append(value)
        self.pose = target


    def _check_lathe_move(self, line: _Line) -> None:
        if not self.diameter:
            raise self.error(line, "X is a radius here; this reader reads lathe programs in diameter mode "
                                   + ("(G7)" if self.dialect == "linuxcnc" else "(DIAMON)"))
        if self.motion == "1" and not self.per_rev:
            raise self.error(line, "a lathe feed move without feed per revolution ("
                                   + ("G99" if self.dialect == "fanuc" else "G95") + ")")


def _directed(current: float, target: float, direction: str, reader: _Reader, line: _Line) -> float:
    """The unwound A reached from `current` turning positively (M15) or negatively (M16) to the angle `target`
    in [0, 360)."""
    if not 0.0 <= target < 360.0:
        raise reader.error(line, f"with M{direction}, A must be an angle in [0, 360), got {target:g}")
    if math.isnan(current):
        return target
    step = (target - current) % 360.0
    return current + step if direction == "15" else current - ((360.0 - step) % 360.0)


def _clean_lines(text: str, dialect: str) -> list[_Line]:
    """Lines without comments, block numbers and surrounding blanks; upper case (LinuxCNC's o-words too)."""
    lines = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split(";", 1)[0] if dialect == "siemens" else re.sub(r"\([^)]*\)", "", raw)
        if dialect == "linuxcnc":
            line = line.split(";", 1)[0]
        line = line.strip().upper()
        if dialect != "haas" or not re.fullmatch(r"N\d+", line):  # Haas's N<n> heads a local subprogram
            line = re.sub(r"^N\d+\s*", "", line)
        if line and line != "%":  # % delimits Fanuc/Haas programs (tape start and end)
            lines.append(_Line(number, line))
    return lines


def read_program(text: str, dialect: str, source: str = "program", checkpoint=None,
                 lathe: bool = False) -> ProgramMoves:
    """The moves of a program in `dialect` (one of DIALECTS); raises ProgramReadError naming `source`'s line.
    `checkpoint()` is called every CHECK_EVERY_BLOCKS blocks (the CLI stops there when a signal arrived).
    `lathe`: a lathe program (LATHE_DIALECTS; the module docstring says what is read): x is the diameter as
    written, y = a = 0, feed in mm/rev as written."""
    if dialect not in DIALECTS:
        raise ProgramReadError(f"unknown dialect {dialect!r} (known: {', '.join(DIALECTS)})")
    if lathe and dialect not in LATHE_DIALECTS:
        raise ProgramReadError(f"no lathe dialect {dialect!r} (known: {', '.join(LATHE_DIALECTS)})")
    if len(text) > MAX_PROGRAM_BYTES:
        raise ProgramReadError(f"{source}: larger than {MAX_PROGRAM_BYTES // 2**20} MiB")
    return _Reader(text, dialect, source, checkpoint, lathe).run()
