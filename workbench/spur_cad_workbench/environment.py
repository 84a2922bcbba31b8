"""Make spur_cad and its dependencies importable inside FreeCAD, by either of the two ways it gets there.

- `spur-cad install-freecad` (pip users) writes `spur_cad_environment.json` into FreeCAD's user data
  folder: the site-packages folders of the Python environment it ran in. `activate` puts them at the
  front of sys.path (so that environment's numpy wins over the system one) with their .pth files
  processed (editable installs).
- The Addon Manager clones the whole repository into `Mod/spur_cad/`, so the `spur_cad` package sits in
  the addon's own folder (`Mod/spur_cad/spur_cad/`), and pip-installs package.xml's Python dependencies
  into `AdditionalPythonPackages/py3XY` (0.20: `AdditionalPythonPackages`) of the user data folder, which
  FreeCAD appends to sys.path before it runs any Init.py. FreeCAD 0.20 to 1.1 also put every `Mod/<addon>`
  folder itself at the front of sys.path (src/App/FreeCADInit.py), which makes that spur_cad importable
  already; with no record `activate` appends the addon's folder only where spur_cad is not importable
  (a FreeCAD that stops doing so, or a workbench folder put on sys.path by hand).

FreeCAD runs the workbench's Init.py at start-up, which calls `activate`. Plain Python: no FreeCAD import,
so the installer and the tests share it.
"""

from __future__ import annotations

import importlib.util
import json
import site
import sys
from collections.abc import Callable
from pathlib import Path

RECORD_NAME = "spur_cad_environment.json"
# The addon's folder: <addon>/workbench/spur_cad_workbench/environment.py (as FreeCAD found it: a link to a
# checkout stays the link, which holds the same files).
ADDON_FOLDER = Path(__file__).absolute().parents[2]


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


def use_addon_folder(addon_folder: Path) -> bool:
    """Append `addon_folder` to sys.path when it holds the spur_cad package and no spur_cad is importable
    yet (an Addon Manager copy or a clone of the repository); returns whether it was appended. Appended,
    not put in front: the repository's other top-level folders (tests, docs, ...) shadow nothing."""
    if importlib.util.find_spec("spur_cad") is not None:
        return False
    if not (addon_folder / "spur_cad" / "__init__.py").is_file():
        return False
    sys.path.append(str(addon_folder))
    importlib.invalidate_caches()
    return True


def activate(user_app_data_dir: str | Path, addon_folder: Path | None = None,
             log: Callable[[str], None] | None = None) -> list[str]:
    """Make spur_cad importable: the recorded site-packages folders at the front of sys.path, or without a
    record the addon's own folder (`ADDON_FOLDER` unless given) at its end; returns problems (empty: fine).
    `log` receives what was done, for FreeCAD's log."""
    record = read_record(record_path(user_app_data_dir))
    if record is None:
        folder = ADDON_FOLDER if addon_folder is None else addon_folder
        if use_addon_folder(folder) and log is not None:
            log(f"no {RECORD_NAME}; spur_cad imported from the addon's folder {folder}")
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
