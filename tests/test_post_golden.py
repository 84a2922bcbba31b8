"""Golden programs: a two-space toolpath (plunge, two simultaneous Y/Z/A moves, retract) in every
dialect, exact lines. Each was read line by line against the dialect's manual conventions
(docs/post.md) before it was pinned here; a change to any of them must be reviewed the same way."""

from __future__ import annotations

import pytest

from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder
from spur_cad.post import PostSettings, ProgramInfo, post_program


def two_space_path():
    """Space k at A = -90 k (a 4-tooth pattern), X = 5; the last move belongs to no space."""
    builder = ToolpathBuilder(Operation.FINISHING, 2, 6999.6)
    for k in range(2):
        base = -90.0 * k
        builder.move(MoveKind.RAPID, 5.0, -1.5, 12.0, base + 2.5, space=k)
        builder.move(MoveKind.LINEAR, 5.0, -1.5, 10.25, base + 2.5, 100.0, space=k)
        builder.move(MoveKind.LINEAR, 5.0, -1.0, 10.0, base + 1.25, 40.0, inverse_time=True, space=k)
        builder.move(MoveKind.LINEAR, 5.0, 0.0, 9.875, base, 50.0, inverse_time=True, space=k)
        builder.move(MoveKind.LINEAR, 5.0, 0.0, 12.0, base, 200.0, space=k)
    builder.move(MoveKind.RAPID, 5.0, 0.0, 20.0, -90.0)
    return builder.build()


INFO = ProgramInfo("spur_cad golden", ("gear: z = 4",))

GOLDEN = {
    "linuxcnc": """\
(spur_cad golden)
(gear: z = 4)
o1001 sub
G0 X#1 Y-1.5 Z12.0 A#2
G94 G1 Z10.25 F100.0
G93 Y-1.0 Z10.0 A[#2-1.25] F40.0
Y0.0 Z9.875 A[#2-2.5] F50.0
G94 Z12.0 F200.0
o1001 endsub
G21 G90 G94 G17 G40 G49 G80 G64 P0.001
G54
T2 M6
G43 H2
S7000 M3
M8
o1001 call [5.0] [2.5]
o1001 call [5.0] [-87.5]
G0 X5.0 Y0.0 Z20.0 A-90.0
M9
M5
M30
""",
    "fanuc": """\
%
O1000 (SPUR_CAD GOLDEN)
(GEAR: Z = 4)
G21 G90 G94 G17 G40 G49 G80
G54
T2 M06
G43 H2
S7000 M03
M08
G65 P1001 X5.0 A2.5
G65 P1001 X5.0 A-87.5
G0 X5.0 Y0.0 Z20.0 A-90.0
M09
M05
M30
O1001
G0 X#24 Y-1.5 Z12.0 A#1
G94 G1 Z10.25 F100.0
G93 Y-1.0 Z10.0 A[#1-1.25] F40.0
Y0.0 Z9.875 A[#1-2.5] F50.0
G94 Z12.0 F200.0
M99
%
""",
    "haas": """\
%
O01000 (SPUR_CAD GOLDEN)
(GEAR: Z = 4)
G21 G90 G94 G17 G40 G49 G80
G54
T2 M06
G43 H2
S7000 M03
M08
#101=5.0
#102=2.5
M97 P99999
#101=5.0
#102=-87.5
M97 P99999
G0 X5.0 Y0.0 Z20.0 A-90.0
M09
M05
M30
N99999
G0 X#101 Y-1.5 Z12.0 A#102
G94 G1 Z10.25 F100.0
G93 Y-1.0 Z10.0 A[#102-1.25] F40.0
Y0.0 Z9.875 A[#102-2.5] F50.0
G94 Z12.0 F200.0
M99
%
""",
    "siemens": """\
; spur_cad golden
; gear: z = 4
G71 G90 G94 G17 G40
G54
T2 D1
M6
S7000 M3
M8
R1=5.0 R2=2.5
SPACE1001:
G0 X=R1 Y-1.5 Z12.0 A=R2
G94 G1 Z10.25 F100.0
G93 Y-1.0 Z10.0 A=R2-1.25 F40.0
Y0.0 Z9.875 A=R2-2.5 F50.0
G94 Z12.0 F200.0
SPACE1001_END:
R1=5.0 R2=-87.5
REPEAT SPACE1001 SPACE1001_END P=1
G0 X5.0 Y0.0 Z20.0 A-90.0
M9
M5
M30
""",
    "okuma": """\
O1000 (SPUR_CAD GOLDEN)
(GEAR: Z = 4)
G21 G90 G94 G17 G40 G80
G15 H1
T2 M06
G56 H2
S7000 M03
M08
CALL O1001 XST=5.0 ASP=2.5
CALL O1001 XST=5.0 ASP=-87.5
G0 X5.0 Y0.0 Z20.0 A-90.0
M09
M05
M30
O1001
G0 X=XST Y-1.5 Z12.0 A=ASP
G94 G1 Z10.25 F100.0
Y-1.0 Z10.0 A=ASP-1.25 F54.8
Y0.0 Z9.875 A=ASP-2.5 F80.3
Z12.0 F200.0
RTS
""",
}


# Okuma has no G93 here: F = sqrt(dY^2 + dZ^2 + dA^2) / time, e.g. sqrt(0.5^2 + 0.25^2 + 1.25^2) * 40 = 54.8.
LINUXCNC_FLAT_NUMBERED = """\
(spur_cad golden)
(gear: z = 4)
N10 G21 G90 G94 G17 G40 G49 G80 G64 P0.001
N20 G54
N30 T2 M6
N40 G43 H2
N50 S7000 M3
N60 G0 X5.0 Y-1.5 Z12.0 A2.5
N70 G94 G1 Z10.25 F100.0
N80 G93 Y-1.0 Z10.0 A1.25 F40.0
N90 Y0.0 Z9.875 A0.0 F50.0
N100 G94 Z12.0 F200.0
N10 G0 X5.0 Y-1.5 Z12.0 A-87.5
N20 G94 G1 Z10.25 F100.0
N30 G93 Y-1.0 Z10.0 A-88.75 F40.0
N40 Y0.0 Z9.875 A-90.0 F50.0
N50 G94 Z12.0 F200.0
N60 G0 X5.0 Y0.0 Z20.0 A-90.0
N70 M5
N80 M30
"""


@pytest.mark.parametrize("dialect", list(GOLDEN))
def test_golden_folded_program(dialect):
    assert post_program(two_space_path(), PostSettings(dialect=dialect), INFO).text == GOLDEN[dialect]


def test_golden_flat_program_with_block_numbers_wrapping_at_100():
    settings = PostSettings(folded=False, line_numbers=True, line_number_step=10, max_line_number=100, coolant=False)
    assert post_program(two_space_path(), settings, INFO).text == LINUXCNC_FLAT_NUMBERED
