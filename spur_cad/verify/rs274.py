"""LinuxCNC's own interpreter as a second reader of LinuxCNC programs (`rs274`, Debian's linuxcnc-uspace).

`rs274 -g PROGRAM CANON` interprets the whole program in batch mode and exits 1 on an error, with
the message and the block on stderr. `verify` reports its verdict for each LinuxCNC program; where
rs274 is not installed the verdict says so (the simulation does not depend on it).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

RS274_LOCATIONS = ("/usr/bin/rs274", "/usr/lib/linuxcnc/bin/rs274", "/usr/local/bin/rs274")
TIMEOUT_S = 300.0
NUMERIC_CALLS = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "SET_FEED_RATE", "SET_FEED_MODE", "CHANGE_TOOL",
                 "SET_SPINDLE_SPEED")


def rs274_executable() -> str | None:
    """rs274 on PATH, else in Debian's locations; None when LinuxCNC is not installed."""
    found = shutil.which("rs274")
    if found:
        return found
    return next((path for path in RS274_LOCATIONS if os.access(path, os.X_OK)), None)


def rs274_verdict(program: str | os.PathLike) -> str:
    """'passed', 'failed: <rs274's message>' or 'not available: ...' for a LinuxCNC program file."""
    executable = rs274_executable()
    if executable is None:
        return "not available: rs274 not found (install linuxcnc-uspace)"
    with tempfile.TemporaryDirectory(prefix="spur-cad-rs274-") as work:
        try:
            proc = subprocess.run([executable, "-g", str(Path(program).resolve()), str(Path(work) / "canon.txt")],
                                  stdin=subprocess.DEVNULL, capture_output=True, text=True, cwd=work,
                                  timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            return f"failed: rs274 did not finish within {TIMEOUT_S:.0f} s"
    if proc.returncode == 0:
        return "passed"
    messages = [line.strip() for line in (proc.stderr + proc.stdout).splitlines()
                if line.strip() and line.strip() != "executing"]
    return "failed: " + ("; ".join(messages[:2]) if messages else f"exit status {proc.returncode}")


def _canonical_text(program: str | os.PathLike, source: str) -> str:
    """rs274's canonical calls for a program (raises SpurCadError when rs274 is missing or refuses it)."""
    from spur_cad.errors import SpurCadError

    executable = rs274_executable()
    if executable is None:
        raise SpurCadError("--reader rs274: rs274 not found (install linuxcnc-uspace)")
    with tempfile.TemporaryDirectory(prefix="spur-cad-rs274-") as work:
        canon = Path(work) / "canon.txt"
        proc = subprocess.run([executable, "-g", str(Path(program).resolve()), str(canon)], stdin=subprocess.DEVNULL,
                              capture_output=True, text=True, cwd=work, timeout=TIMEOUT_S)
        if proc.returncode != 0:
            messages = [line.strip() for line in proc.stderr.splitlines() if line.strip() not in ("", "executing")]
            raise SpurCadError(f"{source}: rs274 refuses the program: {'; '.join(messages[:2])}")
        return canon.read_text()


def _refuse_unsimulated(name: str, arguments: str, number: int, source: str) -> None:
    """Calls that change what the moves mean (inch units, non-zero offsets) or moves verify cannot simulate."""
    import re

    from spur_cad.errors import SpurCadError

    where = f"{source}: rs274 canonical call {number}"
    if name in ("ARC_FEED", "STRAIGHT_PROBE", "NURBS_FEED", "RIGID_TAP"):
        raise SpurCadError(f"{where} is {name}, which verify does not simulate")
    if name == "USE_LENGTH_UNITS" and "MM" not in arguments:
        raise SpurCadError(f"{where} sets {arguments} units; verify reads millimetre programs (G21)")
    offsets = [float(v) for v in re.findall(r"[-+]?\d+\.\d+", arguments)]
    # (tool length offsets do not show in the canonical positions: the programmed point is read, as with
    # spur_cad's reader; test_the_reader_agrees_with_linuxcncs_interpreter compares them under G43)
    if name in ("SET_G92_OFFSET", "SET_G5X_OFFSET", "SET_XY_ROTATION") and \
            any(abs(v) > 1e-9 for v in offsets):
        raise SpurCadError(f"{where} is {name}({arguments}): non-zero offsets are not applied by verify; "
                           "program in the part frame")


def read_canonical(program: str | os.PathLike, source: str):
    """The moves of a LinuxCNC program as LinuxCNC's own interpreter executes them (rs274's canonical calls
    STRAIGHT_TRAVERSE / STRAIGHT_FEED with SET_FEED_RATE, SET_FEED_MODE, CHANGE_TOOL, SET_SPINDLE_SPEED):
    the reference reader for LinuxCNC programs. `line` holds the canonical call's number."""
    import re

    from spur_cad.errors import SpurCadError
    from spur_cad.verify.reader import MAX_MOVES, ProgramMoves

    text = _canonical_text(program, source)
    call = re.compile(r"^\s*(\d+)\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")
    moves, feed, inverse, tool, spindle = [], float("nan"), False, 0, 0.0
    for line in text.splitlines():
        found = call.match(line)
        if found is None:
            continue
        number, name, arguments = int(found.group(1)), found.group(2), found.group(3)
        if name not in NUMERIC_CALLS:
            _refuse_unsimulated(name, arguments, number, source)
            continue  # comments, coolant, spindle, ...
        values = [float(v) for v in re.split(r"[,\s]+", arguments.strip()) if v]
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            rapid = name == "STRAIGHT_TRAVERSE"
            moves.append((rapid, *values[:4], float("nan") if rapid else feed, inverse and not rapid, number,
                          tool, spindle))
            if len(moves) > MAX_MOVES:
                raise SpurCadError(f"{source}: the program has more than {MAX_MOVES:,} moves; split it")
        elif name == "SET_FEED_RATE":
            feed = values[0]
        elif name == "SET_FEED_MODE":
            inverse = values[-1] == 1.0
        elif name == "CHANGE_TOOL":
            tool = int(values[0])
        elif name == "SET_SPINDLE_SPEED":
            spindle = values[-1]
    return ProgramMoves.from_columns(source, list(zip(*moves)) if moves else [[]] * 10)
