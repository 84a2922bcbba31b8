"""Command line: `spur-cad run JOB.toml --out DIR` computes everything in memory, then writes;
`spur-cad verify JOB.toml PROGRAM...` cuts the job's stock with G-code programs from anywhere and exits
0 when the part is within tolerance, 1 when not (docs/verification.md).

Errors in the user's input print one line (`spur-cad: error: ...`) and exit 2 with nothing
written; an unexpected failure prints a one-line internal error (traceback only with --debug)
and exits 3; SIGINT (Ctrl-C) and SIGTERM print one line and exit 130 and 143 (at the run's next
checkpoint, never inside a library). The output folder
always keeps a complete set (spur_cad.outputs).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import gc
import os
import shutil
import signal
import sys
import threading
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, NoReturn, TextIO

from spur_cad.errors import SpurCadError, escaped, one_line
from spur_cad.inputs import step_timestamp
from spur_cad.version import __version__

if TYPE_CHECKING:  # the stages load only when a command needs them
    from spur_cad.grade.grading import Grading
    from spur_cad.grade.probe_log import ProbeLog
    from spur_cad.job import Job

EXIT_INPUT_ERROR = 2
EXIT_INTERNAL_ERROR = 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it
EXIT_TERMINATED = 143  # 128 + SIGTERM


class Terminated(BaseException):
    """SIGTERM arrived: stop like an interrupt (the output folder keeps its set)."""


class _ArgumentParser(argparse.ArgumentParser):
    """argparse with the command line's one-line errors: `spur-cad: error: ...`, exit 2 (no usage block)."""

    def error(self, message: str) -> NoReturn:
        sys.stderr.write(f"spur-cad: error: {one_line(message)} (spur-cad --help)\n")
        sys.exit(EXIT_INPUT_ERROR)


