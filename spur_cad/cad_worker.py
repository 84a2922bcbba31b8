"""The CAD stage in a second process (issue 27): `spur-cad run` builds the gear solid, the stock and their STEP
files here while its own process plans, posts, simulates and reports, so a run takes about the longer of the
two instead of their sum on a machine of two cores, and the main process never imports OCP (about 280 MB).

The worker is a fresh interpreter, `python -m spur_cad.cad_worker` (not a fork: a fork after numpy's or numba's
threads exist can deadlock; not multiprocessing's 'spawn', which runs the caller's main script again in the
worker). It reads the pickled job from its stdin and writes the pickled outcome to its stdout. It runs in a
session of its own, so a Ctrl-C at the terminal reaches the main process only, which decides: it stops the
worker at its next checkpoint. The worker also ends when the main process ends without stopping it (SIGKILL):
the kernel kills it (Linux's parent-death signal), and elsewhere it ends when its stdin reaches end-of-file.
An error in the worker comes back as the same exception (pickled, with the worker's traceback as a note) and
is raised again in the main process.

The FreeCAD workbench builds the CAD in its own process: OCCT is loaded there already, and FreeCAD's
executable is not a Python interpreter a worker could be started with (`run_job` without a `cad_worker`).
"""

from __future__ import annotations

import ctypes
import gc
import os
import pickle
import signal
import subprocess
import sys
import threading
import time
import traceback
from types import TracebackType
from typing import IO, TYPE_CHECKING, BinaryIO, Callable

if TYPE_CHECKING:
    from spur_cad.job import Job
    from spur_cad.result import CadResult

POLL_S = 0.05
"""How often the main process, waiting for the worker, calls its checkpoint (a signal is seen within this)."""
STOP_WAIT_S = 2.0
"""How long a stopped worker is given to end after SIGTERM before SIGKILL."""
READ_BYTES = 1 << 20
PR_SET_PDEATHSIG = 1  # linux/prctl.h


class CadWorker:
    """A worker process started early, then given `build_cad(job, None, timestamp)` by `submit`; `result()` waits
    for it (calling `checkpoint()` meanwhile), `stop()` ends it. As a context manager its exit stops it, so that
    no worker outlives the run that started it; when the run failed with an Exception after `submit`, the worker's
    own error is raised instead if it has one (the CAD stage came before the others in a run, so its error is the
    one a user saw)."""

    def __init__(self, checkpoint: Callable[[], None] | None = None) -> None:
        """Start the worker: it loads the kernel (OCP, about 1 s with Python's start) while the caller reads the
        job, which `submit` then gives it."""
        self._checkpoint = checkpoint
        self._submitted = False
        self._read = False  # the worker's outcome has been read (result() was called to its end)
        self._process = subprocess.Popen([sys.executable, "-m", "spur_cad.cad_worker", str(os.getpid())],
                                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, start_new_session=True)
        if self._process.stdin is None or self._process.stdout is None:  # never: both are PIPE above
            raise RuntimeError("the CAD worker process started without its pipes")
        self._stdin: IO[bytes] = self._process.stdin
        self._stdout: IO[bytes] = self._process.stdout
        # The outcome is read as it comes, not when the run asks for it: a worker whose STEP files fill the pipe
        # would otherwise stay alive, holding OCP's 300 MB, until the main process has simulated and reported
        self._chunks: list[bytes] = []
        self._ended = threading.Event()  # end-of-file on the worker's stdout
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()

    def submit(self, job: Job, timestamp: str | None) -> None:
        """Have the worker build `job`'s CAD stage, with `timestamp` as the STEP headers' time."""
        # pickled before it counts as submitted: a job that cannot be pickled raises here, and the exit stops the
        # worker instead of waiting for a result that will never come
        message = pickle.dumps((job, timestamp), protocol=pickle.HIGHEST_PROTOCOL)
        self._submitted = True
        try:
            self._stdin.write(message)
            self._stdin.flush()  # stdin stays open: the worker's lifeline
        except BrokenPipeError:  # the worker has ended; result() says so
            pass

    @property
    def pid(self) -> int:
        return self._process.pid

    def result(self) -> tuple[CadResult, dict[str, bytes], float]:
        """(CAD facts, STEP files, the worker's own seconds for them); calls `checkpoint()` every POLL_S while
        waiting; raises the worker's exception again."""
        checkpoint = self._checkpoint
        while True:
            if checkpoint is not None:
                checkpoint()
            if self._ended.wait(POLL_S):  # end-of-file: the worker has ended
                break
        self._read = True
        chunks = self._chunks
        code = self._process.wait()
        if code != 0 or not chunks:  # killed, out of memory, or no Python to start
            if checkpoint is not None:
                checkpoint()  # a signal to the whole group ended it: the run stops as interrupted
            raise RuntimeError(f"the CAD worker process ended without a result (exit code {code})")
        kind, value, seconds = pickle.loads(b"".join(chunks))
        if kind == "error":
            raise value
        facts, files = value
        return facts, files, seconds

    def _drain(self) -> None:
        """The reader thread: the worker's stdout to its end, kept in memory (the facts and the STEP files)."""
        descriptor = self._stdout.fileno()
        try:
            while chunk := os.read(descriptor, READ_BYTES):
                self._chunks.append(chunk)
        except OSError:  # closed under it: stop() has ended the worker
            pass
        finally:
            self._ended.set()

    def stop(self) -> None:
        """End the worker if it still runs (SIGTERM, then SIGKILL after STOP_WAIT_S) and close its pipes."""
        if self._process.poll() is None:
            self._process.terminate()
            try:
                self._process.wait(STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
        self._reader.join(STOP_WAIT_S)  # the worker has ended: its stdout reaches end-of-file
        streams = [self._stdin]
        if not self._reader.is_alive():  # never closed under a thread still reading it (its number could be reused)
            streams.append(self._stdout)
        for stream in streams:
            try:
                stream.close()
            except BrokenPipeError:  # closing flushes nothing: everything was flushed at the start
                pass

    def __enter__(self) -> CadWorker:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 traceback_: TracebackType | None) -> None:
        try:
            if isinstance(exc, Exception) and self._submitted and not self._read:
                self.result()  # raises the CAD stage's error, if any, in place of the run's
        finally:
            self.stop()


