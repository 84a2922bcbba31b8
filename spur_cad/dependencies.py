"""Optional parts of spur_cad's environment, checked before the work that needs them starts.

OCP (OpenCascade's Python binding) comes from one of three extras, because PyPI ships it as two distributions
that install the same `OCP` package (`cadquery-ocp` for CadQuery, `cadquery-ocp-novtk` for build123d): a run
without it must say which to install, not fail in the CAD worker. Jinja2 is report.html's engine; FreeCAD's
Addon Manager cannot install it (it is not on FreeCAD's allow-list), so a report made from the workbench
without it must say how to add it. `importlib.util.find_spec` looks without importing (OCP's import costs
a second and is done in the CAD worker).
"""

from __future__ import annotations

import importlib.util

from spur_cad.errors import SpurCadError

OCP_INSTALL_HINT = ("install spur_cad with one of its CAD extras: pip install 'spur_cad[cadquery]' (CadQuery 2.8, "
                    "OCP 7.9), 'spur_cad[build123d]' (build123d 0.13, OCP 8.0) or 'spur_cad[ocp]' (OCP alone)")
JINJA2_INSTALL_HINT = ("install it into the Python that runs spur_cad: `python3 -m pip install jinja2` (in FreeCAD: "
                       "the same command with FreeCAD's Python, or `--target` its AdditionalPythonPackages folder; "
                       "see docs/install.md)")


class MissingDependencyError(SpurCadError, ImportError):
    """A package spur_cad needs for the work asked of it is not installed; the message says what to install."""


def is_installed(module_name: str) -> bool:
    """Whether `module_name` can be imported here (looked up, not imported)."""
    try:
        return importlib.util.find_spec(module_name) is not None
    except (ImportError, ValueError):
        return False


def require_ocp() -> None:
    """Refuse, with what to install, when OCP is missing: the gear solid, STEP and OCP checks need it."""
    if not is_installed("OCP"):
        raise MissingDependencyError(f"the CAD kernel OCP is not installed; {OCP_INSTALL_HINT}")


def require_jinja2() -> None:
    """Refuse, with what to install, when Jinja2 (report.html's template engine) is missing."""
    if not is_installed("jinja2"):
        raise MissingDependencyError(f"report.html is made with Jinja2, which is not installed; {JINJA2_INSTALL_HINT}")