def _parser() -> argparse.ArgumentParser:
    parser = _ArgumentParser(prog="spur-cad", description="Spur gears cut on a 4-axis machining centre.")
    parser.add_argument("--version", action="version", version=f"spur-cad {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a job file and write its outputs")
    run.add_argument("job", help="TOML job file")
    run.add_argument("--out", required=True, help="output folder (created if missing)")
    run.add_argument("--restart", metavar="POINT",
                     help="also write a program restarting an operation after an alarm: roughing:space=K[,level=N], "
                          "finishing:station=N or finishing:space=K[,pass=N] (numbered from 0; docs/shop-floor.md)")
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")
    run.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    verify = sub.add_parser("verify", help="cut the job's stock with G-code programs (from anywhere) and judge the "
                                           "part: exit 0 within tolerance, 1 beyond, 2 bad input")
    verify.add_argument("job", help="TOML job file (gear, stock, tools by number, simulation resolution)")
    verify.add_argument("programs", nargs="+", help="G-code programs, run in the order given")
    verify.add_argument("--out", help="folder for verify.json and deviation_map.csv (created if missing)")
    verify.add_argument("--dialect", help="dialect of the programs (default: the job's [post] dialect)")
    verify.add_argument("--reader", default="spur_cad", choices=("spur_cad", "rs274"),
                        help="read LinuxCNC programs with LinuxCNC's own interpreter (rs274) instead of spur_cad's "
                             "reader")
    verify.add_argument("--point", default="tip", choices=("tip", "corner-centre"),
                        help="programmed point of the tool: its tip (spur_cad's programs) or its corner-radius "
                             "centre (a tool length offset to the ball centre)")
    verify.add_argument("--point-tools", type=int, nargs="+", default=(), metavar="T",
                        help="the tool numbers --point applies to (default: every tool)")
    verify.add_argument("--gouge-tolerance-mm", type=float, help="largest gouge that passes (default: the "
                        "simulation's resolution)")
    verify.add_argument("--leftover-tolerance-mm", type=float, help="largest leftover that passes (default: the "
                        "finishing target scallop plus the resolution)")
    verify.add_argument("--a-offset-deg", type=float, default=0.0, metavar="DEG",
                        help="programs written with another A zero: the job's A where the programs' A is 0, added "
                             "to every A read (default 0)")
    verify.add_argument("--quiet", action="store_true", help="print nothing but errors and the verdict")
    verify.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    grade = sub.add_parser("grade", help="grade a real gear by ISO 1328-1:2013 from points measured on it")
    grade.add_argument("job", help="TOML job file (the gear's design)")
    grade.add_argument("measured", help="CSV of measured points (x_mm,y_mm[,X_mm] in transverse planes), or the "
                       "probe log of the job's probe.ngc (nine numbers a line, recognised by its content)")
    grade.add_argument("--datum", choices=("best-fit", "axis"), help="CSV: 'best-fit' (default) fits the centre "
                       "and the turn; 'axis' takes the file's origin as the gear's datum axis and fits the turn only, "
                       "so an eccentricity shows in F_p. A probe log is always graded against the A axis")
    grade.add_argument("--out", help="folder for grade.json and k_chart.png (created if missing)")
    grade.add_argument("--required-class", type=int, choices=range(1, 12), metavar="1..11",
                       help="exit 1 when the gear is worse than this flank tolerance class")
    grade.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    correct = sub.add_parser("correct", help="identify the machine's errors from a measured gear and write corrected "
                                             "programs (tool size, the rotary table's error e(A), slopes) with "
                                             "correction.json and "
                                             "report.html")
    correct.add_argument("job", help="TOML job file the measured gear was cut with")
    correct.add_argument("measured", help="CSV of measured points as spur-cad grade reads it (x_mm,y_mm[,X_mm]; "
                                          "the scan's frame within half a pitch of the machine's, space 0 at A 0), "
                                          "or the probe log of the job's probe program (size and slopes only)")
    correct.add_argument("--datum", choices=("best-fit", "axis"), help="CSV: 'best-fit' (default) fits the centre "
                         "and the turn, and cannot see a once-per-turn error (an eccentric gear); 'axis' takes the "
                         "file's origin as the gear's datum axis (the bore) and fits the turn only, so the table's "
                         "once-per-turn error is seen and corrected. A probe log has its own datum, the A axis")
    correct.add_argument("--once-per-turn", choices=("table", "blank"), default="table",
                         help="with --datum axis: take a once-per-turn error for the table's (default: the A words are "
                              "corrected, right for every blank) or for the blank clamped off the A axis (Y and Z "
                              "corrected, for this set-up only); the scan cannot tell them apart (docs/correction.md)")
    correct.add_argument("--out", required=True, help="folder for the corrected programs and correction.json")
    correct.add_argument("--quiet", action="store_true", help="print nothing but errors")
    correct.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    for command in (run, verify, grade, correct):
        command.add_argument("--side-files", action="append", default=[], metavar="DIR",
                             help="a folder the files the job names (report_template, rotary_calibration_file) may "
                                  "also be read from, besides the job file's own folder (may be given again)")
    freecad = sub.add_parser("install-freecad", help="make the FreeCAD workbench and this spur_cad available "
                                                     "to your FreeCAD (undo with --uninstall)")
    freecad.add_argument("--uninstall", action="store_true", help="remove what install-freecad added")
    return parser


