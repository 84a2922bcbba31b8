"""The CAD stage in a worker process (spur_cad.cad_worker, issue 27), as `spur-cad run` runs it: the main process
never imports OCP, the STEP files are the in-process ones, a CAD error is the same exception with the same one
line, and a signal during the CAD stage stops the worker and leaves the folder's old set."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from spur_cad.cad_worker import CadWorker
from spur_cad.errors import WorkLimitError
from spur_cad.job import load_job, parse_job

ROOT = Path(__file__).resolve().parents[1]
EPOCH = "1700000000"
ABSURD_LOFT = ("[gear]\nteeth = 17\nmodule_mm = 2.0\nface_width_mm = 300\nhelix_angle_deg = 45\n"
               "[gear.modifications]\nlead_crowning_um = 5\n")  # refused by the CAD stage before it builds
CAD_STAGE_S = 1.5
"""A signal this long after the worker started comes while it builds the CAD of LONG_CAD_JOB (the worker's own
start and OCP's import take about 1 s, that gear's CAD stage about 3 s; the reference gear's takes 0.4 s, too short
to be sure of)."""
LONG_CAD_JOB = ("[job]\nname = \"z200 m3\"\n[gear]\nteeth = 200\nmodule_mm = 3.0\nrack_tip_radius_mm = 0.6\n"
                "face_width_mm = 30.0\n[stock]\nradial_allowance_mm = 0.5\n[tools.roughing]\ndiameter_mm = 3.0\n"
                "[tools.finishing]\nkind = \"bull_nose\"\ndiameter_mm = 2.4\ncorner_radius_mm = 0.6\n"
                "[simulation]\nenabled = false\n")
KILLED_WORKER_ENDS_S = 1.0
"""A worker whose run was killed ends within this (between two of OCP's calls, when its lifeline thread runs)."""
CLI_IN_PROCESS = """
import json, sys
from spur_cad.cli import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "kernel": sorted(m for m in sys.modules if m.split(".")[0] in ("OCP", "cadquery"))}))
"""


CLI_SPYING_ON_NUMBA = """
import json, os, sys
from pathlib import Path

def running_children():
    found = []
    for entry in os.listdir("/proc"):
        try:
            fields = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if fields[1] == str(os.getpid()) and fields[0] != "Z":
            found.append(int(entry))
    return found

class NumbaSpy:  # a finder that finds nothing: it notes who runs when numba is first imported
    children = None
    def find_spec(self, name, path=None, target=None):
        if name == "numba" and NumbaSpy.children is None:
            NumbaSpy.children = running_children()
        return None

sys.meta_path.insert(0, NumbaSpy())
from spur_cad.cli import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "children_at_numba": NumbaSpy.children}))
"""


def _job_without_simulation(folder: Path) -> Path:
    text = (ROOT / "resources" / "examples" / "reference_gear.toml").read_text()
    path = folder / "reference_no_simulation.toml"
    path.write_text(text.replace("[simulation]", "[simulation]\nenabled = false", 1))
    return path


def _children(pid: int) -> list[int]:
    """The processes whose parent is `pid`."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry))
    return found


def _running(pid: int) -> bool:
    """`pid` exists and is not a zombie (an orphan's zombie waits for a reaper that a container may lack)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.fixture(scope="module")
def worker_run(tmp_path_factory):
    """`spur-cad run` of the reference job without simulation, called in a fresh process: (job file, output
    folder, the kernel modules that process imported)."""
    folder = tmp_path_factory.mktemp("cad_worker")
    job = _job_without_simulation(folder)
    out = folder / "out"
    done = subprocess.run([sys.executable, "-c", CLI_IN_PROCESS, "run", str(job), "--out", str(out), "--quiet"],
                          capture_output=True, text=True, timeout=300, env={**os.environ, "SOURCE_DATE_EPOCH": EPOCH},
                          cwd=ROOT)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    outcome = json.loads(done.stdout.splitlines()[-1])
    assert outcome["code"] == 0
    return job, out, outcome["kernel"]


def test_the_run_never_imports_ocp_and_writes_the_in_process_step_files(worker_run, monkeypatch):
    from spur_cad.pipeline import build_cad

    job, out, kernel = worker_run
    assert kernel == []
    monkeypatch.setenv("SOURCE_DATE_EPOCH", EPOCH)
    from spur_cad.inputs import step_timestamp

    _, files = build_cad(load_job(job), timestamp=step_timestamp(os.environ))
    for name in ("gear.step", "stock.step", "job.step"):
        assert (out / name).read_bytes() == files[name], name


def test_a_cad_error_in_the_worker_is_the_same_exception_with_the_same_message():
    from spur_cad.pipeline import build_cad

    job = parse_job(ABSURD_LOFT, "f.toml")
    with pytest.raises(WorkLimitError) as here:
        build_cad(job)
    with CadWorker() as worker, pytest.raises(WorkLimitError) as there:
        worker.submit(job, None)
        worker.result()
    assert str(there.value) == str(here.value)
    assert "lofted through about" in str(there.value)
    assert any("in the CAD worker process" in note for note in there.value.__notes__)
    assert not _running(worker.pid)


def test_the_worker_ends_once_its_outcome_is_sent_before_the_run_reads_it():
    """Its STEP files (about 0.9 MB for the reference gear) overflow a pipe's buffer (64 kB): the outcome is read
    as it comes, so the worker ends, and gives back OCP's 300 MB, while the run still simulates and reports; the
    run then finds the outcome whole."""
    job = load_job(ROOT / "resources" / "examples" / "reference_gear.toml")
    with CadWorker() as worker:
        worker.submit(job, None)
        deadline = time.monotonic() + 60.0
        while _running(worker.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _running(worker.pid), "the worker still runs: its outcome waits in a full pipe"
        facts, files, seconds = worker.result()
    assert sum(len(data) for data in files.values()) > 1 << 16
    assert set(files) == {"gear.step", "stock.step", "job.step"} and seconds > 0.0
    assert facts.gear_volume_mm3 > 0.0 and facts.step_bytes == {name: len(data) for name, data in files.items()}


# a whole run with its simulation in a subprocess (20 s); the worker's own import test stays in the fast tier
@pytest.mark.slow
def test_a_run_that_simulates_loads_numba_only_after_the_worker_has_ended(tmp_path):
    """OCP (in the worker, about 300 MB) and numba (the simulation's, about 130 MB) are never resident at once: the
    run waits for its worker before it simulates. The helical example at 0.05 mm: its CAD ends about 0.5 s after
    its main process is ready to simulate, so a run that did not wait would load numba with the worker running."""
    job = tmp_path / "helical.toml"
    job.write_text((ROOT / "resources" / "examples" / "helical_gear.toml").read_text()
                   + "\n[simulation]\nresolution_mm = 0.05\n")
    done = subprocess.run([sys.executable, "-c", CLI_SPYING_ON_NUMBA, "run", str(job), "--out", str(tmp_path / "out"),
                           "--quiet"], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    outcome = json.loads(done.stdout.splitlines()[-1])
    assert outcome["code"] == 0
    assert outcome["children_at_numba"] == [], "numba was loaded while the CAD worker ran"
    assert (tmp_path / "out" / "gear.step").is_file() and (tmp_path / "out" / "report.html").is_file()


def test_a_job_that_cannot_be_pickled_stops_the_worker_without_waiting():
    """submit raises before anything is sent; the context's exit stops the worker at once (it waited for ever for a
    result the worker, still waiting for its job, would never send)."""
    started = time.monotonic()
    with pytest.raises(Exception), CadWorker() as worker:  # noqa: B017 - whatever pickle raises for a lambda
        worker.submit(lambda: 0, None)
    assert time.monotonic() - started < 5.0
    assert not _running(worker.pid)


def test_a_worker_stopped_before_a_job_came_ends():
    """As when the job file is refused: the worker, started first, ends with the run."""
    worker = CadWorker()
    worker.stop()
    assert not _running(worker.pid)


@pytest.mark.slow
def test_the_cli_shows_the_workers_error_as_one_line(tmp_path):
    job = tmp_path / "absurd.toml"
    job.write_text(ABSURD_LOFT)
    done = subprocess.run([sys.executable, "-m", "spur_cad.cli", "run", str(job), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("spur-cad: error: the lead-modified flanks would be lofted through about")
    assert len(done.stderr.splitlines()) == 1, done.stderr


def _interrupted_during_cad(folder: Path, out: Path, send) -> tuple[subprocess.Popen, int]:
    """Start `spur-cad run` of LONG_CAD_JOB (written into `folder`) in a session of its own, wait until its CAD
    worker runs, then `send(process)`; returns the process and its worker's pid."""
    job = folder / "long_cad.toml"
    job.write_text(LONG_CAD_JOB)
    run = subprocess.Popen([sys.executable, "-m", "spur_cad.cli", "run", str(job), "--out", str(out), "--quiet"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 60
    while not (workers := _children(run.pid)):
        assert run.poll() is None and time.monotonic() < deadline, "no CAD worker started"
        time.sleep(0.01)
    time.sleep(CAD_STAGE_S)  # the worker starts with the run: it is now building
    assert _running(workers[0])
    send(run)
    return run, workers[0]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["SIGINT to the group", "SIGTERM"])
def test_a_signal_during_the_cad_stage_stops_the_worker_and_keeps_the_old_set(kind, worker_run, tmp_path):
    _, old, _ = worker_run  # the set an interrupted run must leave as it was (any complete set will do)
    out = tmp_path / "out"
    shutil.copytree(old, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    if kind == "SIGTERM":
        run, worker = _interrupted_during_cad(tmp_path, out, lambda process: process.send_signal(signal.SIGTERM))
    else:  # as a Ctrl-C at the terminal: every process of the foreground group
        run, worker = _interrupted_during_cad(tmp_path, out, lambda process: os.killpg(process.pid, signal.SIGINT))
    code = run.wait(timeout=60)
    stderr = run.stderr.read()
    assert code == (143 if kind == "SIGTERM" else 130), stderr
    assert len(stderr.splitlines()) == 1 and stderr.startswith("spur-cad: interrupted"), stderr
    assert not _running(worker)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


@pytest.mark.slow
def test_a_worker_whose_run_is_killed_ends_itself(tmp_path):
    """At once, not when it has built the CAD and finds nobody to give it to (about 3 s on)."""
    run, worker = _interrupted_during_cad(tmp_path, tmp_path / "out", lambda process: process.kill())
    run.wait(timeout=60)
    deadline = time.monotonic() + KILLED_WORKER_ENDS_S
    while _running(worker) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _running(worker)
