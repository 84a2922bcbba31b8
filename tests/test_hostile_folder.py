"""Hostile output folders (issue 33): files planted in the output folder, as anyone who can write one file
into a shared folder or an unpacked archive could plant them, never make `spur-cad run` touch anything
outside the folder, delete a user's file, or fail with an internal error.

Every case runs the real CLI in a child process and compares the whole tree around the folder before and
after: a refused case must leave every byte and name as it was; a case that runs must leave the user's
files as they were. The reproducer of the issue (a journal naming another directory as its staging
folder) is the first case.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from spur_cad.outputs import JOURNAL, MANIFEST, STAGING_MARK, STAGING_PREFIX
from tests.tiers import sweep

TIME_LIMIT_S = 180
MEMORY_LIMIT_BYTES = 6 * 1024**3


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, MEMORY_LIMIT_BYTES))


def spur_cad(*args: str | Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "spur_cad.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=TIME_LIMIT_S, preexec_fn=_limits)


@pytest.fixture
def job(small_job: Path) -> Path:
    return small_job


def tree(root: Path) -> dict[str, object]:
    """Every entry under `root` (not following links): file bytes, link targets, folder markers."""
    entries = {}
    for folder, names, files in os.walk(root, followlinks=False):
        for name in names + files:
            path = Path(folder) / name
            key = str(path.relative_to(root))
            if path.is_symlink():
                entries[key] = ("link", os.readlink(path))
            elif path.is_dir():
                entries[key] = ("folder",)
            elif path.is_fifo():
                entries[key] = ("fifo",)
            else:
                entries[key] = ("file", path.read_bytes())
    return entries


def ours_staging(path: Path) -> Path:
    """A staging folder as a killed run leaves it: mode 0700, its mark, owned by this user."""
    path.mkdir()
    path.chmod(0o700)
    (path / STAGING_MARK).write_bytes(b"")
    return path


def check_refused_untouched(result: subprocess.CompletedProcess, before: dict, root: Path, blamed: Path) -> None:
    """Exit 2, exactly one line naming the planted file and saying it is not ours, and nothing changed."""
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"spur-cad: error: {blamed} was not written by spur_cad"), lines[0]
    assert "remove it or choose another folder" in lines[0]
    assert tree(root) == before


@pytest.fixture
def world(tmp_path) -> tuple[Path, Path]:
    """An output folder and, beside it, a victim folder and file of the user's."""
    (tmp_path / "out").mkdir()
    (tmp_path / "victimdir").mkdir()
    (tmp_path / "victimdir" / "precious.txt").write_text("precious")
    (tmp_path / "victim.txt").write_text("victim")
    return tmp_path, tmp_path / "out"


def test_a_journal_naming_another_directory_as_staging_deletes_nothing(job, world):
    """The issue's reproducer: before the fix this run exited 0 and removed victimdir."""
    root, out = world
    (out / JOURNAL).write_text(json.dumps({"staging": str(root / "victimdir"), "new": [], "old": []}))
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, out / JOURNAL)
    assert (root / "victimdir" / "precious.txt").read_text() == "precious"


@pytest.mark.parametrize("journal", sweep([
    {"staging": STAGING_PREFIX + "abcd1234", "new": [], "old": ["../victim.txt"]},  # traversal in the old set
    {"staging": STAGING_PREFIX + "abcd1234", "new": ["../victim.txt"], "old": []},
    {"staging": "../victimdir", "new": [], "old": []},
    {"staging": STAGING_PREFIX + "abcd1234", "new": [], "old": ["/tmp/x/victim.txt"]},
    {"staging": STAGING_PREFIX + "abcd1234", "new": [], "old": ["notes.txt"]},  # a user's name, not ours
    {"staging": STAGING_PREFIX + "abcd1234", "new": []},  # a key missing
    {"staging": 5, "new": [], "old": []},
    {"staging": STAGING_PREFIX + "abcd1234", "new": "ab", "old": []},
    ["not", "a", "journal"],
    "ab",
    7,
], ids=["old-traversal", "new-traversal", "staging-outside", "old-absolute", "old-user-name", "missing-key",
        "staging-number", "new-string", "list", "string", "number"],
    fast=["old-traversal", "staging-outside", "string"]))
