"""No user text or absurd number reaches a program as anything but an inert comment or a refusal.

Programs are read back by the independent reader (tests/gcode_reader.py) and, for LinuxCNC, by
rs274; hostile titles and comments must not change a single move, no line may exceed the
dialect's limit, and each comment stays one line."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from spur_cad.cam.ir import Feature, MoveKind, Operation, ToolpathBuilder
from spur_cad.cam.machine import Machine, MachineError
from spur_cad.dialects import DIALECTS
from spur_cad.errors import SpurCadError
from spur_cad.post import PostSettings, ProgramInfo, dialect, post_program
from spur_cad.post.settings import PostError
from tests.gcode_reader import read_program
from tests.rs274_helper import canon_args, run_rs274

HOSTILE = ("evil\nG0 X0 Y0 Z-50\nM30", "cr\rG0 Z-50", "nul\x00G0 Z-50", "tab\tG1 Z-50 F1", "(paren) G0 Z-50",
           "semi; G0 Z-50", "%\nG0 Z-50", "MSG,hello", " logopen,/tmp/x.txt", "ABORT, stop",
           "py,import os", "Zahnrad \u00e4\u00f6\u00fc \u2699 G0 Z-50", "x" * 10_000 + " G0 Z-50")


def two_space_toolpath():
    """Two tooth spaces with identical patterns (so folding applies): rapid, plunge, a cut, a G93 move."""
    builder = ToolpathBuilder(Operation.FINISHING, 2, 7000.0)
    for k, base in enumerate((0.0, -90.0)):
        builder.move(MoveKind.RAPID, 0.0, 1.0, 30.0, base, space=k)
        builder.move(MoveKind.LINEAR, 0.0, 1.0, 20.0, base, 100.0, space=k)
        builder.move(MoveKind.LINEAR, 5.0, 1.0, 20.0, base, 200.0, space=k, feature=Feature.ROOT)
        builder.move(MoveKind.LINEAR, 5.0, -1.0, 20.0, base + 3.0, 50.0, inverse_time=True, space=k,
                     feature=Feature.ROOT)
        builder.move(MoveKind.LINEAR, 5.0, -1.0, 30.0, base + 3.0, 200.0, space=k)
    return builder.build()


def moves(text: str, name: str) -> list[tuple[bool, tuple[float, ...]]]:
    return [(m.rapid, tuple(round(v, 3) for v in m.end)) for m in read_program(text, name).moves]


@pytest.mark.parametrize("name", sorted(DIALECTS))
@pytest.mark.parametrize("folded", [True, False])
@pytest.mark.parametrize("hostile", HOSTILE, ids=range(len(HOSTILE)))
def test_hostile_text_is_an_inert_comment(name, folded, hostile):
    path = two_space_toolpath()
    settings = PostSettings(dialect=name, folded=folded)
    plain = post_program(path, settings, ProgramInfo("title", ("comment", "gear: comment"))).text
    text = post_program(path, settings, ProgramInfo(hostile, (hostile, "gear: " + hostile))).text
    assert moves(text, name) == moves(plain, name)  # not one move more, less or different
    limit = dialect(name).max_line_length
    assert max(len(line) for line in text.splitlines()) <= limit
    assert len(text.splitlines()) == len(plain.splitlines())  # every comment stayed one line
    assert text.isascii() and "\x00" not in text and "\r" not in text
    body = [line for line in text.splitlines() if "Z-50" in line.replace(" ", "")]
    assert all(line.startswith(("(", ";")) or "(" in line for line in body), body  # only inside comments
    if dialect(name).percent_delimited:
        assert text.count("%") == 2


@pytest.mark.linuxcnc
@pytest.mark.parametrize("hostile", HOSTILE, ids=range(len(HOSTILE)))
def test_rs274_reads_the_same_moves_with_hostile_text(hostile, tmp_path):
    path = two_space_toolpath()
    results = []
    for index, title in enumerate(("title", hostile)):
        program = tmp_path / f"p{index}.ngc"
        program.write_text(post_program(path, PostSettings(), ProgramInfo(title, (title,))).text)
        ok, canon, messages = run_rs274(program)
        assert ok, messages
        results.append([canon_args(line)[:4] for line in canon if line.startswith(("STRAIGHT_", "ARC_"))])
        active = [line for line in canon if line.startswith(("MESSAGE", "LOG", "PROBE", "PY", "ABORT"))]
        assert not active, active  # a comment the interpreter would act on
    assert results[0] == results[1]


@pytest.mark.parametrize("code", ["M10\nG0 Z-50", "M10 G0 Z-50", "(x)", "G0", "M", "M10;", "M100000", "M30", "M2",
                                  "M0", "M99", "M98", "M6", "M10\n", "M\u0661\u0660"])
def test_clamp_codes_other_than_one_m_code_are_refused(code):
    with pytest.raises(MachineError, match="rotary_clamp_code"):
        Machine(rotary_clamp_code=code)
    with pytest.raises(SpurCadError, match="rotary_clamp_code"):
        post_program(two_space_toolpath(), PostSettings(), ProgramInfo("t", (), rotary_clamp_code=code))


def test_valid_clamp_codes_are_written_as_their_own_blocks():
    machine = Machine(rotary_clamp_code="M10", rotary_unclamp_code="M11")  # made: its checks pass
    assert (machine.rotary_clamp_code, machine.rotary_unclamp_code) == ("M10", "M11")


@pytest.mark.parametrize("change, words", [
    ({"x": math.nan}, "X value"), ({"z": math.inf}, "Z value"), ({"y": 1e9}, "Y value"),
    ({"feed": 1e-300}, "F0"), ({"feed": math.inf}, "no usable feed"), ({"tool_number": 2**63 - 1}, "tool number"),
    ({"spindle_rpm": 1e-300}, "S0"), ({"spindle_rpm": math.nan}, "S0"),
])
def test_absurd_numbers_are_refused(change, words):
    path = two_space_toolpath()
    replaced = {}
    for key, value in change.items():
        if key in ("tool_number", "spindle_rpm"):
            replaced[key] = value
        else:
            array = getattr(path, key).copy()
            array[2] = value
            replaced[key] = array
    with pytest.raises(PostError, match=words):
        post_program(dataclasses.replace(path, **replaced), PostSettings(), ProgramInfo("t", ()))
    assert np.isfinite(two_space_toolpath().x).all()
