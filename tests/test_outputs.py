"""Atomic output writing: all or nothing."""

from __future__ import annotations

import pytest

from spur_cad.outputs import write_files_atomically


class Exploding(bytes):
    """Content whose write fails, to simulate a full disk in the middle of staging."""


def test_failure_while_staging_leaves_destination_untouched(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_bytes(b"old a")
    import os

    real_fdopen = os.fdopen
    calls = {"n": 0}

    def fdopen(fd, mode):
        calls["n"] += 1
        if calls["n"] == 2:
            os.close(fd)
            raise OSError(28, "No space left on device")
        return real_fdopen(fd, mode)

    monkeypatch.setattr(os, "fdopen", fdopen)
    with pytest.raises(OSError):
        write_files_atomically(out, {"a.txt": b"new a", "b.txt": b"new b"})
    assert (out / "a.txt").read_bytes() == b"old a"
    assert sorted(p.name for p in out.iterdir()) == ["a.txt"]


def test_writes_all_files(tmp_path):
    paths = write_files_atomically(tmp_path / "new" / "dir", {"x.csv": b"1", "y.json": b"{}"})
    assert [p.read_bytes() for p in paths] == [b"1", b"{}"]


def test_rejects_path_like_names(tmp_path):
    with pytest.raises(ValueError):
        write_files_atomically(tmp_path, {"../evil": b""})
