"""The one place that writes files. A run's outputs form a set: the output folder holds the complete
old set or the complete new set, never a mixture, and no leftovers of ours (docs/output-folder.md).

How (all inside the output folder, so on one filesystem):

1. A lock (flock on the folder itself) serialises runs into the same folder: a second run waits.
2. Recovery of an interrupted earlier run: a journal (`.spur_cad-switching.json`) means a switch was
   under way, and it is completed; then our staging folders (`.spur_cad-staging-XXXXXXXX`) are removed.
3. Checks before anything changes: a target name that is a folder (or not a regular file) is an
   error naming it.
4. Staging: every file, and the journal and manifest to come, is written and fsync'ed in a fresh
   staging folder; an error or interrupt here removes the staging folder and leaves the old set.
5. Switch: the journal is renamed into place, then every staged file, the old set's files that the
   new set lacks are removed, the manifest (`.spur_cad-set.json`, the names of the current set) is
   renamed into place, and the journal and the staging folder are removed. SIGINT and SIGTERM are held
   back during the switch (milliseconds), so only SIGKILL or a power cut can stop it half-way; the
   journal then tells (and the next run completes the switch first).

Every file found in the folder is untrusted input, our own manifest and journal included (an output
folder may be a shared folder or a colleague's unpacked archive). They are read only if they are
regular files of a bounded size, and every name in them must be a plain file name of the set's own
vocabulary (`Vocabulary`: spur_cad's fixed names, and the program names with the extensions of the dialects
of the run's registry, spur_cad.dialects) and the staging folder a direct child with the staging prefix; anything
else is refused (ForeignFileError: "... was not written by spur_cad: remove it or choose another
folder") before anything is touched. Only files a validated manifest or journal lists are ever
removed, and only the new set's names are overwritten: the user's own files are never touched.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import functools
import json
import os
import re
import secrets
import signal
import stat
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from spur_cad.dialects import program_extensions
from spur_cad.errors import SpurCadError, shown_path

MANIFEST = ".spur_cad-set.json"
JOURNAL = ".spur_cad-switching.json"
STAGING_PREFIX = ".spur_cad-staging-"
STAGING_MARK = ".spur_cad-staging"  # the first file of every staging folder: a folder without it is not ours
LOCK_WAIT_S = 60.0  # another run holds the folder's lock for the milliseconds of its switch; longer is not a run
MAX_BOOKKEEPING_BYTES = 64 * 1024  # a manifest or journal lists a few dozen names
_OPERATION = r"(roughing|roughing_bottom|finishing)"
_EXTENSION = re.compile(r"[a-z0-9]{1,8}", re.ASCII)  # what a dialect's program extension may be here


@dataclass(frozen=True)
class Vocabulary:
    """The vocabulary of output sets: every name spur_cad writes into an output folder, the programs' with the
    extensions of a dialect registry's programs (milling, lathe, probing: `program_extensions(dialects)`; the
    default registry's unless a run gives another)."""

    program_extensions: tuple[str, ...] = program_extensions()

    def __post_init__(self) -> None:
        if not self.program_extensions or not all(isinstance(e, str) and _EXTENSION.fullmatch(e)
                                                  for e in self.program_extensions):
            raise ValueError(f"program extensions must be 1 to 8 lower-case letters or digits, got "
                             f"{self.program_extensions!r}")

    def matches(self, name: object) -> bool:
        """True for a plain file name of the vocabulary (no separator, no '..', no control character)."""
        return isinstance(name, str) and _output_name(self.program_extensions).fullmatch(name) is not None


@functools.cache
def _output_name(extensions: tuple[str, ...]) -> re.Pattern:
    """The vocabulary's names for these program extensions, as one regular expression (fullmatch)."""
    program = f"({'|'.join(extensions)})"
    return re.compile(
        r"profile\.(csv|png)|(gear|stock|job)\.step|report\.html|summary\.json"  # spur-cad run
        r"|gear\.(dxf|svg)"  # [export]
        rf"|{_OPERATION}\.{program}|(blank|probe)\.{program}"  # programs
        rf"|{_OPERATION}_(space|station)\d{{1,7}}(_(level|pass)\d{{1,7}})?\.{program}"  # restart programs
        r"|verify\.json|deviation_map\.csv"  # spur-cad verify
        r"|grade\.json|k_chart\.png"  # spur-cad grade
        r"|correction\.json|a_axis\.comp",  # spur-cad correct (with the corrected programs)
        re.ASCII)  # digits are 0-9 only


