"""Run G-code through LinuxCNC's standalone interpreter `rs274` (package linuxcnc-uspace).

Found on Debian 12 (LinuxCNC 2.9.0~pre1): `rs274 -g prog.ngc canon.txt` interprets the whole
program in batch mode (`-g`) and writes one canonical call per line, e.g.
`   14 N..... STRAIGHT_FEED(10.0000, 0.0000, 1.0000, 45.0000, 0.0000, 0.0000)` (X Y Z A B C).
Without `-g` it shows an interactive menu on stdin. On an error it stops, exits with status 1
and prints the message and the offending block on stderr (e.g. "Unknown g code used" then
"G7.7"); a program without M2/M30 or `%` is an error too. stderr always starts with a line
"executing". Without `-t` it uses a built-in tool table; tool table values are read in inches
(a Z50 offset comes out as 1270 mm under G21).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

RS274_CANDIDATES = ("/usr/bin/rs274", "/usr/lib/linuxcnc/bin/rs274", "/usr/local/bin/rs274")
_CANON_PREFIX = re.compile(r"^\s*\d+\s+N\S*\s+")


def rs274_path() -> str | None:
    """Path of the `rs274` executable ($RS274, then PATH, then Debian locations), or None."""
    override = os.environ.get("RS274")
    if override:
        return override if os.access(override, os.X_OK) else None
    found = shutil.which("rs274")
    if found:
        return found
    for candidate in RS274_CANDIDATES:
        if os.access(candidate, os.X_OK):
            return candidate
    return None


def run_rs274(path: str | os.PathLike, tool_table: str | os.PathLike | None = None,
              timeout_s: float = 120.0) -> tuple[bool, list[str], str]:
    """Interpret the G-code file `path`; return (ok, canonical calls, interpreter messages).

    Canonical lines have the line counter and `N.....` prefix removed, e.g.
    `STRAIGHT_FEED(10.0000, 0.0000, 1.0000, 45.0000, 0.0000, 0.0000)`. `ok` is the exit
    status being 0; `messages` is stdout and stderr without the "executing" banner.
    """
    executable = rs274_path()
    if executable is None:
        raise FileNotFoundError("rs274 not found (install linuxcnc-uspace or set $RS274)")
    with tempfile.TemporaryDirectory(prefix="rs274-") as work:
        canon_file = Path(work) / "canon.txt"
        cmd = [executable]
        if tool_table is not None:
            cmd += ["-t", str(Path(tool_table).resolve())]
        cmd += ["-g", str(Path(path).resolve()), str(canon_file)]
        proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              cwd=work, timeout=timeout_s)
        raw = canon_file.read_text() if canon_file.exists() else ""
    canon_lines = [_CANON_PREFIX.sub("", line) for line in raw.splitlines() if line.strip()]
    messages = "\n".join(line for line in (proc.stdout + proc.stderr).splitlines()
                         if line.strip() != "executing")
    return proc.returncode == 0, canon_lines, messages


def canon_args(line: str) -> list[float]:
    """Numbers inside a canonical call, e.g. STRAIGHT_FEED(1.0, 2.0, ...) -> [1.0, 2.0, ...]."""
    inner = line[line.index("(") + 1:line.rindex(")")]
    return [float(part) for part in re.split(r"[,\s]+", inner.strip()) if part]
