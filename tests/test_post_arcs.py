"""Arcs in the toolpath IR (3-axis programs, [machine] axes = 3): G2/G3 with I/J incremental centres in every
dialect, read back here by a small independent parser and by LinuxCNC's own interpreter (rs274's ARC_FEED)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder, arc_sweeps_rad
from spur_cad.dialects import DIALECTS
from spur_cad.errors import PostError
from spur_cad.post import ProgramInfo, post_program
from spur_cad.post.settings import PostSettings
from spur_cad.verify.reader import ProgramReadError, read_program
from tests.rs274_helper import canon_args, run_rs274

INFO = ProgramInfo("arcs", (), writes_a=False)


def arc_path():
    """A rapid, a plunge, then arcs both ways: a quarter, more than a half turn, an off-axis centre."""
    b = ToolpathBuilder(Operation.FINISHING, 3, 6000.0)
    b.move(MoveKind.RAPID, 12.0, 0.0, 3.0, 0.0)
    b.move(MoveKind.LINEAR, 12.0, 0.0, -1.5, 0.0, 200.0)
    b.arc(False, 0.0, 12.0, -1.5, 0.0, 0.0, 400.0)  # quarter, counterclockwise
    b.arc(True, 8.48528137, -8.48528137, -1.5, 0.0, 0.0, 400.0)  # 270 deg clockwise
    cx, cy, r = 5.123456, -3.3, 3.35
    b.move(MoveKind.LINEAR, cx + r, cy, -1.5, 0.0, 350.0)
    b.arc(False, cx + r * math.cos(2.0), cy + r * math.sin(2.0), -1.5, cx, cy, 350.0)
    b.move(MoveKind.RAPID, cx + r * math.cos(2.0), cy + r * math.sin(2.0), 3.0, 0.0)
    return b.build()


def parsed_arcs(text: str):
    """(G code, end x, end y, centre x, centre y) of every G2/G3 block, centres = start + (I, J)."""
    position, motion, arcs = [math.nan, math.nan], None, []
    for line in text.splitlines():
        words = dict(re.findall(r"\b([GXYIJ])(-?\d+\.?\d*)", line.split(";")[0].split("(")[0]))
        g_words = re.findall(r"\bG(\d+)", line)
        for g in g_words:
            if g in ("0", "1", "2", "3"):
                motion = g
        end = [float(words.get("X", position[0])), float(words.get("Y", position[1]))]
        if motion in ("2", "3") and ("X" in words or "Y" in words):
            arcs.append((motion, *end, position[0] + float(words["I"]), position[1] + float(words["J"])))
        position = end
    return arcs


@pytest.mark.parametrize("name", list(DIALECTS))
def test_every_dialect_writes_g2_g3_with_incremental_centres(name):
    path = arc_path()
    text = post_program(path, PostSettings(dialect=name), INFO).text
    unit = 10.0 ** -DIALECTS[name].linear_decimals
    arcs = parsed_arcs(text)
    expected = np.flatnonzero(path.arc_mask)
    assert [a[0] for a in arcs] == ["2" if path.kind[i] == MoveKind.ARC_CW else "3" for i in expected]
    for (_, x, y, cx, cy), i in zip(arcs, expected):
        assert abs(x - path.x[i]) <= unit and abs(y - path.y[i]) <= unit
        assert abs(cx - path.center_x[i]) <= 1.5 * unit and abs(cy - path.center_y[i]) <= 1.5 * unit
    assert "A" not in re.sub(r"\(.*?\)|;.*", "", text).replace("M", "")  # no rotary axis words
    assert " A" not in text


@pytest.mark.linuxcnc
def test_rs274_reads_the_arcs_as_the_ir_has_them(tmp_path):
    path = arc_path()
    program = tmp_path / "arcs.ngc"
    program.write_text(post_program(path, PostSettings(), INFO).text)
    ok, canon, messages = run_rs274(program)
    assert ok, messages
    arcs = [canon_args(line) for line in canon if line.startswith("ARC_FEED")]
    expected = np.flatnonzero(path.arc_mask)
    assert len(arcs) == len(expected)
    _, sweep = arc_sweeps_rad(path)
    for args, i in zip(arcs, expected):
        end_x, end_y, cx, cy, rotation, z = args[:6]
        assert abs(end_x - path.x[i]) < 1e-4 and abs(end_y - path.y[i]) < 1e-4 and abs(z - path.z[i]) < 1e-4
        assert abs(cx - path.center_x[i]) < 2e-4 and abs(cy - path.center_y[i]) < 2e-4
        assert rotation == math.copysign(1.0, sweep[i])


def test_a_full_turn_and_a_rotary_move_without_a_rotary_axis_are_refused():
    b = ToolpathBuilder(Operation.FINISHING, 3, 6000.0)
    b.move(MoveKind.RAPID, 5.0, 0.0, 0.0, 0.0)
    b.arc(True, 5.0, 0.0, 0.0, 0.0, 0.0, 100.0)
    with pytest.raises(PostError, match="full turn"):
        post_program(b.build(), PostSettings(), INFO)
    b = ToolpathBuilder(Operation.FINISHING, 3, 6000.0)
    b.move(MoveKind.RAPID, 5.0, 0.0, 0.0, 30.0)
    with pytest.raises(PostError, match="no rotary axis"):
        post_program(b.build(), PostSettings(), INFO)


def test_the_verify_reader_refuses_arcs_naming_rs274():
    text = post_program(arc_path(), PostSettings(), INFO).text
    with pytest.raises(ProgramReadError, match=r"A unknown; a 3-axis program"):
        read_program(text, "linuxcnc")
    with pytest.raises(ProgramReadError, match=r"G3 \(an arc\) is not read.*rs274"):
        read_program(text.replace("G0 X12.0 Y0.0 Z3.0", "G0 X12.0 Y0.0 Z3.0 A0"), "linuxcnc")