VOCABULARY = Vocabulary()
"""The default registry's vocabulary (spur_cad.dialects.DIALECTS)."""
STAGING_NAME = re.compile(re.escape(STAGING_PREFIX) + r"[a-z0-9_]{8}", re.ASCII)  # 8 random characters (hex
# since issue 33; tempfile.mkdtemp's alphabet before)


class OutputError(SpurCadError, OSError):
    """The output folder cannot take the set (a name in the way, no permission); nothing was changed."""


class ForeignFileError(OutputError):
    """A file in the output folder that looks like spur_cad's bookkeeping but was not written by spur_cad
    (or was changed since): nothing is touched; the user removes it or chooses another folder."""


@dataclass(frozen=True)
class Journal:
    """A switch under way: the staging folder's name, the new set's names and the old set's names."""

    staging: str
    new: tuple[str, ...]
    old: tuple[str, ...]

    def to_json(self) -> bytes:
        return json.dumps({"staging": self.staging, "new": list(self.new), "old": list(self.old)}).encode()


def check_output_folder(out_dir: str | os.PathLike, vocabulary: Vocabulary = VOCABULARY) -> Path:
    """Refuse, before any computation, an --out that is not a folder, a symbolic link to nothing, a name
    the system refuses (too long), or a place that cannot be created or written (a manifest or journal
    naming anything outside `vocabulary` is foreign)."""
    out = Path(out_dir)
    try:
        if any(len(os.fsencode(part)) > 255 for part in out.parts):
            raise OutputError(f"--out {shown_path(out)}: a folder name is longer than 255 bytes")
        if out.is_symlink() and not out.exists():
            raise OutputError(f"--out {shown_path(out)}: a symbolic link to nothing ({shown_path(os.readlink(out))})")
        if out.exists() and not out.is_dir():
            raise OutputError(f"--out {shown_path(out)}: exists and is not a folder")
        existing = next((p for p in (out, *out.parents) if p.exists()), Path("."))
        if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
            raise OutputError(f"--out {shown_path(out)}: cannot write into {shown_path(existing)}")
        if out.is_dir():  # a foreign manifest or journal is refused now, not after the run
            with _opened(out) as folder:
                if _try_lock(folder):  # busy: another run's staging folder may be half made; checked when writing
                    _check_bookkeeping(out, folder, vocabulary)
    except OutputError:
        raise
    except (OSError, ValueError) as exc:  # a path too long for the system, a NUL byte, ...
        raise OutputError(f"--out {shown_path(out)}: {getattr(exc, 'strerror', None) or exc}") from None
    return out


def is_output_name(name: str, vocabulary: Vocabulary = VOCABULARY) -> bool:
    """True for a plain file name of the output sets' vocabulary (no separator, no '..', no control character)."""
    return vocabulary.matches(name)


def write_output_set(out_dir: str | os.PathLike, files: dict[str, bytes],
                     checkpoint: Callable[[], None] | None = None, vocabulary: Vocabulary = VOCABULARY) -> list[Path]:
    """Replace the set in `out_dir` (created if needed) by `files` (name -> content; names of `vocabulary`);
    returns the paths. Raises OutputError (ForeignFileError for a file not ours) with nothing changed.

    Every operation is relative to descriptors of the output folder and of our staging folder, opened once
    (without following links): a name in the folder swapped for a link while the set is written cannot
    redirect a write, a move or a removal to another folder."""
    for name in files:
        if not vocabulary.matches(name):
            raise ValueError(f"output names must be plain file names of the output vocabulary, got {name!r}")
    out = check_output_folder(out_dir, vocabulary)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"--out {shown_path(out)}: cannot create it: {exc.strerror or exc}") from None
    with _locked(out, checkpoint) as folder:
        _recover(out, folder, vocabulary)
        old = _read_manifest(out, folder, vocabulary)
        for name in files:
            if _in_the_way(folder, name):
                raise OutputError(f"--out {shown_path(out)}: {name} is in the way (a folder or special file); "
                                  "nothing was written")
        staging_name, staging = _new_staging(folder)
        journal = Journal(staging_name, tuple(sorted(files)), tuple(sorted(old)))
        try:
            try:
                for name, content in files.items():
                    _write_synced(staging, name, content)
                _write_synced(staging, JOURNAL, journal.to_json())
                _write_synced(staging, MANIFEST, json.dumps(list(journal.new)).encode())
                os.fsync(staging)
            except BaseException:
                _remove_staging(folder, staging_name, staging, vocabulary)  # our own fresh folder
                raise
            with _signals_held():
                os.replace(JOURNAL, JOURNAL, src_dir_fd=staging, dst_dir_fd=folder)
                os.fsync(folder)
                _switch(folder, journal, staging, vocabulary)
        finally:
            os.close(staging)
    return [out / name for name in files]


