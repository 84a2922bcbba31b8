"""The output folder holds a complete old set or a complete new set, never a mixture, and no strays.

Real files and real child processes; the set is compared by names and bytes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time

import pytest

from spur_cad.outputs import (
    JOURNAL,
    MANIFEST,
    STAGING_PREFIX,
    OutputError,
    current_set,
    recover,
    write_file_atomically,
    write_output_set,
)

OURS = {MANIFEST}


def listing(folder):
    """Names and bytes of the files in the folder (our manifest aside), and the names of its sub-folders."""
    files = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file() and p.name not in OURS}
    return files, sorted(p.name for p in folder.iterdir() if p.is_dir())


def test_a_new_set_replaces_the_old_one_whole(tmp_path):
    out = tmp_path / "out"
    write_output_set(out, {"roughing.ngc": b"old r", "finishing.ngc": b"old f", "summary.json": b"{1}"})
    (out / "my notes.txt").write_bytes(b"mine")  # the user's own file
    write_output_set(out, {"roughing.nc": b"new r", "summary.json": b"{2}"})  # other dialect, no finishing
    assert listing(out) == ({"roughing.nc": b"new r", "summary.json": b"{2}", "my notes.txt": b"mine"}, [])
    assert current_set(out) == ["roughing.nc", "summary.json"]


def test_a_set_written_by_an_older_version_is_recognised(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("roughing.ngc", "finishing.ngc", "profile.csv", "notes.txt"):
        (out / name).write_bytes(b"old")
    (out / ".finishing.ngc.abc123.tmp").write_bytes(b"half")  # a stray of the old writer
    write_output_set(out, {"roughing.nc": b"new"})
    assert listing(out) == ({"roughing.nc": b"new", "notes.txt": b"old"}, [])


def test_a_folder_in_the_way_is_found_before_anything_changes(tmp_path):
    out = tmp_path / "out"
    write_output_set(out, {"a.txt": b"old a", "b.txt": b"old b"})
    (out / "c.txt").mkdir()
    with pytest.raises(OutputError, match="c.txt"):
        write_output_set(out, {"a.txt": b"new a", "b.txt": b"new b", "c.txt": b"new c"})
    assert listing(out) == ({"a.txt": b"old a", "b.txt": b"old b"}, ["c.txt"])


def test_failure_while_staging_leaves_the_old_set(tmp_path):
    out = tmp_path / "out"
    write_output_set(out, {"a.txt": b"old a"})

    with pytest.raises(TypeError):
        write_output_set(out, {"a.txt": b"new a", "b.txt": object()})  # the second file cannot be written
    assert listing(out) == ({"a.txt": b"old a"}, [])


def test_an_interrupted_switch_is_completed_by_the_next_run(tmp_path):
    """A journal and a half-moved staging folder, as SIGKILL during the switch leaves them."""
    out = tmp_path / "out"
    write_output_set(out, {"a.txt": b"old a", "old.txt": b"old"})
    staging = out / (STAGING_PREFIX + "x")
    staging.mkdir()
    (staging / "b.txt").write_bytes(b"new b")
    (out / "a.txt").write_bytes(b"new a")  # already moved before the kill
    (out / JOURNAL).write_text(json.dumps({"staging": staging.name, "new": ["a.txt", "b.txt"],
                                           "old": ["a.txt", "old.txt"]}))
    recover(out)
    assert listing(out) == ({"a.txt": b"new a", "b.txt": b"new b"}, [])
    assert current_set(out) == ["a.txt", "b.txt"]


def test_a_killed_writer_leaves_the_old_set_and_no_strays_after_the_next_run(tmp_path):
    """A child process stages a large set and is killed while staging; the old set stays, and the next
    run removes what the child left."""
    out = tmp_path / "out"
    write_output_set(out, {"a.txt": b"old a"})
    code = textwrap.dedent(f"""
        import sys
        from spur_cad.outputs import write_output_set
        big = b"x" * (200 * 1024 * 1024)
        write_output_set({str(out)!r}, {{f"f{{i}}.bin": big for i in range(20)}})
    """)
    child = subprocess.Popen([sys.executable, "-c", code])
    deadline = time.time() + 60
    while time.time() < deadline and not any(p.name.startswith(STAGING_PREFIX) for p in out.iterdir()):
        time.sleep(0.01)
    time.sleep(0.3)
    child.kill()
    child.wait()
    files, folders = listing(out)
    assert files == {"a.txt": b"old a"}
    assert len(folders) == 1 and folders[0].startswith(STAGING_PREFIX)  # the kill left its staging folder
    write_output_set(out, {"b.txt": b"new b"})
    assert listing(out) == ({"b.txt": b"new b"}, [])


def test_concurrent_runs_do_not_mix_sets(tmp_path):
    out = tmp_path / "out"
    code = textwrap.dedent("""
        import sys
        from spur_cad.outputs import write_output_set
        tag = sys.argv[1].encode()
        for _ in range(30):
            write_output_set(sys.argv[2], {f"{sys.argv[1]}-{i}.txt": tag * 1000 for i in range(5)} | {"s.json": tag})
    """)
    children = [subprocess.Popen([sys.executable, "-c", code, tag, str(out)]) for tag in ("a", "b")]
    for child in children:
        assert child.wait(timeout=120) == 0
    names = sorted(listing(out)[0])
    tag = names[0][0]
    assert names == sorted([f"{tag}-{i}.txt" for i in range(5)] + ["s.json"])
    assert (out / "s.json").read_bytes() == tag.encode()


def test_rejects_path_like_names(tmp_path):
    with pytest.raises(ValueError):
        write_output_set(tmp_path, {"../evil": b""})


def test_an_out_that_is_a_file_is_refused(tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        write_output_set(target, {"a.txt": b"a"})


def test_single_file_replaced_atomically(tmp_path):
    path = write_file_atomically(tmp_path / "d" / "record.json", b"{}")
    assert path.read_bytes() == b"{}" and os.listdir(tmp_path / "d") == ["record.json"]
