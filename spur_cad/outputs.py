"""The one place that writes files. A run's outputs form a set: the output folder holds the complete
old set or the complete new set, never a mixture, and no leftovers of ours.

How (all inside the output folder, so on one filesystem):

1. A lock (flock on the folder itself) serialises runs into the same folder: a second run waits.
2. Recovery of an interrupted earlier run: a journal (`.spur_cad-switching.json`) means a switch was
   under way, and it is completed (every file it names is complete in its staging folder); then
   staging folders (`.spur_cad-staging-*`) and temporary files of older versions are removed.
3. Checks before anything changes: a target name that is a folder (or not a regular file) is an
   error naming it.
4. Staging: every file is written and fsync'ed in a fresh staging folder; an error or interrupt
   here removes the staging folder and leaves the old set as it was.
5. Switch: the journal is written atomically, then every staged file is renamed into place, the
   old set's files that the new set lacks are removed, the manifest (`.spur_cad-set.json`, the
   names of the current set) is replaced, and the journal and staging folder are removed. SIGINT
   and SIGTERM are held back during the switch (milliseconds), so only SIGKILL or a power cut can
   stop it half-way; the journal then tells (and the next run completes the switch first).

Files in the folder that never belonged to a set (the user's own) are never touched. Sets written
by versions without a manifest are recognised by spur_cad's output names.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import re
import shutil
import signal
import tempfile
from pathlib import Path

from spur_cad.errors import SpurCadError

MANIFEST = ".spur_cad-set.json"
JOURNAL = ".spur_cad-switching.json"
STAGING_PREFIX = ".spur_cad-staging-"
_OUTPUT_NAME = r"(profile\.(csv|png)|(gear|stock|job)\.step|report\.html|summary\.json|(roughing|finishing)\.[a-z]+)"
_LEGACY_SET = re.compile(_OUTPUT_NAME)  # what older versions wrote (they kept no manifest)
_LEGACY_TEMPORARY = re.compile(rf"\.{_OUTPUT_NAME}\..+\.tmp")  # their staging files


class OutputError(SpurCadError, OSError):
    """The output folder cannot take the set (a name in the way, no permission); nothing was changed."""


def check_output_folder(out_dir: str | Path) -> Path:
    """Refuse, before any computation, an --out that is not a folder or cannot be created or written."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: exists and is not a folder")
    existing = next((p for p in (out, *out.parents) if p.exists()), Path("."))
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out}: cannot write into {existing}")
    return out


def write_output_set(out_dir: str | Path, files: dict[str, bytes]) -> list[Path]:
    """Replace the set in `out_dir` (created if needed) by `files` (name -> content); returns the paths."""
    for name in files:
        if Path(name).name != name or name in {"", ".", ".."} or name.startswith(".spur_cad"):
            raise ValueError(f"output names must be plain file names, got {name!r}")
    out = check_output_folder(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with _locked(out):
        recover(out)
        old = _current_set(out)
        for name in files:
            target = out / name
            if target.is_dir() or (target.exists() and not target.is_file()):
                raise OutputError(f"--out {out}: {name} is in the way (a folder or special file); nothing was written")
        staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=out))
        try:
            for name, content in files.items():
                _write_synced(staging / name, content)
            _sync_folder(staging)
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)
            raise
        journal = {"staging": staging.name, "new": sorted(files), "old": sorted(old)}
        with _signals_held():
            _write_synced(out / (JOURNAL + ".tmp"), json.dumps(journal).encode())
            os.replace(out / (JOURNAL + ".tmp"), out / JOURNAL)
            _sync_folder(out)
            _switch(out, journal)
    return [out / name for name in files]


def write_file_atomically(path: str | Path, content: bytes) -> Path:
    """One file replaced atomically (temporary file in the same folder, fsync, rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(content)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def recover(out: Path) -> None:
    """Complete a switch an earlier run left half-done, then remove staging folders and old temporaries."""
    journal_path = out / JOURNAL
    if journal_path.exists():
        try:
            journal = json.loads(journal_path.read_text())
        except (OSError, ValueError):  # the journal itself was not complete: the switch had not begun
            journal = None
        if journal is not None:
            _switch(out, journal)
        journal_path.unlink(missing_ok=True)
    for entry in out.iterdir():
        if entry.name.startswith(STAGING_PREFIX) and entry.is_dir():
            shutil.rmtree(entry, ignore_errors=True)
        elif entry.name == JOURNAL + ".tmp" or (_LEGACY_TEMPORARY.fullmatch(entry.name) and entry.is_file()):
            entry.unlink(missing_ok=True)


def current_set(out_dir: str | Path) -> list[str]:
    """Names of the set the folder holds (from its manifest; [] when it holds none)."""
    out = Path(out_dir)
    return sorted(_current_set(out)) if out.is_dir() else []


def _current_set(out: Path) -> set[str]:
    manifest = out / MANIFEST
    if manifest.exists():
        try:
            return set(json.loads(manifest.read_text()))
        except (OSError, ValueError):
            pass
    return {p.name for p in out.iterdir() if p.is_file() and _LEGACY_SET.fullmatch(p.name)}


def _switch(out: Path, journal: dict) -> None:
    """Move the staged files into place, remove the old set's extra files, record the new set."""
    staging = out / journal["staging"]
    new = list(journal["new"])
    for name in new:
        if (staging / name).exists():
            os.replace(staging / name, out / name)
    for name in set(journal["old"]) - set(new):
        (out / name).unlink(missing_ok=True)
    _write_synced(out / (MANIFEST + ".tmp"), json.dumps(new).encode())
    os.replace(out / (MANIFEST + ".tmp"), out / MANIFEST)
    _sync_folder(out)
    (out / JOURNAL).unlink(missing_ok=True)
    shutil.rmtree(staging, ignore_errors=True)


def _write_synced(path: Path, content: bytes) -> None:
    with open(path, "wb") as handle:
        handle.write(content)
        handle.flush()
        os.fsync(handle.fileno())
    os.chmod(path, 0o644)


def _sync_folder(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def _locked(out: Path):
    """An exclusive flock on the folder itself (no lock file is left behind)."""
    fd = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


@contextlib.contextmanager
def _signals_held():
    """SIGINT and SIGTERM wait until the block is done (delivered right after it)."""
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
