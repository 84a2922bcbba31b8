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
