"""Peak resident memory of a command, measured so that the measurement is the command's own.

Linux counts in a child's peak (ru_maxrss) the pages it shared with its parent between fork and exec, so a
command started from a large process (a test run, a benchmark holding a CAM plan) seems as large as that
process. `run_measured` starts the command from a fresh, small Python launcher and reports the command's
own peak (the launcher's few megabytes are the floor).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time

_LAUNCHER = """
import glob, os, subprocess, sys, threading
child = subprocess.Popen(sys.argv[2:])
peaks_kb, together_kb, done = {}, [0], threading.Event()

def tree(pid):
    found = [pid]
    for path in glob.glob(f"/proc/{pid}/task/*/children"):
        try:
            with open(path) as listing:
                found += [p for c in listing.read().split() for p in tree(int(c))]
        except OSError:
            pass
    return found

def sample():
    while not done.wait(0.01):
        alive_kb = 0
        for pid in tree(child.pid):
            try:
                with open(f"/proc/{pid}/status") as status:
                    kb = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
            except (OSError, StopIteration):
                continue
            peaks_kb[pid] = max(peaks_kb.get(pid, 0), kb)
            alive_kb += kb
        together_kb[0] = max(together_kb[0], alive_kb)

sampler = threading.Thread(target=sample, daemon=True)
sampler.start()
_, status, usage = os.wait4(child.pid, 0)
done.set()
sampler.join()
with open(sys.argv[1], "w") as report:
    together = max(together_kb[0], usage.ru_maxrss)  # a peak after the last sample: at least the largest process's
    report.write(f"{usage.ru_maxrss * 1024} {os.waitstatus_to_exitcode(status)} {together * 1024}")
sys.exit(0)
"""


def run_measured(args: list[str], timeout_s: float, preexec_fn=None) -> tuple[subprocess.CompletedProcess, int, float]:
    """(the command's result with its text output, its peak resident bytes, wall seconds); raises
    subprocess.TimeoutExpired when it runs past `timeout_s`. The peak is the largest of the command's processes
    (Linux's ru_maxrss of a child); run_measured_tree also gives its processes' memory at one time."""
    result, peak, _, seconds = run_measured_tree(args, timeout_s, preexec_fn)
    return result, peak, seconds


def run_measured_tree(args: list[str], timeout_s: float,
                      preexec_fn=None) -> tuple[subprocess.CompletedProcess, int, int, float]:
    """run_measured's (result, peak bytes of the largest process, ..., wall seconds) with, third, the peak of the
    command's processes together (the command and the processes it started, e.g. `spur-cad run`'s CAD worker):
    sampled every 10 ms, the largest sum over the processes alive at one sample of each one's peak so far (VmHWM,
    at least its resident memory then; not ru_maxrss, which is the largest of a process and the children it waited
    for). A process that has ended no longer counts: two processes that never run at once are not summed."""
    with tempfile.NamedTemporaryFile("r", suffix=".peak") as report:
        start = time.perf_counter()
        launcher = subprocess.Popen([sys.executable, "-c", _LAUNCHER, report.name, *args], stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True, preexec_fn=preexec_fn,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
        try:
            out, err = launcher.communicate(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            os.killpg(launcher.pid, signal.SIGKILL)  # the launcher and the command it started
            launcher.communicate()
            raise
        seconds = time.perf_counter() - start
        peak, code, together = (int(value) for value in report.read().split())
    return subprocess.CompletedProcess(args, code, out, err), peak, together, seconds


def fresh_python_floor_bytes() -> int:
    """The peak of a bare `python -c pass` started the same way (what run_measured cannot go below)."""
    return run_measured([sys.executable, "-c", "pass"], 60)[1]


if __name__ == "__main__":  # pragma: no cover
    result, peak_bytes, together_bytes, wall = run_measured_tree(sys.argv[1:], 3600)
    print(f"exit {result.returncode}, {wall:.2f} s, peak {peak_bytes / 1e6:.0f} MB (its processes together: "
          f"{together_bytes / 1e6:.0f} MB)", file=sys.stderr)
    sys.exit(result.returncode)
