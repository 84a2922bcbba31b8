"""LinuxCNC's own interpreter as a second reader of LinuxCNC programs (`rs274`, Debian's linuxcnc-uspace).

`rs274 -g PROGRAM CANON` interprets the whole program in batch mode and exits 1 on an error, with
the message and the block on stderr. `verify` reports its verdict for each LinuxCNC program; where
rs274 is not installed the verdict says so (the simulation does not depend on it).
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import signal
import subprocess
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from spur_cad.errors import SpurCadError, escaped, shown

RS274_LOCATIONS = ("/usr/bin/rs274", "/usr/lib/linuxcnc/bin/rs274", "/usr/local/bin/rs274")
TIMEOUT_S = 60.0  # rs274 interprets a program of two million moves in seconds; an endless loop never ends
MAX_OUTPUT_BYTES = 512 * 1024 * 1024  # rs274's canonical calls and messages (files of the child, limited by the OS)
NUMERIC_CALLS = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "SET_FEED_RATE", "SET_FEED_MODE", "CHANGE_TOOL",
                 "SET_SPINDLE_SPEED")


@dataclass(frozen=True)
class Rs274Run:
    """How rs274 ended: `problem` is None when it interpreted the whole program, else what went wrong in one
    line; `canon` the file of its canonical calls (inside the run's temporary folder)."""

    problem: str | None
    canon: Path


def rs274_executable() -> str | None:
    """rs274 on PATH, else in Debian's locations; None when LinuxCNC is not installed."""
    found = shutil.which("rs274")
    if found:
        return found
    return next((path for path in RS274_LOCATIONS if os.access(path, os.X_OK)), None)


def _limit_output() -> None:  # in the child, before rs274 starts: its files stop growing at MAX_OUTPUT_BYTES
    resource.setrlimit(resource.RLIMIT_FSIZE, (MAX_OUTPUT_BYTES, MAX_OUTPUT_BYTES))


def _run(executable: str, program: BinaryIO, work: Path, checkpoint: Callable[[], None] | None = None) -> Rs274Run:
    """rs274 -g on an open program file (the child reads it through its inherited descriptor, so what was checked
    is what is interpreted), with its time and output bounded; `checkpoint()` is called while it runs (the CLI
    stops there on a signal, and rs274 is stopped with it)."""
    canon, messages = work / "canon.txt", work / "messages.txt"
    fd = program.fileno()
    deadline = time.monotonic() + TIMEOUT_S
    with open(messages, "wb") as output:
        proc = subprocess.Popen([executable, "-g", f"/dev/fd/{fd}", str(canon)], stdin=subprocess.DEVNULL,
                                stdout=output, stderr=output, cwd=work, pass_fds=(fd,), preexec_fn=_limit_output)
        try:
            while True:
                try:
                    proc.wait(timeout=0.1)
                    break
                except subprocess.TimeoutExpired:
                    if checkpoint is not None:
                        checkpoint()
                    if time.monotonic() > deadline:
                        return Rs274Run(f"rs274 did not finish within {TIMEOUT_S:.0f} s (an endless loop?)", canon)
        finally:
            if proc.returncode is None:
                proc.kill()
                proc.wait()
    if proc.returncode == -signal.SIGXFSZ or any(path.exists() and path.stat().st_size >= MAX_OUTPUT_BYTES
                                                 for path in (canon, messages)):
        from spur_cad.verify.reader import MAX_MOVES

        return Rs274Run(f"rs274's output passed {MAX_OUTPUT_BYTES // 2**20} MiB (verify reads at most "
                        f"{MAX_MOVES:,} moves)", canon)
    if proc.returncode == 0:
        return Rs274Run(None, canon)
    with open(messages, "rb") as handle:
        text = handle.read(16 * 1024).decode("utf-8", "replace")
    lines = [line.strip() for line in text.splitlines() if line.strip() not in ("", "executing")]
    return Rs274Run("; ".join(escaped(line)[:200] for line in lines[:2]) or f"exit status {proc.returncode}", canon)


def rs274_verdict(program: str | os.PathLike, checkpoint: Callable[[], None] | None = None) -> str:
    """'passed', 'failed: <rs274's message>' or 'not available: ...' for a LinuxCNC program file."""
    from spur_cad.verify.reader import open_program_file

    executable = rs274_executable()
    if executable is None:
        return "not available: rs274 not found (install linuxcnc-uspace)"
    with open_program_file(program) as handle, tempfile.TemporaryDirectory(prefix="spur-cad-rs274-") as work:
        run = _run(executable, handle, Path(work), checkpoint)
    return "passed" if run.problem is None else f"failed: {run.problem}"


def _refuse_unsimulated(name: str, arguments: str, number: int, source: str) -> None:
    """Calls that change what the moves mean (inch units, non-zero offsets) or moves verify cannot simulate."""
    where = f"{source}: rs274 canonical call {number}"
    if name in ("ARC_FEED", "STRAIGHT_PROBE", "NURBS_FEED", "RIGID_TAP"):
        raise SpurCadError(f"{where} is {name}, which verify does not simulate")
    if name == "USE_LENGTH_UNITS" and "MM" not in arguments:
        raise SpurCadError(f"{where} sets {shown(arguments)} units; verify reads millimetre programs (G21)")
    offsets = [float(v) for v in re.findall(r"[-+]?\d+\.\d+", arguments)]
    # (tool length offsets do not show in the canonical positions: the programmed point is read, as with
    # spur_cad's reader; test_the_reader_agrees_with_linuxcncs_interpreter compares them under G43)
    if name in ("SET_G92_OFFSET", "SET_G5X_OFFSET", "SET_XY_ROTATION") and \
            any(abs(v) > 1e-9 for v in offsets):
        raise SpurCadError(f"{where} is {name}({shown(arguments)}): non-zero offsets are not applied by verify; "
                           "program in the part frame")


class _CanonState:
    """The modal state of rs274's canonical calls, appending the moves to `columns`."""

    def __init__(self, columns: list):
        self.columns = columns
        self.feed, self.inverse, self.tool, self.spindle = float("nan"), False, 0, 0.0

    def call(self, number: int, name: str, arguments: str, source: str) -> None:
        if name not in NUMERIC_CALLS:
            _refuse_unsimulated(name, arguments, number, source)
            return  # comments, coolant, spindle, ...
        values = [float(v) for v in re.split(r"[,\s]+", arguments.strip()) if v]
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            rapid = name == "STRAIGHT_TRAVERSE"
            for column, value in zip(self.columns, (rapid, *values[:4], float("nan") if rapid else self.feed,
                                                    self.inverse and not rapid, number, self.tool, self.spindle)):
                column.append(value)
        elif name == "SET_FEED_RATE":
            self.feed = values[0]
        elif name == "SET_FEED_MODE":
            self.inverse = values[-1] == 1.0
        elif name == "CHANGE_TOOL":
            self.tool = int(values[0])
        elif name == "SET_SPINDLE_SPEED":
            self.spindle = values[-1]


def read_canonical(program: BinaryIO, source: str, checkpoint: Callable[[], None] | None = None):
    """The moves of an open LinuxCNC program file as LinuxCNC's own interpreter executes them (rs274's canonical
    calls STRAIGHT_TRAVERSE / STRAIGHT_FEED with SET_FEED_RATE, SET_FEED_MODE, CHANGE_TOOL, SET_SPINDLE_SPEED):
    the reference reader for LinuxCNC programs. `line` holds the canonical call's number. rs274's time and output
    are bounded (TIMEOUT_S, MAX_OUTPUT_BYTES) and its calls are read as a stream (at most MAX_MOVES moves)."""
    from spur_cad.verify.reader import MAX_MOVES, ProgramMoves, move_columns

    executable = rs274_executable()
    if executable is None:
        raise SpurCadError("--reader rs274: rs274 not found (install linuxcnc-uspace)")
    call = re.compile(r"^\s*(\d+)\s+N\S*\s+([A-Z_]+)\((.*)\)\s*$")
    columns = move_columns()
    with tempfile.TemporaryDirectory(prefix="spur-cad-rs274-") as work:
        run = _run(executable, program, Path(work), checkpoint)
        if run.problem is not None:
            raise SpurCadError(f"{source}: rs274 refuses the program: {run.problem}")
        with open(run.canon, "rb") as canon:
            state = _CanonState(columns)
            for raw in canon:
                found = call.match(raw.decode("utf-8", "replace"))
                if found is not None:
                    state.call(int(found.group(1)), found.group(2), found.group(3), source)
                if len(columns[0]) > MAX_MOVES:
                    raise SpurCadError(f"{source}: the program has more than {MAX_MOVES:,} moves; verify reads at "
                                       f"most {MAX_MOVES:,}")
    return ProgramMoves.from_columns(source, columns)