class ProgressBars:
    """A `run_job` progress callback: one tqdm bar per long stage on `stream` (used when stderr is a
    terminal and --quiet is not given, so that logs and pipes get only the one-line messages).

    tqdm is optional (FreeCAD's Addon Manager cannot install it): without it each stage gets one plain
    line when it ends."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self._bars: dict = {}
        try:
            from tqdm import tqdm
        except ImportError:
            tqdm = None
        self._tqdm = tqdm

    def __call__(self, stage: str, fraction: float) -> None:
        if self._tqdm is None:
            if fraction >= 1.0 and stage not in self._bars:
                self._bars[stage] = None
                print(f"{stage:>13}: done", file=self._stream, flush=True)
            return
        bar = self._bars.get(stage)
        if bar is None:
            size = shutil.get_terminal_size()  # 80 x 24 when the terminal does not say (tqdm would draw nothing)
            bar = self._bars[stage] = self._tqdm(total=100, desc=f"{stage:>13}", file=self._stream, leave=True,
                                                 ncols=min(100, size.columns), nrows=max(size.lines, 10),
                                                 bar_format="{desc}: {percentage:3.0f}%|{bar:30}| {elapsed}")
        bar.n = min(100, round(100.0 * fraction))
        bar.refresh()
        if fraction >= 1.0:
            bar.close()

    def close(self) -> None:
        for bar in self._bars.values():
            if bar is not None:
                bar.close()


def _install_freecad(uninstall: bool) -> int:
    """`spur-cad install-freecad [--uninstall]` (see spur_cad.freecad_install)."""
    from spur_cad.freecad_install import install
    from spur_cad.freecad_install import uninstall as remove

    try:
        lines = remove(os.environ) if uninstall else install(os.environ)
    except SpurCadError as exc:
        print(f"spur-cad: error: {one_line(str(exc))}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    for line in lines:
        print(line)
    return 0


def main(argv: list[str] | None = None, *, exiting: bool = False) -> int:
    """The command line; SIGINT and SIGTERM anywhere in a run give one line and exit 130 / 143. The signal
    handlers only record the signal; the run stops at its next checkpoint (between stages, and in the
    simulation's progress), never inside a library: an exception raised in the middle of native code or of
    an import can be swallowed there ("Exception ignored in ...") or leave a C++ object half-built that
    crashes the process later. A signal that arrives after the last checkpoint, up to the return, still gives
    the one line and 130 / 143. Called in-process (tests), the handlers are the caller's again when main
    returns; as the process's entry point (`exiting`, see `entry`) they stay until the process ends, so that
    no signal can end it silently between the return and the exit."""
    received: list[int] = []  # the signals that arrived

    def on_signal(signum: int, frame: FrameType | None) -> None:
        received.append(signum)

    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)} if in_main_thread else {}
    try:
        try:
            code = _main(argv, received)
        except (KeyboardInterrupt, Terminated):
            code = EXIT_INTERRUPTED
        if received or code == EXIT_INTERRUPTED:
            print("spur-cad: interrupted (the output folder holds a complete set: its previous one, or this run's "
                  "if writing had finished)", file=sys.stderr)
            return EXIT_TERMINATED if signal.SIGTERM in received else EXIT_INTERRUPTED
        return code
    finally:
        if not exiting:
            for signum, handler in previous.items():
                signal.signal(signum, handler)


def entry() -> NoReturn:
    """The `spur-cad` program: `main` whose signal handling lasts until the process exits. The process ends
    with os._exit once the output is flushed: the interpreter's own shutdown gives the signals back to their
    defaults while it tears the modules down (a second or more after a run), and a signal then would end
    the process silently; the outputs are complete and synced by then, and nothing is left to clean up."""
    code = main(exiting=True)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: nothing more can be said
            pass
    os._exit(code)


def _side_folders(names: list[str]) -> tuple[Path, ...]:
    """The --side-files folders, each an existing folder (else one line, before the job is read)."""
    from spur_cad.errors import shown_path

    for name in names:
        if not os.path.isdir(name):
            raise SpurCadError(f"--side-files {shown_path(name)}: not a folder")
    return tuple(Path(name) for name in names)


def _checkpoint(received: list[int]) -> None:
    """Stop here (one line, 130 / 143) when a signal has arrived since the run began."""
    if received:
        raise Terminated() if signal.SIGTERM in received else KeyboardInterrupt()


def _run(args: argparse.Namespace, received: list[int], loaded: list) -> tuple[list, tuple[str, ...]]:
    """Load, compute and write the job's output set; the job goes into `loaded` (for locating errors). Returns
    the paths written and the run's warnings (summary.json's)."""
    from spur_cad.cad_worker import CadWorker  # the standard library only

    def checkpoint() -> None:
        _checkpoint(received)

    checkpoint()
    # The CAD stage's process, started first: it loads OCP while this one imports the rest and reads the job (a
    # refused --restart, --out or job file stops it with the run).
    with CadWorker(checkpoint) as cad_worker:
        from spur_cad.cam.restart import parse_restart
        from spur_cad.job import load_job  # heavy imports after the signal handling is in place
        from spur_cad.outputs import check_output_folder
        from spur_cad.pipeline import run_job

        restart = parse_restart(args.restart) if args.restart is not None else None
        out_dir = check_output_folder(args.out)  # before any computation
        loaded.append(load_job(args.job, side_folders=_side_folders(args.side_files)))
        bars = ProgressBars(sys.stderr) if not args.quiet and sys.stderr.isatty() else None

        def progress(stage: str, fraction: float) -> None:
            checkpoint()
            if bars is not None:
                bars(stage, fraction)

        try:
            result = run_job(loaded[0], progress, checkpoint, restart, cad_worker=cad_worker)
        finally:
            if bars is not None:
                bars.close()
    checkpoint()
    paths = _write(out_dir, result.files, received)
    checkpoint()  # a signal while the set was switched: it is this run's set, and the message says so
    return paths, result.warnings


def _write(out_dir: str | os.PathLike, files: dict[str, bytes], received: list[int]) -> list[Path]:
    """The output set written (spur_cad.outputs); a failure is one line naming the folder (exit 2)."""
    from spur_cad.errors import shown_path
    from spur_cad.outputs import OutputError, write_output_set

    try:
        return write_output_set(out_dir, files, lambda: _checkpoint(received))
    except OutputError:
        raise
    except OSError as exc:
        raise SpurCadError(f"cannot write to {shown_path(out_dir)}: {exc.strerror or exc}") from None


def _verify(args: argparse.Namespace, received: list[int], loaded: list) -> int:
    """`spur-cad verify`: read the programs, simulate, print the verdict, write the set; 0 pass, 1 fail."""

    from spur_cad.errors import shown, shown_path
    from spur_cad.job import load_job
    from spur_cad.outputs import check_output_folder
    from spur_cad.verify.reader import open_program_file, read_program_file
    from spur_cad.verify.rs274 import read_canonical, rs274_verdict
    from spur_cad.verify.verify import VerifyOptions, result_files, verify_moves

    _checkpoint(received)
    out_dir = check_output_folder(args.out) if args.out else None
    loaded.append(load_job(args.job, side_folders=_side_folders(args.side_files)))
    job = loaded[0]
    options = VerifyOptions(args.point, args.gouge_tolerance_mm, args.leftover_tolerance_mm, tuple(args.point_tools),
                            args.a_offset_deg)
    dialect = args.dialect or job.post.dialect
    known = job.dialects.get(dialect)  # None for a name the registry does not hold (the reader says so)
    rs274_checkable = known is not None and known.rs274_checkable  # LinuxCNC's interpreter reads these programs
    if args.reader == "rs274" and not rs274_checkable:
        raise SpurCadError(f"--reader rs274 reads LinuxCNC programs only (the dialect is {shown(dialect)})")
    programs = []
    for name in args.programs:
        source = shown_path(name)
        if args.reader == "rs274":
            with open_program_file(name, source) as handle:  # a regular file of bounded size, checked first
                programs.append(read_canonical(handle, source, lambda: _checkpoint(received)))
        else:
            programs.append(read_program_file(name, dialect, source, checkpoint=lambda: _checkpoint(received),
                                              dialects=job.dialects))
        _checkpoint(received)
    result = verify_moves(job, programs, options, progress=lambda fraction: _checkpoint(received))
    if rs274_checkable:
        result = dataclasses.replace(result, rs274={shown_path(name): rs274_verdict(name, lambda: _checkpoint(received))
                                                    for name in args.programs})
    lines = result.lines() + [f"rs274 {name}: {verdict}" for name, verdict in result.rs274.items()]
    for line in (lines if not args.quiet else lines[-1 - len(result.rs274):]):
        print(line)
    if out_dir is not None:
        _checkpoint(received)
        _write(out_dir, result_files(result), received)
    rs274_failed = any(verdict.startswith("failed") for verdict in result.rs274.values())
    return 0 if result.passed and not rs274_failed else 1


def _grade(args: argparse.Namespace, received: list[int], loaded: list) -> int:
    """`spur-cad grade`: best-fit the measured points to the design, print deviations and classes; 0, or 1 when
    worse than --required-class."""
    import json

    from spur_cad.grade.measured import MeasuredPoints, grade_measured
    from spur_cad.grade.probe_log import read_measured_file
    from spur_cad.job import load_job
    from spur_cad.outputs import check_output_folder

    _checkpoint(received)
    out_dir = check_output_folder(args.out) if args.out else None
    loaded.append(load_job(args.job, side_folders=_side_folders(args.side_files)))
    job = loaded[0]
    measured = read_measured_file(args.measured)
    if isinstance(measured, MeasuredPoints):
        grading = grade_measured(job.gear, measured, args.datum or "best-fit", job.modifications)
    else:
        grading = _grade_probe_log(job, measured, args.datum)
    spec = job.gear
    _checkpoint(received)
    fit = grading.fit
    if fit is None:  # never: a measured grading has its fit
        raise ValueError("the measured grading has no fit")
    if fit.datum == "probe log":
        print(f"probe log: {grading.points} trips, datum the A axis (no fit), rms {fit.rms_deviation_um:.2f} um "
              "from the design")
    else:
        centre = "fixed: the datum axis" if fit.datum == "axis" else "fitted"
        print(f"fit: rotation {fit.rotation_deg:.4f} deg, centre ({fit.centre_mm[0]:.4f}, "
              f"{fit.centre_mm[1]:.4f}) mm ({centre}), rms {fit.rms_deviation_um:.2f} um over {grading.points} "
              "points")
    for name, value in grading.deviations_um.items():
        grade = grading.classes[name]
        print(f"{name}: {value:.2f} um, class {grade if grade else 'beyond 11'}")
    for cut in grading.modifications_cut or ():
        print(f"{cut.side} flank: {cut.sentence}")
    for note in grading.notes:
        print(f"note: {note}")
    overall = grading.overall_class
    if not grading.classes:
        print("not graded: no flank had three points in its evaluation range")
    else:
        print(f"ISO 1328-1:2013 flank tolerance class: {overall if overall else 'beyond 11'}")
    if out_dir is not None:
        from spur_cad.report.figures import k_chart_png

        files = {"grade.json": (json.dumps(grading.to_json(), indent=2) + "\n").encode()}
        if grading.has_profile_traces:
            files["k_chart.png"] = k_chart_png(spec, grading)
        _write(out_dir, files, received)
    if args.required_class is not None and (overall is None or overall > args.required_class):
        return 1
    return 0


def _correct(args: argparse.Namespace, received: list[int], loaded: list) -> int:
    """`spur-cad correct`: identify the size, the table's e(A) and the slopes in the measured points, write the
    corrected set."""
    from spur_cad.correct.correct import correct_job
    from spur_cad.errors import shown_path
    from spur_cad.grade.measured import MeasuredPoints
    from spur_cad.grade.probe_log import read_measured_file
    from spur_cad.job import load_job
    from spur_cad.outputs import check_output_folder

    _checkpoint(received)
    out_dir = check_output_folder(args.out)
    loaded.append(load_job(args.job, side_folders=_side_folders(args.side_files)))
    measured = read_measured_file(args.measured)  # a scan's CSV, or the job's probe log
    _checkpoint(received)
    if args.datum == "best-fit" and not isinstance(measured, MeasuredPoints):
        raise SpurCadError(f"{shown_path(args.measured)}: a probe log is read against the A axis (the gear's datum "
                           "axis in the cutting setup); --datum is for CSV scans")
    identified, applied, files = correct_job(loaded[0], measured, shown_path(args.measured),
                                             args.datum or "best-fit", args.once_per_turn)
    _checkpoint(received)
    paths = _write(out_dir, files, received)
    if not args.quiet:
        print(f"size error: {identified.size_um:+.2f} um +- {identified.size_uncertainty_um:.2f} "
              "(+: material left; the finishing tool is programmed for it)")
        table = identified.table
        if table is None:
            print("table error e(A): not seen by a probe log (the probe turns on the table that cut the gear): "
                  "not corrected")
        else:
            kept = ", ".join(f"order {h.order} {h.amplitude_arcsec:.1f} arcsec" for h in table.kept) or "none"
            print(f"table error e(A), orders {table.harmonics[0].order} to {table.harmonics[-1].order} tested: "
                  f"{kept} (every block's A corrected)")
            if not table.first_order_visible:
                print("once-per-turn error: not seen on a best-fit scan (an eccentric gear); use --datum axis")
            elif applied.once_per_turn is not None:
                print(f"once-per-turn error taken for the {applied.once_per_turn}'s; a blank off the A axis leaves "
                      "the same gear: probe the bore's centre at set-up (correction.json)")
        for name, slopes in (("profile slope", identified.profile_slope_um),
                             ("helix slope", identified.helix_slope_um)):
            print(f"{name}: " + ", ".join(f"{side} {value:+.2f} um" for side, value in slopes.items())
                  + " (correction.json says whether the finishing follows it)")
        for path in paths:
            print(f"wrote {escaped(str(path))}")
    return 0


def _grade_probe_log(job: Job, log: ProbeLog, datum: str | None) -> Grading:
    """The Grading of a probe log against the job's probing plan (recomputed from its [probe] section)."""
    from spur_cad.cam.probing import plan_probe
    from spur_cad.grade.probe_log import grade_probe_log

    if datum == "best-fit":
        raise SpurCadError(f"{log.source}: a probe log is graded against the A axis (the gear's datum axis in the "
                           "cutting setup); --datum best-fit is for CSV scans")
    if job.probe is None:
        raise SpurCadError(f"{log.source}: a probe log, but the job has no [probe] section to name its trips (grade "
                           "with the job that wrote the probing program)")
    plan = plan_probe(job.gear, job.stock, job.machine, job.probe)
    return grade_probe_log(job.gear, plan, log, job.post.rotary_sign, job.modifications)


