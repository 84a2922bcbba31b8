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
    STAGING_MARK,
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


def test_without_a_manifest_only_the_new_sets_names_are_overwritten(tmp_path):
    """Files of our names in a folder without a manifest (an older version's set, or the user's own files that
    happen to have such names) are not taken for a set: nothing but the new set's names is overwritten."""
    out = tmp_path / "out"
    out.mkdir()
    for name in ("roughing.ngc", "finishing.ngc", "roughing.txt", "finishing.md", "notes.txt"):
        (out / name).write_bytes(b"old")
    (out / ".finishing.ngc.abc123.tmp").write_bytes(b"half")  # a stray of an old writer: not ours to judge
    write_output_set(out, {"roughing.nc": b"new", "finishing.ngc": b"new f"})
    assert listing(out)[0] == {"roughing.nc": b"new", "finishing.ngc": b"new f", "roughing.ngc": b"old",
                               "roughing.txt": b"old", "finishing.md": b"old", "notes.txt": b"old",
                               ".finishing.ngc.abc123.tmp": b"half"}


def test_a_folder_in_the_way_is_found_before_anything_changes(tmp_path):
    out = tmp_path / "out"
    write_output_set(out, {"gear.step": b"old a", "stock.step": b"old b"})
    (out / "job.step").mkdir()
    with pytest.raises(OutputError, match="job.step"):
        write_output_set(out, {"gear.step": b"new a", "stock.step": b"new b", "job.step": b"new c"})
    assert listing(out) == ({"gear.step": b"old a", "stock.step": b"old b"}, ["job.step"])


def test_failure_while_staging_leaves_the_old_set(tmp_path):
    out = tmp_path / "out"
    write_output_set(out, {"gear.step": b"old a"})

    with pytest.raises(TypeError):
        write_output_set(out, {"gear.step": b"new a", "stock.step": object()})  # the second file cannot be written
    assert listing(out) == ({"gear.step": b"old a"}, [])


def test_an_interrupted_switch_is_completed_by_the_next_run(tmp_path):
    """A journal and a half-moved staging folder, as SIGKILL during the switch leaves them."""
    out = tmp_path / "out"
    write_output_set(out, {"gear.step": b"old a", "finishing.ngc": b"old"})
    staging = out / (STAGING_PREFIX + "abcd1234")
    staging.mkdir(mode=0o700)  # as the writer makes it: mode 0700, its mark first
    staging.chmod(0o700)
    (staging / STAGING_MARK).write_bytes(b"")
    (staging / "stock.step").write_bytes(b"new b")
    (staging / MANIFEST).write_text(json.dumps(["gear.step", "stock.step"]))
    (out / "gear.step").write_bytes(b"new a")  # already moved before the kill
    (out / JOURNAL).write_text(json.dumps({"staging": staging.name, "new": ["gear.step", "stock.step"],
                                           "old": ["finishing.ngc", "gear.step"]}))
    recover(out)
    assert listing(out) == ({"gear.step": b"new a", "stock.step": b"new b"}, [])
    assert current_set(out) == ["gear.step", "stock.step"]


def test_a_killed_writer_leaves_the_old_set_and_no_strays_after_the_next_run(tmp_path):
    """A child process stages a large set and is killed while staging; the old set stays, and the next
    run removes what the child left."""
    out = tmp_path / "out"
    write_output_set(out, {"gear.step": b"old a"})
    code = textwrap.dedent(f"""
        import sys
        from spur_cad.outputs import write_output_set
        big = b"x" * (200 * 1024 * 1024)
        names = ["profile.csv", "profile.png", "stock.step", "job.step", "report.html", "summary.json",
                 "roughing.ngc", "finishing.ngc", "verify.json", "deviation_map.csv", "grade.json", "k_chart.png"]
        write_output_set({str(out)!r}, {{name: big for name in names}})
    """)
    child = subprocess.Popen([sys.executable, "-c", code])
    deadline = time.time() + 60
    while time.time() < deadline and not any(p.name.startswith(STAGING_PREFIX) for p in out.iterdir()):
        time.sleep(0.01)
    time.sleep(0.3)
    child.kill()
    child.wait()
    files, folders = listing(out)
    assert files == {"gear.step": b"old a"}
    assert len(folders) == 1 and folders[0].startswith(STAGING_PREFIX)  # the kill left its staging folder
    write_output_set(out, {"stock.step": b"new b"})
    assert listing(out) == ({"stock.step": b"new b"}, [])


