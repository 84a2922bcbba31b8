"""`spur-cad install-freecad`: make the workbench and this environment's spur_cad available to the user's FreeCAD.

FreeCAD 0.20 on Linux loads user add-ons from `$XDG_DATA_HOME/FreeCAD/Mod` (default
`~/.local/share/FreeCAD/Mod`). Installing puts a symbolic link `Mod/spur_cad` to the addon
folder (the source checkout holding package.xml, workbench/ and resources/) and records this
environment's site-packages folders in `FreeCAD/spur_cad_environment.json`; the workbench's
Init.py adds them to FreeCAD's sys.path at start-up (spur_cad_workbench.environment).
Uninstalling removes both. No FreeCAD import: this only manages files.
"""

from __future__ import annotations

import json
import os
import sys
import sysconfig
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from spur_cad import __version__
from spur_cad.errors import SpurCadError
from spur_cad.outputs import write_file_atomically

ADDON_NAME = "spur_cad"
RECORD_NAME = "spur_cad_environment.json"  # = spur_cad_workbench.environment.RECORD_NAME


@dataclass(frozen=True)
class InstallPaths:
    """Where the installation goes for one user."""

    user_data_dir: Path  # FreeCAD's user data folder
    link: Path  # <user data>/Mod/spur_cad -> the addon folder
    record: Path  # <user data>/spur_cad_environment.json


def freecad_user_data_dir(env: Mapping[str, str]) -> Path:
    """FreeCAD 0.20's user data folder on Linux: $XDG_DATA_HOME/FreeCAD, else ~/.local/share/FreeCAD."""
    xdg = env.get("XDG_DATA_HOME", "")
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / "FreeCAD"
    home = env.get("HOME", "")
    if not home:
        raise SpurCadError("HOME is not set: cannot find FreeCAD's user folder")
    return Path(home) / ".local" / "share" / "FreeCAD"


def install_paths(env: Mapping[str, str]) -> InstallPaths:
    data = freecad_user_data_dir(env)
    return InstallPaths(data, data / "Mod" / ADDON_NAME, data / RECORD_NAME)


def addon_root() -> Path:
    """The folder holding package.xml, workbench/ and resources/ (the source checkout of this spur_cad)."""
    root = Path(__file__).resolve().parent.parent
    if not (root / "package.xml").is_file() or not (root / "workbench" / "InitGui.py").is_file():
        raise SpurCadError(f"no FreeCAD addon next to this spur_cad ({root} has no package.xml and workbench/): "
                           "install-freecad needs spur_cad installed from a source checkout (pip install -e .)")
    return root


def site_packages() -> list[str]:
    """This environment's site-packages folders (pure and platform-specific)."""
    paths = sysconfig.get_paths()
    return list(dict.fromkeys([paths["purelib"], paths["platlib"]]))


def install(env: Mapping[str, str]) -> list[str]:
    """Link the addon into FreeCAD's user Mod folder and record this environment; returns what was done."""
    root = addon_root()
    where = install_paths(env)
    if where.link.exists() or where.link.is_symlink():
        if not where.link.is_symlink():
            raise SpurCadError(f"{where.link} exists and is not a link made by `spur-cad install-freecad` "
                               "(an Addon Manager copy?); remove it first")
        where.link.unlink()
    try:
        where.link.parent.mkdir(parents=True, exist_ok=True)
        where.link.symlink_to(root, target_is_directory=True)
        record = {"spur_cad_version": __version__, "addon": str(root), "python": sys.executable,
                  "python_version": f"{sys.version_info[0]}.{sys.version_info[1]}",
                  "site_packages": site_packages()}
        write_file_atomically(Path(where.user_data_dir) / RECORD_NAME, (json.dumps(record, indent=2) + "\n").encode())
    except OSError as exc:
        raise SpurCadError(f"cannot install into {where.user_data_dir}: {exc.strerror or exc}") from None
    return [f"linked {where.link} -> {root}",
            f"recorded this environment ({', '.join(record['site_packages'])}) in {where.record}",
            "restart FreeCAD and choose the spur_cad workbench; undo with `spur-cad install-freecad --uninstall`"]


def uninstall(env: Mapping[str, str]) -> list[str]:
    """Remove the link and the record made by `install`; returns what was done."""
    where = install_paths(env)
    done = []
    if where.link.is_symlink():
        where.link.unlink()
        done.append(f"removed {where.link}")
    elif where.link.exists():
        raise SpurCadError(f"{where.link} is not a link made by `spur-cad install-freecad`; left as it is")
    if where.record.exists():
        where.record.unlink()
        done.append(f"removed {where.record}")
    return done or [f"nothing to uninstall in {where.user_data_dir}"]
