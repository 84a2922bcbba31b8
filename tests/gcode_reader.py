"""An independent reader of the G-code subset spur_cad's posts write, for all five dialects.

It executes a program text the way the controller's manual describes (modal G0/G1 and G93/G94,
F, subprogram and repeat calls with their parameters) and returns the moves it commands. It
shares no code with spur_cad.post: the tests compare what it reads with the toolpath IR.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

WORD = re.compile(r"([A-Z])\s*(=\s*[A-Z0-9#.+\-]+|\[[^\]]*\]|#\d+|[-+]?\d*\.?\d+)")
VALUE = re.compile(r"^(#\d+|[A-Z]+\d*)?\s*([-+]\s*\d*\.?\d+)?$")


@dataclass
class Move:
    rapid: bool
    start: tuple[float, float, float, float]
    end: tuple[float, float, float, float]
    inverse_time: bool
    feed: float | None  # F in effect (mm/min, or 1/min under G93)
    feed_in_block: bool
    words: str  # the block as written (for messages)
    direction: str | None = None  # M15 / M16


@dataclass
class ReadProgram:
    moves: list[Move] = field(default_factory=list)
    block_numbers: list[int] = field(default_factory=list)
    ended: bool = False  # the main flow reached the end code
    blocks_after_end_in_main: int = 0


class GcodeReadError(AssertionError):
    pass


def _strip(line: str, dialect: str) -> str:
    if dialect == "siemens":
        line = line.split(";", 1)[0]
    else:
        line = re.sub(r"\([^)]*\)", "", line)
    return line.strip()


def _number_prefix(line: str) -> tuple[int | None, str]:
    match = re.match(r"^N(\d+)\s+(.*)$", line)
    return (int(match.group(1)), match.group(2)) if match else (None, line)


def _value(text: str, variables: dict[str, float]) -> float:
    """A number, a variable, a variable plus/minus a number; in [..] or after '='."""
    text = text.strip()
    if text.startswith("="):
        text = text[1:]
    if text.startswith("[") and text.endswith("]"):
        text = text[1:-1]
    text = text.replace(" ", "")
    try:
        return float(text)
    except ValueError:
        pass
    match = VALUE.match(text)
    if not match or not match.group(1):
        raise GcodeReadError(f"cannot read value {text!r}")
    name, offset = match.group(1), match.group(2)
    if name not in variables:
        raise GcodeReadError(f"variable {name} used before it is set")
    return variables[name] + (float(offset) if offset else 0.0)


def read_program(text: str, dialect: str) -> ReadProgram:
    """Execute `text` (one of linuxcnc, fanuc, haas, siemens, okuma) and return its moves."""
    raw_lines = text.splitlines()
    result = ReadProgram()
    lines: list[str] = []
    for raw in raw_lines:
        number, rest = _number_prefix(_strip(raw, dialect))
        if number is not None:
            result.block_numbers.append(number)
        lines.append(rest)
    if dialect in ("fanuc", "haas"):
        if raw_lines[0].strip() != "%" or raw_lines[-1].strip() != "%":
            raise GcodeReadError("program must start and end with %")
        lines = lines[1:-1]
    # Find the main program's end and the subprogram definitions.
    subs: dict[str, tuple[int, int]] = {}
    end_index = next((i for i, line in enumerate(lines) if re.fullmatch(r"M0?30|M0?2", line)), None)
    if end_index is None:
        raise GcodeReadError("no end code (M30)")
    if dialect in ("fanuc", "okuma", "haas"):
        i = end_index + 1
        while i < len(lines):
            if not lines[i]:
                i += 1
                continue
            head = re.fullmatch(r"N(\d+)" if dialect == "haas" else r"O(\d+)", lines[i])
            if head is None:
                raise GcodeReadError(f"unexpected block after the end code: {lines[i]!r}")
            close = "RTS" if dialect == "okuma" else "M99"
            j = lines.index(close, i + 1)
            subs[head.group(1)] = (i + 1, j)
            i = j + 1
    elif dialect == "linuxcnc":
        for i, line in enumerate(lines):
            match = re.fullmatch(r"o(\d+) sub", line)
            if match:
                subs[match.group(1)] = (i + 1, lines.index(f"o{match.group(1)} endsub", i + 1))
    labels = {line[:-1]: i for i, line in enumerate(lines) if re.fullmatch(r"[A-Z_][A-Z0-9_]*:", line)}

    state = {"motion": None, "inverse": False, "feed": None, "pos": [None, None, None, None]}
    variables: dict[str, float] = {}

    def execute(start: int, stop: int, depth: int) -> bool:
        """Run lines[start:stop]; True when the end code is reached."""
        if depth > 4:
            raise GcodeReadError("calls nested too deep")
        i = start
        while i < stop:
            line = lines[i]
            i += 1
            if not line or line == "%":
                continue
            if dialect == "linuxcnc":
                match = re.fullmatch(r"o(\d+) sub", line)
                if match:  # definitions are skipped in the main flow
                    i = subs[match.group(1)][1] + 1
                    continue
                match = re.fullmatch(r"o(\d+) call((?:\s*\[[^\]]*\])*)", line)
                if match:
                    args = re.findall(r"\[([^\]]*)\]", match.group(2))
                    saved = dict(variables)
                    variables.update({f"#{k + 1}": _value(arg, variables) for k, arg in enumerate(args)})
                    execute(*subs[match.group(1)], depth + 1)
                    variables.clear()
                    variables.update(saved)
                    continue
            if dialect == "fanuc" and line.startswith("G65"):
                words = dict((a, v) for a, v in WORD.findall(line))
                saved = dict(variables)
                variables.update({"#24": _value(words["X"], variables), "#1": _value(words["A"], variables)})
                execute(*subs[str(int(float(words["P"])))], depth + 1)
                variables.clear()
                variables.update(saved)
                continue
            if dialect == "okuma" and line.startswith("CALL"):
                match = re.fullmatch(r"CALL O(\d+)((?:\s+[A-Z]+=\S+)*)", line)
                if not match:
                    raise GcodeReadError(f"cannot read {line!r}")
                saved = dict(variables)
                for name, value in re.findall(r"([A-Z]+)=(\S+)", match.group(2)):
                    variables[name] = _value(value, variables)
                execute(*subs[match.group(1)], depth + 1)
                variables.clear()
                variables.update(saved)
                continue
            if dialect == "haas":
                match = re.fullmatch(r"(#\d+)=(\S+)", line)
                if match:
                    variables[match.group(1)] = _value(match.group(2), variables)
                    continue
                match = re.fullmatch(r"M97 P(\d+)", line)
                if match:
                    execute(*subs[match.group(1)], depth + 1)
                    continue
            if dialect == "siemens":
                if re.fullmatch(r"(R\d+=\S+\s*)+", line):
                    for name, value in re.findall(r"(R\d+)=(\S+)", line):
                        variables[name] = _value(value, variables)
                    continue
                match = re.fullmatch(r"REPEAT (\w+) (\w+) P=(\d+)", line)
                if match:
                    for _ in range(int(match.group(3))):
                        execute(labels[match.group(1)] + 1, labels[match.group(2)], depth + 1)
                    continue
                if line.endswith(":"):
                    continue
            if re.fullmatch(r"M0?30|M0?2", line):
                return True
            block(line)
        return False

    def block(line: str) -> None:
        words = WORD.findall(line)
        codes = [(a, v) for a, v in words]
        gs = [float(v) for a, v in codes if a == "G"]
        for g in gs:
            if g in (0, 1):
                state["motion"] = int(g)
            elif g == 93:
                state["inverse"] = True
                state["feed"] = None  # G93 wants F in every block
            elif g == 94:
                if state["inverse"]:
                    state["feed"] = None
                state["inverse"] = False
        feed_in_block = False
        for a, v in codes:
            if a == "F":
                state["feed"] = _value(v, variables)
                feed_in_block = True
        axes = {a: _value(v, variables) for a, v in codes if a in "XYZA"}
        direction = next((f"M{int(float(v))}" for a, v in codes if a == "M" and int(float(v)) in (15, 16)), None)
        if not axes:
            return
        if state["motion"] is None:
            raise GcodeReadError(f"motion without G0/G1 in effect: {line!r}")
        start = tuple(state["pos"])
        pos = list(state["pos"])
        for k, axis in enumerate("XYZA"):
            if axis in axes:
                pos[k] = axes[axis]
        if any(p is None for p in pos):
            raise GcodeReadError(f"first move does not give every axis: {line!r}")
        state["pos"] = pos
        result.moves.append(Move(state["motion"] == 0, start, tuple(pos), state["inverse"], state["feed"],
                                 feed_in_block, line, direction))

    result.ended = execute(0, end_index + 1, 0)
    return result


def inlined_lines(text: str) -> list[str]:
    """A LinuxCNC program's lines with its one subprogram's text put in at each call, in call order (a flat
    program's lines as they are): for checks on the order of M codes and moves by text."""
    sub = re.search(r"^o(\d+) sub\n(.*?)^o\1 endsub\n", text, flags=re.M | re.S)
    if sub is None:
        return text.splitlines()
    lines: list[str] = []
    for line in text[sub.end():].splitlines():
        lines += sub.group(2).splitlines() if line.startswith(f"o{sub.group(1)} call") else [line]
    return lines