def test_concurrent_runs_do_not_mix_sets(tmp_path):
    out = tmp_path / "out"
    code = textwrap.dedent("""
        import sys
        from spur_cad.outputs import write_output_set
        tag = sys.argv[1].encode()
        names = {"a": ["gear.step", "stock.step", "job.step"], "b": ["roughing.nc", "finishing.nc", "report.html"]}
        for _ in range(30):
            write_output_set(sys.argv[2], {name: tag * 1000 for name in names[sys.argv[1]]} | {"summary.json": tag})
    """)
    children = [subprocess.Popen([sys.executable, "-c", code, tag, str(out)]) for tag in ("a", "b")]
    for child in children:
        assert child.wait(timeout=120) == 0
    files = listing(out)[0]
    tag = files["summary.json"].decode()
    expected = {"a": ["gear.step", "stock.step", "job.step"], "b": ["roughing.nc", "finishing.nc", "report.html"]}
    assert sorted(files) == sorted(expected[tag] + ["summary.json"])
    assert all(content == tag.encode() * 1000 for name, content in files.items() if name != "summary.json")


@pytest.mark.parametrize("name", ["../evil", "a.txt", "sub/gear.step", "/tmp/gear.step", "gear.step\n", ""])
def test_rejects_names_outside_the_vocabulary(tmp_path, name):
    with pytest.raises(ValueError):
        write_output_set(tmp_path, {name: b""})


def test_an_out_that_is_a_file_is_refused(tmp_path):
    target = tmp_path / "file"
    target.write_text("x")
    with pytest.raises(OutputError, match="not a folder"):
        write_output_set(target, {"gear.step": b"a"})


def test_single_file_replaced_atomically(tmp_path):
    path = write_file_atomically(tmp_path / "d" / "record.json", b"{}")
    assert path.read_bytes() == b"{}" and os.listdir(tmp_path / "d") == ["record.json"]


def test_every_name_a_run_writes_is_in_the_vocabulary():
    """The vocabulary the folder's manifest is checked against holds every program name the posts can give
    (each dialect's extension, the lathe's, the restart programs' labels); a name outside it would make
    write_output_set refuse our own set."""
    from spur_cad.cam.restart import parse_restart
    from spur_cad.dialects import DIALECTS
    from spur_cad.outputs import is_output_name

    extensions = {d.extension for d in DIALECTS.values()}  # every program's: milling, lathe and probing
    assert extensions == {"ngc", "nc", "mpf", "min"}
    for extension in extensions:
        for stem in ("roughing", "roughing_bottom", "finishing", "blank", "probe"):
            assert is_output_name(f"{stem}.{extension}"), (stem, extension)
        for point in ("roughing:space=5", "roughing:space=5,level=2", "finishing:station=40",
                      "finishing:space=3,pass=7", "roughing_bottom:space=22,level=9999999"):
            assert is_output_name(f"{parse_restart(point).label()}.{extension}"), point
    for name in ("../roughing.ngc", "roughing.txt", "finishing.md", ".spur_cad-set.json", "gear.step/x",
                 "roughing.ngc\n", "roughing_space5.ngc.bak"):
        assert not is_output_name(name), name


def test_a_staging_folder_being_made_by_a_run_holding_the_lock_is_not_refused_as_foreign(tmp_path):
    """Found under load: the early check of --out (before a run computes) read another run's staging folder
    between its mkdir and its mark and refused the folder as not ours. While the folder's lock is held the
    early check leaves the bookkeeping alone (the write checks it under the lock); an idle folder holding the
    same markless staging folder is still refused."""
    import fcntl

    from spur_cad.outputs import STAGING_PREFIX, ForeignFileError, check_output_folder

    out = tmp_path / "out"
    out.mkdir()
    os.mkdir(out / f"{STAGING_PREFIX}0123abcd", 0o700)  # as _new_staging leaves it before writing the mark
    holder = os.open(out, os.O_RDONLY)
    try:
        fcntl.flock(holder, fcntl.LOCK_EX)  # another run, mid-write
        assert check_output_folder(out) == out
    finally:
        os.close(holder)
    with pytest.raises(ForeignFileError, match="mark"):
        check_output_folder(out)
