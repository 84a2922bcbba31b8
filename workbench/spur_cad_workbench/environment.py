"""Make spur_cad (and cadquery) importable inside FreeCAD from the environment recorded at installation.

`spur-cad install-freecad` writes `spur_cad_environment.json` into FreeCAD's user data folder:
the site-packages folders of the Python environment it ran in. FreeCAD runs the workbench's
Init.py at start-up, which calls `activate`; the folders go to the front of sys.path (so that
environment's numpy wins over the system one) with their .pth files processed (editable installs).
Plain Python: no FreeCAD import, so the installer and the tests share it.
"""

from __future__ import annotations

import json
import site
import sys
from pathlib import Path

RECORD_NAME = "spur_cad_environment.json"


def record_path(user_app_data_dir: str | Path) -> Path:
    """Where the installer records the environment, inside FreeCAD's user data folder."""
    return Path(user_app_data_dir) / RECORD_NAME


def read_record(path: Path) -> dict | None:
    """The recorded environment, or None when spur_cad was not installed for this FreeCAD user."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        raise RuntimeError(f"cannot read {path}: {exc}; run `spur-cad install-freecad` again") from None


def _prefer_environment_portions(folders: list[str]) -> None:
    """Packages imported before activation (Debian's python3-matplotlib imports its regular
    `mpl_toolkits` package from a .pth file) search the environment's copy first, so that e.g.
    `mpl_toolkits.mplot3d` matches the environment's matplotlib."""
    for name, module in list(sys.modules.items()):
        search = getattr(module, "__path__", None)
        if "." in name or not isinstance(search, list):
            continue
        for folder in reversed(folders):
            candidate = str(Path(folder) / name)
            if Path(candidate).is_dir() and candidate not in search:
                search.insert(0, candidate)


def activate(user_app_data_dir: str | Path) -> list[str]:
    """Put the recorded site-packages folders at the front of sys.path; returns problems (empty: fine)."""
    record = read_record(record_path(user_app_data_dir))
    if record is None:
        return []
    problems = []
    wanted = record.get("python_version", "")
    running = f"{sys.version_info[0]}.{sys.version_info[1]}"
    if wanted and wanted != running:
        problems.append(f"spur_cad was installed from Python {wanted} but FreeCAD runs Python {running}; "
                        "install it from a Python " + running + " environment")
    folders = [folder for folder in record.get("site_packages", []) if folder not in sys.path]
    for folder in folders:
        if not Path(folder).is_dir():
            problems.append(f"recorded site-packages folder {folder} does not exist; "
                            "run `spur-cad install-freecad` again")
    before = list(sys.path)
    for folder in folders:
        if Path(folder).is_dir():
            site.addsitedir(folder)  # appends the folder and the paths of its .pth files
    added = [entry for entry in sys.path if entry not in before]
    sys.path[:] = added + [entry for entry in sys.path if entry not in added]
    _prefer_environment_portions(folders)
    numpy = sys.modules.get("numpy")
    numpy_file = str(getattr(numpy, "__file__", "") or "")
    provided = [folder for folder in folders if (Path(folder) / "numpy").is_dir()]
    if numpy is not None and provided and not any(numpy_file.startswith(folder) for folder in provided):
        problems.append(f"numpy was already loaded from {numpy_file} before spur_cad's environment was added; "
                        "spur_cad may not work (another add-on imported numpy first)")
    return problems
