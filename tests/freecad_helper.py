"""Run Python code inside Debian's FreeCAD 0.20 (`freecadcmd`, or `freecad` under `xvfb-run`).

Found on this machine: `freecadcmd script.py` runs the file and exits, but exits 0 even
when the script raises (it only prints "Exception while processing file: ..."), and
`freecadcmd --version` segfaults after printing. `freecad script.py` (GUI) runs the file once
the main window exists and then stays open, also after an exception. So the code runs
wrapped: it writes a JSON result file (`{"ok": true, ...}` or `{"ok": false, "error": ...}`)
and, in the GUI, closes the main window in a `finally`. As root the GUI needs
QTWEBENGINE_DISABLE_SANDBOX=1 (else Chromium's zygote aborts and freecad exits 1).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
from pathlib import Path

GUI_TIMEOUT_S = 180.0
CMD_TIMEOUT_S = 120.0

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


def run_freecad_code(body: str, work: Path, *, freecadcmd: str | None = None,
                     gui: tuple[str, str] | None = None, site_packages: str | None = None,
                     timeout_s: float | None = None) -> tuple[dict | None, subprocess.CompletedProcess]:
    """Run `body` in FreeCAD; return (RESULT dict or None if none was written, process).

    `body` fills the dict `RESULT`; an exception sets RESULT["ok"] = False and "error".
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
    if gui:
        xvfb_run, freecad = gui
        cmd = [xvfb_run, "-a", "-s", "-screen 0 1280x1024x24", freecad, str(script)]
        timeout_s = timeout_s or GUI_TIMEOUT_S
    else:
        cmd = [freecadcmd, str(script)]
        timeout_s = timeout_s or CMD_TIMEOUT_S
    proc = run_in_session(cmd, env, work, timeout_s)
    result = json.loads(result_file.read_text()) if result_file.exists() else None
    return result, proc


def describe(proc: subprocess.CompletedProcess, result: dict | None) -> str:
    """Failure text: exit status, result and the tail of FreeCAD's output."""
    return (f"exit status {proc.returncode}; result {result!r}\n"
            f"--- stdout (tail)\n{proc.stdout[-3000:]}\n--- stderr (tail)\n{proc.stderr[-3000:]}")
