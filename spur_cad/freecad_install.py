"""`spur-cad install-freecad`: make the workbench and this environment's spur_cad available to the user's FreeCAD.

Installing puts into each user data folder a FreeCAD of this user may take (`user_data_dirs`) a
symbolic link `Mod/spur_cad` to the addon folder (package.xml, workbench/, resources/icons/: the
source checkout of an editable install, or the copy a wheel installs as spur_cad/freecad_addon/) and
a record `spur_cad_environment.json` of this environment's site-packages folders; the workbench's
Init.py adds them to FreeCAD's sys.path at start-up (spur_cad_workbench.environment). A copy of this
workbench that the Addon Manager put in `Mod/spur_cad` is kept: only the record is written beside
it. Uninstalling removes the links and records. No FreeCAD import: this only manages files.

FreeCAD's user data folder on Linux, as FreeCAD's sources decide it (App/Application.cpp up to 1.0,
App/ApplicationDirectories.cpp from 1.1; docs/install.md). This module is the one place here that
knows it:
- FREECAD_USER_DATA, else FREECAD_USER_HOME, naming an existing folder: that folder, in every version;
- 0.20 and 1.0: `$XDG_DATA_HOME/FreeCAD` (an absolute XDG_DATA_HOME), else `$HOME/.local/share/FreeCAD`;
- 1.1 and later: in that folder, the newest versioned subfolder `v<major>-<minor>` not newer than the
  running FreeCAD; the folder itself when it has none (settings not migrated yet); the running
  version's subfolder, created at first start, when the folder does not exist at all.
"""

from __future__ import annotations

import json
import os
import re
import sys
import sysconfig
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from spur_cad.errors import SpurCadError
from spur_cad.outputs import write_file_atomically
from spur_cad.version import __version__

ADDON_NAME = "spur_cad"
RECORD_NAME = "spur_cad_environment.json"  # = spur_cad_workbench.environment.RECORD_NAME
PACKAGED_ADDON = "freecad_addon"  # spur_cad/freecad_addon/: the addon folder inside an installed wheel
FIRST_VERSIONED = (1, 1)  # the first FreeCAD whose user data folder has a version subfolder
_VERSIONED_NAME = re.compile(r"v(\d+)-(\d+)")


@dataclass(frozen=True)
class InstallPaths:
    """Where the installation goes in one FreeCAD user data folder."""

    user_data_dir: Path  # FreeCAD's user data folder
    link: Path  # <user data>/Mod/spur_cad -> the addon folder
    record: Path  # <user data>/spur_cad_environment.json


def custom_user_data_dir(env: Mapping[str, str]) -> Path | None:
    """The folder FREECAD_USER_DATA (else FREECAD_USER_HOME) names, if it exists: FreeCAD then uses it
    as it is, in every version; None when neither is set to an existing folder (FreeCAD ignores them)."""
    for name in ("FREECAD_USER_DATA", "FREECAD_USER_HOME"):
        value = env.get(name, "")
        if value and Path(value).is_dir():
            return Path(value).resolve()
    return None


def freecad_data_root(env: Mapping[str, str]) -> Path:
    """$XDG_DATA_HOME/FreeCAD (an absolute XDG_DATA_HOME), else ~/.local/share/FreeCAD: the user data
    folder of FreeCAD 0.20 and 1.0, and the folder holding 1.1's versioned ones."""
    xdg = env.get("XDG_DATA_HOME", "")
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / "FreeCAD"
    home = env.get("HOME", "")
    if not home:
        raise SpurCadError("HOME is not set: cannot find FreeCAD's user folder")
    return Path(home) / ".local" / "share" / "FreeCAD"


def version_folder_name(version: tuple[int, int]) -> str:
    """FreeCAD's name for the user data subfolder of version (major, minor): v1-1 for 1.1."""
    return f"v{version[0]}-{version[1]}"


def versioned_folders(root: Path) -> dict[tuple[int, int], Path]:
    """The subfolders of `root` that FreeCAD 1.1 and later take as versioned user data folders
    (v<major>-<minor>, major >= 1, minor <= 99, as FreeCAD searches them), oldest version first."""
    found = {}
    if root.is_dir():
        for entry in root.iterdir():
            match = _VERSIONED_NAME.fullmatch(entry.name)
            if match and entry.is_dir():
                version = (int(match[1]), int(match[2]))
                if version[0] >= 1 and version[1] <= 99:
                    found[version] = entry
    return dict(sorted(found.items()))


