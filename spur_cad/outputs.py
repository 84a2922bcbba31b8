"""The one place that writes files: all outputs of a run are staged, then renamed into place.

Each file is written to a temporary name in the destination folder and fsync'ed; only when
every file has been staged are they renamed (atomic per file on POSIX). A failure while
staging removes the temporaries and leaves the destination untouched.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def write_files_atomically(out_dir: str | Path, files: dict[str, bytes]) -> list[Path]:
    """Write `files` (name -> content) into `out_dir`, creating it if needed; returns the paths."""
    out = Path(out_dir)
    for name in files:
        if Path(name).name != name or name in {"", ".", ".."}:
            raise ValueError(f"output names must be plain file names, got {name!r}")
    out.mkdir(parents=True, exist_ok=True)
    staged: list[tuple[str, Path]] = []
    try:
        for name, content in files.items():
            fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=out)
            staged.append((tmp, out / name))
            with os.fdopen(fd, "wb") as handle:
                handle.write(content)
                handle.flush()
                os.fsync(handle.fileno())
    except BaseException:
        for tmp, _ in staged:
            Path(tmp).unlink(missing_ok=True)
        raise
    for tmp, final in staged:
        os.chmod(tmp, 0o644)
        os.replace(tmp, final)
    return [final for _, final in staged]
