"""Run Python code inside Debian's FreeCAD 0.20 (`freecadcmd`, or `freecad` under `xvfb-run`).

Found on this machine: `freecadcmd script.py` runs the file and exits, but exits 0 even
when the script raises (it only prints "Exception while processing file: ..."), and
`freecadcmd --version` segfaults after printing. `freecad script.py` (GUI) runs the file once
the main window exists and then stays open, also after an exception. So the code runs
wrapped: it writes a JSON result file (`{"ok": true, ...}` or `{"ok": false, "error": ...}`)
and, in the GUI, closes the main window in a `finally`. As root the GUI needs
QTWEBENGINE_DISABLE_SANDBOX=1 (else Chromium's zygote aborts and freecad exits 1).

Every run writes FreeCAD's log (`--log-file=FILE`, after the script: 0.20's executables take no
option before it) and fails, whatever the test body found, when the log holds a traceback, an error,
a warning or a Qt warning that the test did not name as expected (`log_allowed`). FreeCAD routes Qt's
messages into its console: 0.20 as "Log:" lines, 1.0 and 1.1 as "Wrn:" lines (observed in all three).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
from pathlib import Path

GUI_TIMEOUT_S = 180.0
CMD_TIMEOUT_S = 120.0
LOG_NAME = "freecad.log"

# A log entry starts with its level; lines that do not (a traceback's, a banner's) continue the entry before.
_LOG_ENTRY = re.compile(r"^\ufeff?(Msg|Log|Wrn|Err): ", re.MULTILINE)
# A message of Qt itself: "QPainter::begin: ...", "QXcbConnection: ...", "QStandardPaths: ...".
_QT_MESSAGE = re.compile(r"^Q[A-Z][A-Za-z0-9]*(::[A-Za-z0-9_~]+)*: ")
# Lines FreeCAD writes in these environments whatever the workbench does, each with where it comes from.
ENVIRONMENT_LOG_LINES = (
    # 0.20 on Debian 12: FreeCAD's own Addon Manager, at start-up (Debian packages no python3-pyside2.qtwebengine).
    re.compile(r"^Wrn: Addon Manager Warning: Could not import QtWebEngineWidgets"),
    # 0.20 under Xvfb, which has no window manager: Qt focusing the main window as it hides at the end.
    re.compile(r"^Log: QXcbConnection: XCB error: 8 \(BadMatch\).*major code: 42 \(SetInputFocus\)"),
)

# Runs first inside FreeCAD: make the venv importable, run the test code, record the outcome.
_PRELUDE = r'''
import json, os, site, sys, traceback
_site = os.environ.get("SPUR_CAD_SITE_PACKAGES")
if _site:
    sys.path.insert(0, _site)
    site.addsitedir(_site)  # also processes .pth files (editable install of spur_cad)
RESULT = {}

def _run_body():
    try:
        _path = os.environ["SPUR_CAD_BODY"]
        with open(_path) as _f:
            _code = compile(_f.read(), _path, "exec")
        exec(_code, {"RESULT": RESULT, "__name__": "__spur_cad_test__"})
        RESULT.setdefault("ok", True)
    except BaseException:
        RESULT["ok"] = False
        RESULT["error"] = traceback.format_exc()
    with open(os.environ["SPUR_CAD_RESULT"], "w") as _f:
        json.dump(RESULT, _f, default=repr)
'''

_CMD_MAIN = "_run_body()\n"

_GUI_MAIN = r'''
def _in_event_loop():
    try:
        _run_body()
    finally:
        import FreeCAD, FreeCADGui
        for _name in list(FreeCAD.listDocuments()):
            FreeCAD.closeDocument(_name)  # no "save changes?" dialog on close
        FreeCADGui.getMainWindow().close()

from PySide import QtCore
QtCore.QTimer.singleShot(0, _in_event_loop)
'''


def _environment(work: Path, site_packages: str | None) -> dict[str, str]:
    """Environment for FreeCAD: a fresh HOME (no user add-ons or settings)."""
    env = dict(os.environ)
    for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_CACHE_HOME", "PYTHONPATH", "PYTHONHOME",
                 "FREECAD_USER_DATA", "FREECAD_USER_HOME"):  # these two would replace HOME's user folder
        env.pop(name, None)
    home = work / "home"
    home.mkdir(exist_ok=True)
    env["HOME"] = str(home)
    runtime = work / "runtime"  # Qt warns "XDG_RUNTIME_DIR not set" without one (1.0 as a warning in the log)
    runtime.mkdir(mode=0o700, exist_ok=True)
    env["XDG_RUNTIME_DIR"] = str(runtime)
    if site_packages:
        env["SPUR_CAD_SITE_PACKAGES"] = site_packages
    if os.geteuid() == 0:
        env["QTWEBENGINE_DISABLE_SANDBOX"] = "1"
    return env


def run_in_session(cmd: list[str], env: dict[str, str], cwd: Path,
                   timeout_s: float) -> subprocess.CompletedProcess:
    """Run `cmd` in its own process group; on timeout kill the whole group (Xvfb too)."""
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=cwd,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        err += f"\n[killed after {timeout_s:.0f} s timeout]"
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def log_entries(text: str) -> list[str]:
    """The entries of a FreeCAD log file: each starts with its level ("Err: ...") and holds its continuation lines."""
    starts = [match.start() for match in _LOG_ENTRY.finditer(text)]
    return [text[start:end].strip("\ufeff\n") for start, end in zip(starts, starts[1:] + [len(text)])]


def log_problems(text: str, allowed: tuple[str, ...] = ()) -> list[str]:
    """The entries of a FreeCAD log that fail a run: errors, warnings, tracebacks and Qt's messages, except
    those matching a regular expression in `allowed` (searched) or ENVIRONMENT_LOG_LINES (matched)."""
    problems = []
    for entry in log_entries(text):
        level, message = entry[:3], entry[5:]
        bad = (level in ("Err", "Wrn") or "Traceback (most recent call last)" in entry
               or _QT_MESSAGE.match(message) is not None)
        if not bad or any(pattern.match(entry) for pattern in ENVIRONMENT_LOG_LINES):
            continue
        if not any(re.search(pattern, entry) for pattern in allowed):
            problems.append(entry)
    return problems


def run_freecad_code(body: str, work: Path, *, freecadcmd: str | None = None,
                     gui: tuple[str, str] | None = None, site_packages: str | None = None,
                     timeout_s: float | None = None,
                     log_allowed: tuple[str, ...] = ()) -> tuple[dict | None, subprocess.CompletedProcess]:
    """Run `body` in FreeCAD; return (RESULT dict or None if none was written, process).

    `body` fills the dict `RESULT`; an exception sets RESULT["ok"] = False and "error". So does an entry of
    FreeCAD's log that `log_problems` finds (a traceback, error, warning or Qt message) unless one of the
    regular expressions `log_allowed` matches it: what a test provokes on purpose, such as an input error's
    one line. The log's text is RESULT["freecad_log"].
    Give `freecadcmd=path` for the console, or `gui=(xvfb_run, freecad)` for the GUI.
    """
    work.mkdir(parents=True, exist_ok=True)
    result_file = work / "result.json"
    result_file.unlink(missing_ok=True)
    script = work / "freecad_script.py"
    script.write_text(_PRELUDE + (_GUI_MAIN if gui else _CMD_MAIN))
    env = _environment(work, site_packages)
    body_file = work / "body.py"
    body_file.write_text(body)
    env["SPUR_CAD_BODY"] = str(body_file)
    env["SPUR_CAD_RESULT"] = str(result_file)
    log_file = work / LOG_NAME
    log_file.unlink(missing_ok=True)
    log_option = f"--log-file={log_file}"
    if gui:
        xvfb_run, freecad = gui
        # -a: the first free display from 99 up, judged by the lock files in /tmp. CI runs a chroot's tier beside the
        # host's tests: each chroot has its own /tmp but X's abstract sockets are shared, so each starts its search
        # at its own display (SPUR_CAD_XVFB_SERVERNUM, set by .ci/run) and the two never meet.
        first_display = os.environ.get("SPUR_CAD_XVFB_SERVERNUM", "99")
        cmd = [xvfb_run, "-a", "-n", first_display, "-s", "-screen 0 1280x1024x24", freecad, str(script), log_option]
        timeout_s = timeout_s or GUI_TIMEOUT_S
    else:
        cmd = [freecadcmd, str(script), log_option]
        timeout_s = timeout_s or CMD_TIMEOUT_S
    proc = run_in_session(cmd, env, work, timeout_s)
    result = json.loads(result_file.read_text()) if result_file.exists() else None
    log = log_file.read_text(errors="replace") if log_file.exists() else ""
    if result is not None:
        result["freecad_log"] = log
        problems = log_problems(log, log_allowed) if log else [f"FreeCAD wrote no log file {log_file}"]
        if problems and result.get("ok"):
            result["ok"] = False
            result["error"] = "FreeCAD's log holds:\n" + "\n".join(problems)
    return result, proc


def describe(proc: subprocess.CompletedProcess, result: dict | None) -> str:
    """Failure text: exit status, result and the tail of FreeCAD's output."""
    error = ""
    if result is not None:
        error = f"error: {result.get('error')}\n" if result.get("error") else ""
        result = {key: value for key, value in result.items() if key not in ("freecad_log", "error")}
    return (f"{error}exit status {proc.returncode}; result {result!r}\n"
            f"--- stdout (tail)\n{proc.stdout[-3000:]}\n--- stderr (tail)\n{proc.stderr[-3000:]}")
