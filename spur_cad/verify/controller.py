"""The controller the program reader (spur_cad.verify.reader) drives: its modal state (motion, feed mode, F,
tool, spindle, the lathe's diameter and feed-per-revolution modes) and the words of one block, G and M codes,
axes, F, T, S; every move it makes is recorded in compact columns (ProgramMoves).

The reader owns the program's flow (subprograms, loops, variables) and hands each block that is not a control
statement to `Controller.block`; values are evaluated by the reader (`value`), which knows the variables."""

from __future__ import annotations

import math
import re
from array import array
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spur_cad.dialects import Dialect, LatheWords
from spur_cad.verify.limits import DIRECTED_TOLERANCE_DEG, MAX_MOVES
from spur_cad.verify.program_text import Line, ProgramReadError, line_error

# Codes that set up the machine without moving it; anything else is refused.
# G54..G59 select work offsets: the program's frame is taken as the job's (one offset for all of them).
SETUP_G = {"17", "21", "40", "49", "54", "55", "56", "57", "58", "59", "64", "80", "90", "43", "61"}
QUIET_M = {"0", "1", "3", "4", "5", "7", "8", "9", "10", "11", "2", "30", "6", "68", "69"}
# ProgramMoves columns: rapid, x, y, z, a, feed, inverse_time, line, tool, spindle_rpm (array typecode, dtype)
_COLUMNS = (("b", np.int8), ("d", np.float64), ("d", np.float64), ("d", np.float64), ("d", np.float64),
            ("d", np.float64), ("b", np.int8), ("l", np.int_), ("l", np.int_), ("d", np.float64))

_WORDS = re.compile(r"([A-Z])\s*(\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))")
_WORDS_ASSIGNED = re.compile(r"([A-Z])\s*(=\s*[^\s]+|\[[^\]]*\]|#\d+|[-+]?(?:\d+\.?\d*|\.\d+))")
_ORDER = {"T": 0, "S": 0, "G": 1, "F": 2, "M": 3}  # T and S before M, G before F, then the rest in order


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
        rapid, x, y, z, a, feed, inverse_time, line, tool, spindle_rpm = arrays
        return cls(source, rapid.astype(bool), x, y, z, a, feed, inverse_time.astype(bool), line, tool, spindle_rpm)


def move_columns() -> list:
    """Empty compact columns for moves (Python arrays: about 60 bytes a move)."""
    return [array(code) for code, _ in _COLUMNS]


class Controller:
    """A controller's modal state while a program runs, and the moves it has made."""

    def __init__(self, d: Dialect, source: str, value: Callable[[str, Line], float], lathe: bool = False):
        """`value(text, line)`: a word's value (a number, or variables the reader evaluates)."""
        self.d, self.source, self.value, self.lathe = d, source, value, lathe
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

    def error(self, line: Line, message: str) -> ProgramReadError:
        return line_error(self.source, line, message)

    def _lathe_words_at(self, line: Line) -> LatheWords:
        """The dialect's lathe words, which a lathe program is read with (the reader checked them there)."""
        if self.lathe_words is None:
            raise self.error(line, f"{self.d.title} has no lathe words: this is not read as a lathe program")
        return self.lathe_words

    def moves(self) -> ProgramMoves:
        """The moves made so far, as arrays (the columns start afresh)."""
        columns, self.columns = self.columns, move_columns()
        return ProgramMoves.from_columns(self.source, columns)

    # --- one block --------------------------------------------------------------------------------
    def block(self, line: Line) -> None:
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

    def _word(self, letter: str, value: str, line: Line, target: list[float]) -> None:
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

    def _t_word(self, value: str, line: Line) -> None:
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

    def _lathe_keywords(self, line: Line) -> Line:
        """Siemens lathe words that are not address + number: LIMS=<rpm> (spindle limit under G96), DIAMON /
        DIAM90 (X as diameter) and DIAMOF (X as radius); the rest of the block is returned."""
        text = line.text
        for value in re.findall(r"\bLIMS\s*=\s*(\S+)", text):
            self.value(value, line)  # a number (or parameter) it must be
        for mode in re.findall(r"\bDIAM(ON|OF|90)\b", text):
            self.diameter = mode != "OF"
        text = re.sub(r"\bLIMS\s*=\s*\S+|\bDIAM(?:ON|OF|90)\b", " ", text)
        return Line(line.number, text.strip())

    def _check_block_codes(self, words: list[tuple[str, str]], line: Line) -> None:
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

    def words(self, line: Line) -> list[tuple[str, str]]:
        text = line.text
        found = self.words_pattern.findall(text)
        if self.words_pattern.sub("", text).strip():
            raise self.error(line, "cannot read this block")
        if self.words_pattern is _WORDS:
            return found
        return [(letter, value.lstrip("=").strip()) for letter, value in found]

    def _g_code(self, value: str, line: Line) -> None:
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

    def _lathe_g_code(self, code: str, line: Line) -> bool:
        """Lathe G codes; False for the codes milling and turning share (G21, G40, G54...)."""
        words = self._lathe_words_at(line)
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

    def _m_code(self, value: str, line: Line) -> str | None:
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

    def _move(self, target: list[float], line: Line) -> None:
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

    def _check_lathe_move(self, line: Line) -> None:
        if not self.diameter:
            raise self.error(line, "X is a radius here; this reader reads lathe programs in diameter mode "
                                   + f"({self._lathe_words_at(line).diameter_word})")
        if self.motion == "1" and not self.per_rev:
            raise self.error(line, "a lathe feed move without feed per revolution ("
                                   + f"G{self._lathe_words_at(line).feed_codes[0]})")


def _directed(current: float, target: float, direction: str, controller: Controller, line: Line) -> float:
    """The unwound A reached from `current` turning positively (M15) or negatively (M16) to the angle `target`
    in [0, 360] (360 is 0, as legacy Okuma programs write it); `direction` is the code without M (a key of
    controller.directions). A target within DIRECTED_TOLERANCE_DEG of where A is moves 0, not a full turn."""
    if not 0.0 <= target <= 360.0:
        raise controller.error(line, f"with M{direction}, A must be an angle in [0, 360], got {target:g}")
    target %= 360.0
    if math.isnan(current):
        return target
    step = (target - current) % 360.0  # in [0, 360]: rounding of an unwound `current` may give 359.99999999999994
    if min(step, 360.0 - step) <= DIRECTED_TOLERANCE_DEG:
        return current
    reached = current + step if controller.directions[direction] else current - (360.0 - step)
    return target + 360.0 * round((reached - target) / 360.0)  # the angle as written plus whole turns: no drift


def _word_order(word: tuple[str, str]) -> int:
    return _ORDER.get(word[0], 4)
