"""Smoke tests of the external tools the suite relies on: FreeCAD (console and GUI) and
LinuxCNC's G-code interpreter rs274."""

from __future__ import annotations

from pathlib import Path

import pytest

import spur_cad
from tests.freecad_helper import describe, run_freecad_code
from tests.rs274_helper import canon_args, run_rs274

CONSOLE_BODY = """
import FreeCAD, Part
box = Part.makeBox(10, 20, 30)
import numpy
import spur_cad
from spur_cad.geometry import GearSpec
spec = GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8,
                thickness_allowance_fraction=0.05, face_width_mm=20.0)
RESULT.update(box_volume=box.Volume, box_valid=box.isValid(),
              tip_radius_mm=spec.tip_radius_mm, freecad_version=FreeCAD.Version(),
              spur_cad_file=spur_cad.__file__, numpy_version=numpy.__version__)
"""

GUI_BODY = """
import FreeCAD, FreeCADGui
doc = FreeCAD.newDocument("Smoke")
box = doc.addObject("Part::Box", "Box")
doc.recompute()
RESULT.update(gui_up=bool(FreeCAD.GuiUp), main_window=FreeCADGui.getMainWindow() is not None,
              has_view_object=box.ViewObject is not None, box_volume=box.Shape.Volume)
"""


@pytest.mark.freecad
def test_freecadcmd_runs_part_and_spur_cad(freecadcmd, venv_site_packages, tmp_path):
    """freecadcmd builds a Part box and imports spur_cad from the venv."""
    result, proc = run_freecad_code(CONSOLE_BODY, tmp_path, freecadcmd=freecadcmd,
                                    site_packages=venv_site_packages)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["box_volume"] == pytest.approx(6000.0)
    assert result["box_valid"] is True
    assert result["tip_radius_mm"] == pytest.approx(50.0)
    assert tuple(int(part) for part in result["freecad_version"][:2]) >= (0, 20)
    assert Path(result["spur_cad_file"]).resolve() == Path(spur_cad.__file__).resolve()


@pytest.mark.freecad
def test_freecadcmd_reports_script_errors(freecadcmd, tmp_path):
    """An exception inside FreeCAD reaches the result file (freecadcmd itself exits 0)."""
    result, proc = run_freecad_code("raise ValueError('deliberate')", tmp_path, freecadcmd=freecadcmd)
    assert result is not None, describe(proc, result)
    assert result["ok"] is False
    assert "ValueError: deliberate" in result["error"]


@pytest.mark.freecad
def test_freecad_gui_under_xvfb(freecad_gui, tmp_path):
    """The FreeCAD GUI starts under xvfb-run, runs a script in its event loop and quits."""
    result, proc = run_freecad_code(GUI_BODY, tmp_path, gui=freecad_gui)
    assert result is not None and result.get("ok"), describe(proc, result)
    assert result["gui_up"] and result["main_window"] and result["has_view_object"]
    assert result["box_volume"] == pytest.approx(1000.0)
    assert proc.returncode == 0, describe(proc, result)


GOOD_PROGRAM = """G21 G90 G94
G0 X0 Y0 Z10 A0
G1 Z1 F100
G1 X10 A45
M2
"""


@pytest.mark.linuxcnc
def test_rs274_interprets_four_axis_program(rs274, tmp_path):
    """rs274 accepts a small X/A program and reports the feed move in canonical form."""
    program = tmp_path / "prog.ngc"
    program.write_text(GOOD_PROGRAM)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    feeds = [canon_args(line) for line in canon if line.startswith("STRAIGHT_FEED(")]
    assert len(feeds) == 2, canon
    x, y, z, a = feeds[-1][:4]
    assert (x, y, z, a) == pytest.approx((10.0, 0.0, 1.0, 45.0))
    assert feeds[0][:4] == pytest.approx([0.0, 0.0, 1.0, 0.0])
    assert any(line.startswith("PROGRAM_END") for line in canon)


@pytest.mark.linuxcnc
@pytest.mark.parametrize("bad_block, expected", [
    ("G7.7", "Unknown g code"),
    ("G1 X10", "zero feed rate"),
])
def test_rs274_reports_errors(rs274, tmp_path, bad_block, expected):
    """An invalid block makes rs274 fail with a readable message."""
    program = tmp_path / "bad.ngc"
    program.write_text(f"G21 G90 G94\nG0 X0 Y0 Z10\n{bad_block}\nM2\n")
    ok, canon, messages = run_rs274(program)
    assert not ok
    assert expected in messages
    assert bad_block in messages
    assert not any(line.startswith("PROGRAM_END") for line in canon)