def test_a_journal_not_of_our_making_is_refused_with_nothing_touched(job, world, journal):
    root, out = world
    (out / "notes.txt").write_text("mine")
    (out / JOURNAL).write_text(json.dumps(journal))
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, out / JOURNAL)


@pytest.mark.parametrize("manifest", sweep(['"ab"', "5", '["../victim.txt"]', '["a", "b"]', '{"a": 1}', "[1, 2]",
                                            "not json", '["gear.step", null]', '["roughing.txt"]'],
                                           ids=["string", "number", "traversal", "user-names", "object", "numbers",
                                                "not-json", "null", "user-roughing-notes"],
                                           fast=["string", "traversal", "not-json"]))
def test_a_manifest_not_of_our_making_is_refused_with_nothing_touched(job, world, manifest):
    """A manifest that is the JSON string "ab" used to delete the user's files a and b."""
    root, out = world
    for name in ("a", "b", "roughing.txt"):
        (out / name).write_text(f"user's {name}")
    (out / MANIFEST).write_text(manifest)
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, out / MANIFEST)


@pytest.mark.parametrize("kind", sweep(["fifo", "folder", "link-to-file", "dangling-link", "huge"],
                                         fast=["fifo", "link-to-file"]))
@pytest.mark.parametrize("name", [MANIFEST, JOURNAL])
def test_bookkeeping_that_is_no_regular_file_of_ours_is_refused_without_hanging(job, world, name, kind):
    root, out = world
    target = out / name
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "folder":
        target.mkdir()
    elif kind == "link-to-file":
        target.symlink_to(root / "victim.txt")
    elif kind == "dangling-link":
        target.symlink_to(root / "nowhere")
    else:
        target.write_text("[" + '"gear.step", ' * 100_000 + '"gear.step"]')
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, target)


def test_a_staging_folder_that_links_elsewhere_is_refused(job, world):
    root, out = world
    staging = out / (STAGING_PREFIX + "abcd1234")
    staging.symlink_to(root / "victimdir")
    (out / JOURNAL).write_text(json.dumps({"staging": staging.name, "new": ["gear.step"], "old": []}))
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, staging)


@pytest.mark.parametrize("mode, mark", [(0o755, True), (0o700, False)], ids=["mode-755", "no-mark"])
def test_a_users_folder_renamed_to_the_staging_pattern_is_not_emptied(job, world, mode, mark):
    """Renaming a folder needs write access to its parent only: anyone who can write into a shared output folder
    could rename a user's folder of our names to the staging pattern. A folder we did not make (another mode,
    no mark) is refused, its files kept."""
    root, out = world
    folder = out / (STAGING_PREFIX + "abcd1234")
    folder.mkdir()
    folder.chmod(mode)
    for name in ("gear.step", "summary.json") + ((STAGING_MARK,) if mark else ()):
        (folder / name).write_text(f"the user's {name}")
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, folder)


@pytest.mark.parametrize("planted", ["subfolder", "link", "user-file"])
def test_a_stray_staging_folder_holding_what_we_never_write_is_refused(job, world, planted):
    root, out = world
    staging = ours_staging(out / (STAGING_PREFIX + "zz99zz99"))
    (staging / "gear.step").write_bytes(b"half-written")  # what a killed run leaves: ours
    if planted == "subfolder":
        (staging / "photos").mkdir()
        (staging / "photos" / "cat.jpg").write_bytes(b"cat")
        blamed = staging / "photos"
    elif planted == "link":
        (staging / "report.html").symlink_to(root / "victim.txt")
        blamed = staging / "report.html"
    else:
        (staging / "thesis.tex").write_text("years of work")
        blamed = staging / "thesis.tex"
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, blamed)