@contextlib.contextmanager
def _cycle_collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off for one run, as it was afterwards. A run's imports (OCCT's, numba's,
    matplotlib's) leave a million long-lived objects that the collector traversed again and again (0.4 s of a 4 s
    reference run, docs/benchmarks.md), while the run itself makes few reference cycles (its figures, a fixed
    number): plain reference counting frees its arrays as before."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _main(argv: list[str] | None, received: list[int]) -> int:
    args = _parser().parse_args(argv)
    if not getattr(args, "debug", False):
        # Numerical warnings (overflow in an intermediate, ...) are not messages for the user: an input
        # problem is reported as one line, and results are checked, not warned about.
        warnings.simplefilter("ignore", RuntimeWarning)
    if args.command == "install-freecad":
        return _install_freecad(args.uninstall)
    loaded: list = []
    try:
        step_timestamp(os.environ)  # before numpy's f2py (imported by scipy) reads it and fails with a traceback
        if args.command == "verify":
            return _verify(args, received, loaded)
        if args.command == "grade":
            return _grade(args, received, loaded)
        if args.command == "correct":
            with _cycle_collector_paused():
                return _correct(args, received, loaded)
        with _cycle_collector_paused():
            paths, run_warnings = _run(args, received, loaded)
    except SpurCadError as exc:
        message = loaded[0].located(exc) if loaded and exc.section else str(exc)
        print(f"spur-cad: error: {one_line(message)}", file=sys.stderr)
        return EXIT_INPUT_ERROR
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback unless asked
        _checkpoint(received)  # a failure after a signal arrived (e.g. a library's own SIGINT handling)
        if getattr(args, "debug", False):
            raise
        print(one_line(f"spur-cad: internal error: {type(exc).__name__}: {exc}") + " (run with --debug for "
              "details; please report it)", file=sys.stderr)
        return EXIT_INTERNAL_ERROR
    if not args.quiet:
        for path in paths:
            print(f"wrote {escaped(str(path))}")  # a folder name's control characters as escapes
        for warning in run_warnings:  # the report and summary.json hold them too
            print(f"spur-cad: warning: {one_line(warning)}", file=sys.stderr)
    return 0


if __name__ == "__main__":  # pragma: no cover
    entry()