def _serve(source: BinaryIO, sink: BinaryIO) -> None:
    """The worker process: load the kernel, read (job, timestamp) from `source`, build, write ("done", (facts,
    files), seconds) or ("error", exception, None) to `sink`, end. Ends at once when `source` reaches end-of-file
    before."""
    import spur_cad.cad.solid  # noqa: F401 - the kernel, loaded while the main process reads the job
    import spur_cad.cad.step  # noqa: F401
    from spur_cad.cad_stage import build_cad

    try:
        job, timestamp = pickle.load(source)
    except EOFError:  # stopped before a job came
        os._exit(0)
    threading.Thread(target=_exit_at_end_of_file, args=(source,), daemon=True).start()
    try:
        start = time.perf_counter()
        value = build_cad(job, None, timestamp)
        message: tuple[str, object, float | None] = ("done", value, time.perf_counter() - start)
    except Exception as exc:  # noqa: BLE001 - every failure goes back to the main process, which decides
        message = ("error", _transferable(exc), None)
    sink.write(pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL))
    sink.flush()
    os._exit(0)  # not the interpreter's shutdown, which tears OCP's modules down for a second while the run waits


def _exit_at_end_of_file(source: BinaryIO) -> None:
    """Wait for end-of-file on `source` (the main process closed it or died), then end this process."""
    try:
        source.read()
    except OSError:
        pass
    os._exit(1)


def _end_with_parent(parent_pid: int) -> None:
    """On Linux, have the kernel SIGKILL this process when its parent ends (prctl PR_SET_PDEATHSIG): at once, where
    the lifeline thread waits for the GIL, which OCP's long calls and its import hold. Ends now if the parent has
    ended already."""
    try:
        ctypes.CDLL(None).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the lifeline alone
        pass
    if os.getppid() != parent_pid:
        os._exit(1)


def _transferable(exc: Exception) -> Exception:
    """`exc` with the worker's traceback as a note when it survives pickling, else a RuntimeError naming it."""
    exc.add_note("in the CAD worker process:\n" + "".join(traceback.format_exception(exc)).rstrip())
    try:
        pickle.loads(pickle.dumps(exc))
    except Exception:  # noqa: BLE001 - an exception type that cannot be rebuilt from its arguments
        return RuntimeError(f"{type(exc).__name__}: {exc}")
    return exc


if __name__ == "__main__":
    gc.disable()  # one build and os._exit: the collector would only traverse OCP's import again and again
    _end_with_parent(int(sys.argv[1]))
    results = os.fdopen(os.dup(sys.stdout.fileno()), "wb")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # whatever a library prints goes to stderr, not the result
    _serve(sys.stdin.buffer, results)