def test_planted_links_and_user_files_survive_a_run(job, world):
    """The folder runs, and: links planted where we write temporaries write nowhere outside; files of names a
    folder without a manifest may hold (roughing.txt, finishing.md: the user's notes) are not taken for a set;
    a folder of our staging prefix but not our name pattern is the user's. Before the fix roughing.txt and
    finishing.md were deleted and victim.txt truncated through the planted link."""
    root, out = world
    for name in (MANIFEST + ".tmp", JOURNAL + ".tmp"):
        (out / name).symlink_to(root / "victim.txt")
    (out / "roughing.txt").write_text("my roughing notes")
    (out / "finishing.md").write_text("# my finishing notes")
    (out / (STAGING_PREFIX + "My Photos")).mkdir()
    (out / (STAGING_PREFIX + "My Photos") / "cat.jpg").write_bytes(b"cat")
    result = spur_cad("run", job, "--out", out, "--quiet")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    assert (root / "victim.txt").read_text() == "victim"
    assert (root / "victimdir" / "precious.txt").read_text() == "precious"
    assert (out / "roughing.txt").read_text() == "my roughing notes"
    assert (out / "finishing.md").read_text() == "# my finishing notes"
    assert (out / (STAGING_PREFIX + "My Photos") / "cat.jpg").read_bytes() == b"cat"
    written = json.loads((out / MANIFEST).read_text())
    assert "summary.json" in written and all((out / name).is_file() for name in written)
    assert not [p.name for p in out.iterdir() if STAGING_NAME_OF_OURS(p.name)]  # no stray of ours
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [*written, MANIFEST, MANIFEST + ".tmp", JOURNAL + ".tmp", "roughing.txt", "finishing.md",
         STAGING_PREFIX + "My Photos"])


def STAGING_NAME_OF_OURS(name: str) -> bool:  # noqa: N802 - reads as the constant it checks against
    """mkdtemp's names: the prefix and eight characters of [a-z0-9_] (written here independently)."""
    rest = name.removeprefix(STAGING_PREFIX)
    return rest != name and len(rest) == 8 and all(c in "abcdefghijklmnopqrstuvwxyz0123456789_" for c in rest)


@pytest.mark.parametrize("command", ["verify", "grade"])
def test_verify_and_grade_outputs_refuse_a_foreign_manifest_too(job, world, tmp_path, command):
    root, out = world
    (out / MANIFEST).write_text('"ab"')
    (out / "a").write_text("mine")
    other = tmp_path / "input.txt"
    other.write_text("G0 X0\nM30\n" if command == "verify" else "1,2\n")
    before = tree(root)
    check_refused_untouched(spur_cad(command, job, other, "--out", out), before, root, out / MANIFEST)


def test_a_manifest_naming_a_digit_of_another_script_is_refused(job, world):
    """`\\d` in Python's patterns matches any script's digits: `roughing_space٣.ngc` (Arabic-Indic three) passed
    as one of our names, and the run deleted the user's file of that name."""
    root, out = world
    name = "roughing_space\u0663.ngc"
    (out / name).write_text("user")
    (out / MANIFEST).write_text(json.dumps([name]))
    before = tree(root)
    check_refused_untouched(spur_cad("run", job, "--out", out, "--quiet"), before, root, out / MANIFEST)


def test_a_staging_folder_swapped_for_a_link_after_its_check_is_never_followed(tmp_path):
    """Between the check of a staging folder and its removal (or the switch's moves), whoever can write into the
    output folder can put a link in its place. Every removal and move is relative to descriptors opened without
    following links: here the swap is made at the worst moment by hand, with the functions the writer uses."""
    from spur_cad.outputs import _opened, _remove_staging, _write_synced

    out, victim = tmp_path / "out", tmp_path / "victim"
    out.mkdir()
    victim.mkdir()
    (victim / "gear.step").write_text("the user's own gear")
    name = STAGING_PREFIX + "abcd1234"
    with _opened(out) as folder:
        os.mkdir(name, 0o700, dir_fd=folder)
        staging = os.open(name, os.O_RDONLY | os.O_DIRECTORY, dir_fd=folder)
        os.fchmod(staging, 0o700)
        _write_synced(staging, STAGING_MARK, b"")
        _write_synced(staging, "gear.step", b"staged")
        os.rename(out / name, out / "moved_away")  # the swap: our folder away, a link to the victim in its place
        (out / name).symlink_to(victim)
        _remove_staging(folder, name, staging)  # removes what is in *our* folder, through its descriptor
        os.close(staging)
        _remove_staging(folder, name)  # by name: the link is not followed
    assert (victim / "gear.step").read_text() == "the user's own gear"
    assert not (out / "moved_away" / "gear.step").exists()  # our staged file went, from our folder