def write_file_atomically(path: str | os.PathLike, content: bytes) -> Path:
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


def recover(out: Path, vocabulary: Vocabulary = VOCABULARY) -> None:
    """Complete a switch an earlier run left half-done, then remove our staging folders. Everything is
    validated first (ForeignFileError, nothing touched, when a file is not ours)."""
    with _locked(out) as folder:
        _recover(out, folder, vocabulary)


def _recover(out: Path, folder: int, vocabulary: Vocabulary) -> None:
    journal, strays = _check_bookkeeping(out, folder, vocabulary)
    if journal is not None:
        _switch(folder, journal, None, vocabulary)
    for name in strays:
        _remove_staging(folder, name, vocabulary=vocabulary)


def _check_bookkeeping(out: Path, folder: int, vocabulary: Vocabulary) -> tuple[Journal | None, list[str]]:
    """The journal (None without one) and the names of stray staging folders, every one of them validated with
    the manifest (ForeignFileError when a file is not ours); nothing is changed."""
    journal = _read_journal(out, folder, vocabulary)
    strays = [entry for entry in sorted(os.listdir(folder)) if STAGING_NAME.fullmatch(entry) and
              (journal is None or entry != journal.staging)]
    if journal is not None:
        blocked = [name for name in journal.new if _in_the_way(folder, name)]
        if blocked:
            raise OutputError(f"--out {shown_path(out)}: {blocked[0]} is in the way (a folder or special file) of "
                              "an interrupted switch that the journal asks to complete; remove it")
    for name in [*strays, *([journal.staging] if journal is not None else [])]:
        staging = _open_staging(out, folder, name)
        if staging is not None:
            try:
                _check_staging(out / name, staging, vocabulary)
            finally:
                os.close(staging)
    _read_manifest(out, folder, vocabulary)
    return journal, strays


def current_set(out_dir: str | os.PathLike, vocabulary: Vocabulary = VOCABULARY) -> list[str]:
    """Names of the set the folder holds (from its validated manifest; [] when it holds none)."""
    out = Path(out_dir)
    if not out.is_dir():
        return []
    with _opened(out) as folder:
        return sorted(_read_manifest(out, folder, vocabulary))


def _foreign(path: Path, reason: str) -> ForeignFileError:
    return ForeignFileError(f"{shown_path(path)} was not written by spur_cad ({reason}): remove it or choose "
                            "another folder")


def _read_bookkeeping(path: Path, folder: int) -> object | None:
    """The JSON of our manifest or journal (None when absent), read only from a regular file of bounded size."""
    try:
        fd = os.open(path.name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, dir_fd=folder)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise _foreign(path, "a symbolic link" if exc.errno == errno.ELOOP else
                       f"cannot read it: {exc.strerror or exc}") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise _foreign(path, "not a regular file")
    with os.fdopen(fd, "rb") as handle:
        raw = handle.read(MAX_BOOKKEEPING_BYTES + 1)
    if len(raw) > MAX_BOOKKEEPING_BYTES:
        raise _foreign(path, f"larger than {MAX_BOOKKEEPING_BYTES // 1024} KiB")
    try:
        return json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        raise _foreign(path, "not the JSON spur_cad writes") from None


def _names(value: object, path: Path, what: str, vocabulary: Vocabulary) -> tuple[str, ...]:
    if not isinstance(value, list):
        raise _foreign(path, f"{what} is not a list of names")
    for name in value:
        if not vocabulary.matches(name):
            shown = shown_path(name) if isinstance(name, str) else type(name).__name__
            raise _foreign(path, f"{what} names {shown!s}, not a file of an output set")
    return tuple(value)


def _read_manifest(out: Path, folder: int, vocabulary: Vocabulary) -> set[str]:
    """The current set's names from the manifest; the empty set without one (files of older versions that kept
    no manifest are left alone: they are overwritten only where the new set has the same name)."""
    path = out / MANIFEST
    data = _read_bookkeeping(path, folder)
    return set() if data is None else set(_names(data, path, "the manifest", vocabulary))


