"""Opening the files a user names (job files, programs, measured points): only regular files, read in
bounded pieces. A FIFO would block the open or the read forever, a device such as /dev/zero never ends,
a folder cannot be read: each is refused with one line naming the file, before anything is read."""

from __future__ import annotations

import datetime
import os
import re
import stat
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

from spur_cad.errors import SpurCadError, shown, shown_path

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a device"),
          (stat.S_ISBLK, "a device"), (stat.S_ISSOCK, "a socket"))


def open_regular_file(path: str | os.PathLike, what: str, error: type[SpurCadError] = SpurCadError,
                      name: str | None = None) -> BinaryIO:
    """`path` opened for binary reading if it is a regular file (a link to one is fine); else `error` with
    one line: '<name>: <what> not found' / 'is a FIFO (named pipe), not a regular file' / 'cannot read ...'.
    `name`: how messages name the file (default: `path`, shown)."""
    name = shown_path(path) if name is None else name
    try:
        # O_NONBLOCK: opening a FIFO does not wait for a writer; the kind is then checked on what was opened
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
    except FileNotFoundError:
        raise error(f"{name}: {what} not found") from None
    except (OSError, ValueError) as exc:
        raise error(f"{name}: cannot read the {what}: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = next((label for test, label in _KINDS if test(mode)), "not a regular file")
            raise error(f"{name}: the {what} is {kind}, not a regular file")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular_file(path: str | os.PathLike, what: str, max_bytes: int,
                      error: type[SpurCadError] = SpurCadError, name: str | None = None) -> bytes:
    """The bytes of a regular file of at most `max_bytes` (refused with its size beyond, before reading).
    `name`: how messages name the file (default: `path`, shown)."""
    name = shown_path(path) if name is None else name
    with open_regular_file(path, what, error, name) as handle:
        size = os.fstat(handle.fileno()).st_size
        if size > max_bytes:
            raise error(f"{name}: the {what} has {size:,} bytes; at most {max_bytes:,} are read")
        try:
            data = handle.read(max_bytes + 1)
        except OSError as exc:
            raise error(f"{name}: cannot read the {what}: {exc.strerror or exc}") from None
    if len(data) > max_bytes:  # it grew while being read
        raise error(f"{name}: the {what} has more than {max_bytes:,} bytes; at most {max_bytes:,} are read")
    return data


def side_file_path(name: str, folders: Sequence[str | os.PathLike], what: str,
                   error: type[SpurCadError] = SpurCadError) -> Path:
    """Where a file a job names beside itself ([job] report_template, [machine] rotary_calibration_file, ...) is
    read: `name`, relative, looked up in each of `folders` in turn (the job file's folder first, then those the
    user named: `--side-files`, the workbench's document folder), the first where it exists. Links and `..` are
    followed, and the file they reach must lie inside one of `folders` (each with its own links resolved): an
    absolute name, or one that leads out of them, is refused with one line whatever the file holds, so that a
    job file from elsewhere cannot make a run read (and put into its report) any other file on the machine."""
    shown_name = shown(name)
    if not name or os.path.isabs(name):
        raise error(f"{shown_name} is {'an absolute path' if name else 'empty'}: a {what} is named relative to "
                    "the job file's folder, and must lie in it (or in a folder given with --side-files)")
    try:
        roots = [Path(folder).resolve() for folder in folders]
        candidates = [(root / name).resolve() for root in roots]
    except (OSError, RuntimeError, ValueError) as exc:  # a loop of links, a name too long
        raise error(f"{shown_name}: cannot find the {what}: {getattr(exc, 'strerror', None) or exc}") from None
    for candidate in candidates:
        if not any(candidate.is_relative_to(root) for root in roots):
            allowed = " or ".join(shown_path(root) for root in roots)
            raise error(f"{shown_name} leads outside the job file's folder (to {shown_path(candidate)}): a {what} "
                        f"must lie in {allowed}; name another folder with --side-files")
        if os.path.lexists(candidate):
            return candidate
    return candidates[0]


def step_timestamp(environment: Mapping[str, str]) -> str | None:
    """The STEP headers' time from SOURCE_DATE_EPOCH (seconds since 1970, the reproducible-builds
    convention), as 'YYYY-MM-DDTHH:MM:SS' UTC; None when it is not set (OCCT then writes its clock). A value
    that is no such number is refused with one line: numpy's f2py, which scipy imports, would otherwise fail
    on it at import with a traceback, so the CLI checks it before anything heavy is imported."""
    text = environment.get("SOURCE_DATE_EPOCH")
    if text is None:
        return None
    if not re.fullmatch(r"[0-9]{1,11}", text.strip()):
        raise SpurCadError(f"SOURCE_DATE_EPOCH must be a whole number of seconds since 1970, got {shown(text)}")
    moment = datetime.datetime.fromtimestamp(int(text.strip()), tz=datetime.timezone.utc)
    return moment.strftime("%Y-%m-%dT%H:%M:%S")