@pytest.mark.slow
def test_a_link_swapped_in_during_a_real_run_deletes_nothing_outside(job, world):
    """The same swap raced against a real `spur-cad run` by a second process (the hostile review's reproducer:
    before the fix, 3 runs of 3 deleted the victim folder's files)."""
    root, out = world
    swapper = textwrap.dedent(f"""
        import os, time
        out = {str(out)!r}
        deadline = time.time() + 120
        while time.time() < deadline:
            if os.path.exists(os.path.join(out, {MANIFEST!r})):
                names = [n for n in os.listdir(out) if n.startswith({STAGING_PREFIX!r})]
                if names:
                    try:
                        os.rename(os.path.join(out, names[0]), os.path.join(out, "moved_away"))
                        os.symlink({str(root / "victimdir")!r}, os.path.join(out, names[0]))
                    except OSError:
                        continue
                    break
    """)
    for attempt in range(3):
        for leftover in [p for p in out.iterdir() if p.name != "notes.txt"]:
            leftover.unlink() if leftover.is_symlink() or leftover.is_file() else shutil.rmtree(leftover)
        race = subprocess.Popen([sys.executable, "-c", swapper])
        result = spur_cad("run", job, "--out", out, "--quiet")
        race.kill()  # the race is over when the run has ended (the swapper would spin on to its deadline)
        race.wait(timeout=60)
        assert result.returncode in (0, 2), result.stderr
        assert (root / "victimdir" / "precious.txt").read_text() == "precious", attempt
        assert (root / "victim.txt").read_text() == "victim"


def test_an_interrupted_switch_blocked_by_a_folder_is_refused_before_anything_changes(job, world):
    """A folder made at a name of the new set while a switch ran: the next run names it at once."""
    root, out = world
    staging = ours_staging(out / (STAGING_PREFIX + "abcd1234"))
    (staging / "gear.step").write_text("staged")
    (out / "gear.step").mkdir()
    (out / JOURNAL).write_text(json.dumps({"staging": staging.name, "new": ["gear.step"], "old": []}))
    before = tree(root)
    result = spur_cad("run", job, "--out", out, "--quiet")
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1, result.stderr
    assert "gear.step is in the way" in result.stderr and "interrupted switch" in result.stderr
    assert tree(root) == before


def test_a_staged_manifest_is_not_trusted_when_a_switch_is_completed(job, world):
    """Completing an earlier switch writes the manifest anew from the journal's checked names: a staged manifest
    that is not ours is never moved in (it used to be, and then every run was refused)."""
    root, out = world
    staging = ours_staging(out / (STAGING_PREFIX + "abcd1234"))
    (staging / "gear.step").write_text("staged")
    (staging / MANIFEST).write_text('"x"')
    (out / JOURNAL).write_text(json.dumps({"staging": staging.name, "new": ["gear.step"], "old": []}))
    result = spur_cad("run", job, "--out", out, "--quiet")
    assert result.returncode == 0, result.stderr
    assert "summary.json" in json.loads((out / MANIFEST).read_text())


@pytest.mark.slow
def test_a_lock_held_by_another_process_does_not_make_the_run_deaf(job, world):
    """Anyone who can read the folder can hold its lock: the run waits (a run of ours holds it for
    milliseconds), and a signal still stops it with the one line."""
    import fcntl
    import signal
    import time

    root, out = world
    holder = os.open(out, os.O_RDONLY)
    fcntl.flock(holder, fcntl.LOCK_EX)
    try:
        child = subprocess.Popen([sys.executable, "-m", "spur_cad.cli", "run", str(job), "--out", str(out),
                                  "--quiet"], stderr=subprocess.PIPE, text=True)
        time.sleep(20)  # the small job's computation takes about 6 s: the run waits for the lock by then
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=30)
    finally:
        os.close(holder)
    assert child.returncode == 130, err
    assert err.startswith("spur-cad: interrupted") and len(err.splitlines()) == 1
    assert not (out / MANIFEST).exists()