def user_data_dir(env: Mapping[str, str], version: tuple[int, int]) -> Path:
    """The user data folder FreeCAD `version` (major, minor) takes when it starts, given the folders there now."""
    custom = custom_user_data_dir(env)
    if custom is not None:
        return custom
    root = freecad_data_root(env)
    if version < FIRST_VERSIONED:
        return root
    if not root.exists():
        return root / version_folder_name(version)
    usable = [folder for found, folder in versioned_folders(root).items() if found <= version]
    return usable[-1] if usable else root


def user_data_dirs(env: Mapping[str, str]) -> list[Path]:
    """Every user data folder a FreeCAD from 0.20 on may take for this user: the folder FREECAD_USER_DATA
    (or FREECAD_USER_HOME) names; else the unversioned folder (0.20, 1.0, and later versions while they
    find no versioned one: it exists once something is installed into it) and each versioned one present."""
    custom = custom_user_data_dir(env)
    if custom is not None:
        return [custom]
    root = freecad_data_root(env)
    return [root, *versioned_folders(root).values()]


def _users(folder: Path, env: Mapping[str, str]) -> str:
    """Which FreeCAD versions take `folder` (for the messages)."""
    if custom_user_data_dir(env) is not None:
        return "every FreeCAD version (FREECAD_USER_DATA / FREECAD_USER_HOME)"
    match = _VERSIONED_NAME.fullmatch(folder.name)
    if match and folder.parent == freecad_data_root(env):
        return f"FreeCAD {match[1]}.{match[2]}"
    return "FreeCAD 0.20 and 1.0, and later versions until they have a versioned folder"


def install_paths(user_data: Path) -> InstallPaths:
    return InstallPaths(user_data, user_data / "Mod" / ADDON_NAME, user_data / RECORD_NAME)


def _is_addon(folder: Path) -> bool:
    return (folder / "package.xml").is_file() and (folder / "workbench" / "InitGui.py").is_file()


def addon_root() -> Path:
    """The addon folder (package.xml, workbench/, resources/icons/): the source checkout this spur_cad
    lives in (an editable install), else the copy a wheel installed as spur_cad/freecad_addon/."""
    package = Path(__file__).resolve().parent
    for candidate in (package.parent, package / PACKAGED_ADDON):
        if _is_addon(candidate):
            return candidate
    raise SpurCadError(f"no FreeCAD addon with this spur_cad (neither {package.parent} nor {package / PACKAGED_ADDON} "
                       "holds package.xml and workbench/InitGui.py): reinstall spur_cad from its wheel or a source "
                       "checkout")


def package_name_and_version(folder: Path) -> tuple[str, str] | None:
    """<name> and <version> of folder/package.xml; None when it is missing or unreadable."""
    try:
        root = ET.parse(folder / "package.xml").getroot()
    except (OSError, ET.ParseError):
        return None
    fields = {child.tag.rsplit("}", 1)[-1]: (child.text or "").strip() for child in root}
    return fields.get("name", ""), fields.get("version", "")


def _is_addon_manager_copy(link: Path) -> bool:
    """A real folder holding this workbench (its package.xml names spur_cad): what the Addon Manager installs."""
    found = package_name_and_version(link) if link.is_dir() and not link.is_symlink() else None
    return found is not None and found[0] == ADDON_NAME


def _check_replaceable(where: InstallPaths) -> None:
    """Refuse (before anything changes) a Mod/spur_cad that is neither our link nor a copy of this workbench."""
    if where.link.is_symlink() or not where.link.exists() or _is_addon_manager_copy(where.link):
        return
    raise SpurCadError(f"{where.link} exists and is not a link made by `spur-cad install-freecad` nor a copy of "
                       "this workbench; remove it first")


def site_packages() -> list[str]:
    """This environment's site-packages folders (pure and platform-specific)."""
    paths = sysconfig.get_paths()
    return list(dict.fromkeys([paths["purelib"], paths["platlib"]]))


MAX_RECORD_BYTES = 64 * 1024


def _own_folders(where: InstallPaths) -> set[Path]:
    """The folders an install may create and an uninstall may remove again when empty: `Mod`, the user data
    folder and, for a versioned one (FreeCAD 1.1's `v1-1`), the folder above it; never a folder above those
    (`~/.local/share` stays even when installing created it)."""
    folders = {where.link.parent, where.user_data_dir}
    if _VERSIONED_NAME.fullmatch(where.user_data_dir.name):
        folders.add(where.user_data_dir.parent)
    return folders


def _missing_folders(where: InstallPaths) -> list[Path]:
    """The folders of _own_folders that do not exist yet (installing creates them)."""
    return [folder for folder in _own_folders(where) if not folder.exists() and not folder.is_symlink()]