def _read_journal(out: Path, folder: int, vocabulary: Vocabulary) -> Journal | None:
    path = out / JOURNAL
    data = _read_bookkeeping(path, folder)
    if data is None:
        return None
    if not isinstance(data, dict) or set(data) != {"staging", "new", "old"}:
        raise _foreign(path, "not a journal of staging, new and old names")
    staging = data["staging"]
    if not isinstance(staging, str) or STAGING_NAME.fullmatch(staging) is None:
        raise _foreign(path, "its staging folder is not one of spur_cad's in this folder")
    return Journal(staging, _names(data["new"], path, "its new set", vocabulary),
                   _names(data["old"], path, "its old set", vocabulary))


def _open_child_folder(folder: int, name: str) -> int:
    """A descriptor of the folder `name` inside `folder`, opened without following a link (OSError otherwise)."""
    return os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=folder)


def _open_staging(out: Path, folder: int, name: str) -> int | None:
    """A staging folder opened without following a link (None when it is gone); ForeignFileError for a link or
    anything but a folder."""
    try:
        return _open_child_folder(folder, name)
    except FileNotFoundError:
        return None
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.ENOTDIR):
            raise _foreign(out / name, "not a folder") from None
        raise


def _ours(entry: os.DirEntry, vocabulary: Vocabulary) -> bool:
    return entry.is_file(follow_symlinks=False) and (vocabulary.matches(entry.name) or
                                                     entry.name in (MANIFEST, JOURNAL, STAGING_MARK))


def _check_staging(path: Path, staging: int, vocabulary: Vocabulary) -> None:
    """A staging folder must be one we made (ours by owner, mode 0700 and its mark) and hold only regular files
    of our names: a user's folder renamed to the staging pattern is not emptied."""
    info = os.fstat(staging)
    if info.st_uid != os.geteuid() or stat.S_IMODE(info.st_mode) != 0o700:
        raise _foreign(path, "not a folder spur_cad made: another owner or mode")
    entries = list(os.scandir(staging))
    if STAGING_MARK not in {entry.name for entry in entries}:
        raise _foreign(path, f"no {STAGING_MARK} mark")
    for entry in entries:
        if not _ours(entry, vocabulary):
            raise _foreign(path / entry.name, "not a file of an output set")


def _new_staging(folder: int) -> tuple[str, int]:
    """A fresh staging folder of ours (mode 0700, the prefix and eight random characters): its name and a
    descriptor, opened without following a link."""
    while True:
        name = STAGING_PREFIX + secrets.token_hex(4)
        try:
            os.mkdir(name, 0o700, dir_fd=folder)
        except FileExistsError:
            continue
        staging = _open_child_folder(folder, name)
        try:
            os.fchmod(staging, 0o700)  # whatever the umask
            _write_synced(staging, STAGING_MARK, b"")
        except BaseException:
            os.close(staging)
            raise
        return name, staging


def _remove_staging(folder: int, name: str, staging: int | None = None,
                    vocabulary: Vocabulary = VOCABULARY) -> None:
    """Remove a staging folder of ours: the regular files of our names in it, then the folder. Relative to its
    descriptor (`staging`, or opened here without following a link and checked again as ours on that very
    descriptor): a link or a user's folder put in its place meanwhile is never emptied. What cannot be removed
    is left for the next run (which removes it, or refuses it when it is not ours)."""
    opened = staging is None
    if opened:
        try:
            staging = _open_child_folder(folder, name)
            _check_staging(Path(name), staging, vocabulary)
        except (OSError, ForeignFileError):
            if staging is not None:
                os.close(staging)
            return
    if staging is None:  # opened above, or given
        return
    try:
        for entry in list(os.scandir(staging)):
            if _ours(entry, vocabulary):
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(entry.name, dir_fd=staging)
    finally:
        if opened:
            os.close(staging)
    with contextlib.suppress(OSError):
        os.rmdir(name, dir_fd=folder)