def _recorded_folders(where: InstallPaths) -> list[Path]:
    """The folders an earlier install recorded as its own creation, as far as they are folders on the way to the
    link (the record is a file on disk: anything else in it is ignored, never acted on)."""
    from spur_cad.inputs import read_regular_file

    try:
        record = json.loads(read_regular_file(where.record, "install record", MAX_RECORD_BYTES))
    except (SpurCadError, OSError, ValueError):
        return []
    listed = record.get("created_folders") if isinstance(record, dict) else None
    ours = _own_folders(where)
    return [Path(p) for p in listed if isinstance(p, str) and Path(p) in ours] if isinstance(listed, list) else []


def _install_one(where: InstallPaths, root: Path, users: str) -> str:
    """Link the addon (or keep the Addon Manager's copy) and write the record in one user data folder (with the
    folders this created, so that uninstalling leaves none of them empty behind)."""
    created = _recorded_folders(where)
    if _is_addon_manager_copy(where.link):
        addon = where.link
        _, version = package_name_and_version(addon) or ("", "")
        done = (f"kept the copy of the workbench in {where.link} (the Addon Manager's or a clone; version {version}, "
                f"this spur_cad is {__version__}) for {users}")
    else:
        if where.link.is_symlink():
            where.link.unlink()
        created += _missing_folders(where)
        where.link.parent.mkdir(parents=True, exist_ok=True)
        where.link.symlink_to(root, target_is_directory=True)
        addon = root
        done = f"linked {where.link} -> {root} for {users}"
    record = {"spur_cad_version": __version__, "addon": str(addon), "python": sys.executable,
              "python_version": f"{sys.version_info[0]}.{sys.version_info[1]}",
              "site_packages": site_packages(),
              "created_folders": sorted({str(folder) for folder in created}, key=len, reverse=True)}
    write_file_atomically(where.record, (json.dumps(record, indent=2) + "\n").encode())
    return done


def install(env: Mapping[str, str]) -> list[str]:
    """Link the addon into every FreeCAD user data folder of this user and record this environment there;
    returns what was done. Every folder is checked before any is changed."""
    root = addon_root()
    targets = [install_paths(folder) for folder in user_data_dirs(env)]
    for where in targets:
        _check_replaceable(where)
    done = []
    for where in targets:
        try:
            done.append(_install_one(where, root, _users(where.user_data_dir, env)))
        except OSError as exc:
            raise SpurCadError(f"cannot install into {where.user_data_dir}: {exc.strerror or exc}") from None
    records = ", ".join(str(where.record) for where in targets)
    return [*done, f"recorded this environment ({', '.join(site_packages())}) in {records}",
            "restart FreeCAD and choose the spur_cad workbench; undo with `spur-cad install-freecad --uninstall`"]


def _uninstall_one(where: InstallPaths) -> list[str]:
    """Remove the link and the record, then the folders installing created, where they are empty now (deepest
    first; a folder holding anything, or that is a link, stays)."""
    done = []
    created = _recorded_folders(where)
    if where.link.is_symlink():
        where.link.unlink()
        done.append(f"removed {where.link}")
    elif where.link.exists():
        done.append(f"left {where.link}: a copy of the workbench (remove it with the Addon Manager or by hand)")
    if where.record.exists():
        where.record.unlink()
        done.append(f"removed {where.record}")
    for folder in sorted(created, key=lambda path: len(path.parts), reverse=True):
        try:
            if folder.is_dir() and not folder.is_symlink() and not any(folder.iterdir()):
                folder.rmdir()
                done.append(f"removed the empty folder {folder} (made by the install)")
        except OSError:  # something arrived in it meanwhile, or it cannot be read: it stays
            continue
    return done


def uninstall(env: Mapping[str, str]) -> list[str]:
    """Remove the links and records made by `install` from every user data folder; returns what was done.
    An Addon Manager copy is left to the Addon Manager."""
    targets = [install_paths(folder) for folder in user_data_dirs(env)]
    for where in targets:
        if where.link.exists() and not where.link.is_symlink() and not _is_addon_manager_copy(where.link):
            raise SpurCadError(f"{where.link} is not a link made by `spur-cad install-freecad`; left as it is")
    done = []
    for where in targets:
        try:
            done.extend(_uninstall_one(where))
        except OSError as exc:
            raise SpurCadError(f"cannot uninstall from {where.user_data_dir}: {exc.strerror or exc}") from None
    folders = ", ".join(str(where.user_data_dir) for where in targets)
    return done or [f"nothing to uninstall in {folders}"]