def _switch(folder: int, journal: Journal, staging: int | None, vocabulary: Vocabulary) -> None:
    """Move the staged files into place, remove the old set's extra files, record the new set (the journal
    and its names were validated). `staging`: the journal's staging folder, opened (None: open it here)."""
    opened = staging is None
    if opened:
        try:
            staging = _open_child_folder(folder, journal.staging)
        except FileNotFoundError:
            staging = None
        if staging is not None:
            try:  # checked again on this very descriptor: the name may have been given to another folder
                _check_staging(Path(journal.staging), staging, vocabulary)
            except BaseException:
                os.close(staging)
                raise
    try:
        _move_in(folder, journal, staging, vocabulary, staged_manifest=not opened)
        os.fsync(folder)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(JOURNAL, dir_fd=folder)
        if staging is not None:
            _remove_staging(folder, journal.staging, staging, vocabulary)
    finally:
        if opened and staging is not None:
            os.close(staging)
    os.fsync(folder)


def _move_in(folder: int, journal: Journal, staging: int | None, vocabulary: Vocabulary, staged_manifest: bool) -> None:
    """The switch's renames and removals, relative to the folders' descriptors. The manifest staged by this run
    is moved in (`staged_manifest`); when completing an earlier run's switch it is written anew from the
    journal's validated names."""
    for name in journal.new:
        if staging is not None and _exists(staging, name):
            try:
                os.replace(name, name, src_dir_fd=staging, dst_dir_fd=folder)
            except (IsADirectoryError, NotADirectoryError, PermissionError) as exc:  # made in its place meanwhile
                raise OutputError(f"{name} is in the way of the switch ({exc.strerror}); the journal "
                                  f"{JOURNAL} lets the next run complete it once {name} is removed") from None
    for name in set(journal.old) - set(journal.new):
        with contextlib.suppress(FileNotFoundError):
            if not stat.S_ISDIR(os.stat(name, dir_fd=folder, follow_symlinks=False).st_mode):
                os.unlink(name, dir_fd=folder)
    if staged_manifest and staging is not None and _exists(staging, MANIFEST):
        os.replace(MANIFEST, MANIFEST, src_dir_fd=staging, dst_dir_fd=folder)
        return
    fresh_name, fresh = _new_staging(folder)
    try:
        _write_synced(fresh, MANIFEST, json.dumps(list(journal.new)).encode())
        os.replace(MANIFEST, MANIFEST, src_dir_fd=fresh, dst_dir_fd=folder)
    finally:
        _remove_staging(folder, fresh_name, fresh, vocabulary)
        os.close(fresh)


def _exists(folder: int, name: str) -> bool:
    try:
        os.stat(name, dir_fd=folder, follow_symlinks=False)
        return True
    except FileNotFoundError:
        return False


def _in_the_way(folder: int, name: str) -> bool:
    """A target name held by a folder, a special file or a link to nothing (a link to a file is replaced)."""
    if not _exists(folder, name):
        return False
    try:
        return not stat.S_ISREG(os.stat(name, dir_fd=folder).st_mode)
    except FileNotFoundError:  # a link to nothing
        return True


def _write_synced(folder: int, name: str, content: bytes) -> None:
    """A new file in `folder` (never through an existing name or link) written and fsync'ed."""
    fd = os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644, dir_fd=folder)
    with os.fdopen(fd, "wb") as handle:
        os.fchmod(fd, 0o644)  # whatever the umask: the set is readable like any other file
        handle.write(content)
        handle.flush()
        os.fsync(handle.fileno())


@contextlib.contextmanager
def _opened(out: Path) -> Iterator[int]:
    """The output folder's descriptor (every operation on its entries is relative to it)."""
    fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        yield fd
    finally:
        os.close(fd)


def _try_lock(folder: int) -> bool:
    """Take the folder's exclusive lock if nobody holds it (released when `folder` is closed); False if held."""
    try:
        fcntl.flock(folder, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


@contextlib.contextmanager
def _locked(out: Path, checkpoint: Callable[[], None] | None = None) -> Iterator[int]:
    """The folder's descriptor, with an exclusive flock on the folder itself (no lock file is left behind).
    Waits up to LOCK_WAIT_S for another holder, calling `checkpoint()` meanwhile (the CLI stops there on a
    signal); a lock held longer is no run of ours (anyone who can read the folder can take it) and is refused."""
    with _opened(out) as fd:
        deadline = time.monotonic() + LOCK_WAIT_S
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if checkpoint is not None:
                    checkpoint()
                if time.monotonic() > deadline:
                    raise OutputError(f"--out {shown_path(out)}: another process has held the folder's lock for "
                                      f"{LOCK_WAIT_S:.0f} s (a spur_cad run holds it for milliseconds); nothing "
                                      "was written") from None
                time.sleep(0.05)
        yield fd  # closing releases the lock


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM wait until the block is done (delivered right after it)."""
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
