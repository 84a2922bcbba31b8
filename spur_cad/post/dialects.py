"""Controller dialects as data: one `Dialect` per controller, read by the one post in program.py.

What each dialect relies on is listed in docs/post.md. Only LinuxCNC is checked by an
interpreter here (rs274); the others follow their programming manuals and are pinned by
golden tests.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from spur_cad.errors import shown
from spur_cad.post.settings import PostError


@dataclass(frozen=True)
class Dialect:
    """Everything that differs between controllers; `{...}` fields are str.format templates."""

    name: str
    extension: str
    percent_delimited: bool  # the file starts and ends with a "%" line
    program_start: str  # first block, "" for none; {number}, {title}
    comment_style: str  # "paren" (...) or "semicolon" ; ...
    uppercase_comments: bool
    setup: str  # units, absolute, feed per minute, plane, cancel compensation / cycles
    tool_change: tuple[str, ...]  # {tool}
    spindle_on: str  # {rpm}
    coolant_on: str
    coolant_off: str
    spindle_off: str
    program_end: str
    linear_decimals: int
    rotary_decimals: int
    feed_decimals: int
    inverse_feed_decimals: int
    inverse_time: bool  # G93/G94 available; else F is compensated (docs/post.md)
    # Folding: how a space pattern is written once and called per space with its X and A base.
    fold_style: str  # "linuxcnc_sub", "macro_call" (Fanuc G65, Okuma CALL), "local_sub" (Haas M97), "repeat"
    x_param: str  # how the body names the X base
    a_param: str  # how the body names the A base
    param_word: str  # an address taking a parameter: {address}, {param}
    param_offset_word: str  # an address taking parameter + offset: {address}, {param}, {offset}
    sub_start: str  # {sub}
    sub_end: str  # {sub}
    call: tuple[str, ...]  # {sub}, {x}, {a}
    subprograms_after_end: bool  # else defined before the main body
    direction_codes: tuple[str, str] | None = None  # (positive, negative) A direction for wrapped A
    max_line_length: int = 128  # longest block the control takes (every line is checked; comments are cut to fit)
    work_offset: str = "{code}"  # selects the work offset; {code} is G54..G59, {number} 1..6 (Okuma's G15 H<n>)
    workpiece: str = ""  # the blank for the control's own simulation; {x_min} ... {z_max} of the blank's box


LINUXCNC = Dialect(
    name="linuxcnc", extension="ngc", max_line_length=250,
    percent_delimited=False, program_start="", comment_style="paren",
    uppercase_comments=False, setup="G21 G90 G94 G17 G40 G49 G80 G64 P0.001", tool_change=("T{tool} M6",
                                                                                           "G43 H{tool}"),
    spindle_on="S{rpm} M3", coolant_on="M8", coolant_off="M9", spindle_off="M5", program_end="M30",
    linear_decimals=4, rotary_decimals=4, feed_decimals=1, inverse_feed_decimals=4, inverse_time=True,
    fold_style="linuxcnc_sub", x_param="#1", a_param="#2", param_word="{address}{param}",
    param_offset_word="{address}[{param}{offset}]", sub_start="o{sub} sub", sub_end="o{sub} endsub",
    call=("o{sub} call [{x}] [{a}]",), subprograms_after_end=False)

FANUC = Dialect(
    name="fanuc", extension="nc", percent_delimited=True, program_start="O{number:04d} ({title})",
    comment_style="paren", uppercase_comments=True, setup="G21 G90 G94 G17 G40 G49 G80",
    tool_change=("T{tool} M06", "G43 H{tool}"), spindle_on="S{rpm} M03", coolant_on="M08", coolant_off="M09",
    spindle_off="M05", program_end="M30", linear_decimals=3, rotary_decimals=3, feed_decimals=1,
    inverse_feed_decimals=3, inverse_time=True, fold_style="macro_call", x_param="#24", a_param="#1",
    param_word="{address}{param}", param_offset_word="{address}[{param}{offset}]", sub_start="O{sub:04d}",
    sub_end="M99", call=("G65 P{sub:04d} X{x} A{a}",), subprograms_after_end=True)

# Haas differs from Fanuc in the program number's digits and in folding: local subprograms
# (M97 P<N label> in the same file) with their parameters in common variables.
HAAS = replace(FANUC, name="haas", program_start="O{number:05d} ({title})", fold_style="local_sub",
               x_param="#101", a_param="#102", sub_start="N{sub}", call=("#101={x}", "#102={a}", "M97 P{sub}"))

SIEMENS = Dialect(
    name="siemens", extension="mpf", max_line_length=200,
    percent_delimited=False, program_start="", comment_style="semicolon",
    uppercase_comments=False, setup="G71 G90 G94 G17 G40", tool_change=("T{tool} D1", "M6"),
    spindle_on="S{rpm} M3", coolant_on="M8", coolant_off="M9", spindle_off="M5", program_end="M30",
    linear_decimals=4, rotary_decimals=4, feed_decimals=1, inverse_feed_decimals=4, inverse_time=True,
    fold_style="repeat", x_param="R1", a_param="R2", param_word="{address}={param}",
    param_offset_word="{address}={param}{offset}", sub_start="SPACE{sub}:", sub_end="SPACE{sub}_END:",
    call=("R1={x} R2={a}", "REPEAT SPACE{sub} SPACE{sub}_END P=1"), subprograms_after_end=False,
    workpiece='WORKPIECE(,"",,"BOX",112,{z_max},{z_min},-80,{x_min},{y_min},{x_max},{y_max})')

OKUMA = Dialect(
    name="okuma", extension="min", percent_delimited=False, program_start="O{number:04d} ({title})",
    comment_style="paren", uppercase_comments=True, setup="G21 G90 G94 G17 G40 G80",
    tool_change=("T{tool} M06", "G56 H{tool}"), spindle_on="S{rpm} M03", coolant_on="M08", coolant_off="M09",
    spindle_off="M05", program_end="M30", linear_decimals=3, rotary_decimals=3, feed_decimals=1,
    inverse_feed_decimals=3, inverse_time=False, fold_style="macro_call", x_param="XST", a_param="ASP",
    param_word="{address}={param}", param_offset_word="{address}={param}{offset}", sub_start="O{sub:04d}",
    sub_end="RTS", call=("CALL O{sub:04d} XST={x} ASP={a}",), subprograms_after_end=True,
    direction_codes=("M15", "M16"), work_offset="G15 H{number}")

DIALECTS: dict[str, Dialect] = {d.name: d for d in (LINUXCNC, FANUC, HAAS, SIEMENS, OKUMA)}


def dialect(name: str) -> Dialect:
    """The dialect called `name`, or a PostError listing the known ones."""
    try:
        return DIALECTS[name]
    except KeyError:
        raise PostError(f"[post] dialect = {shown(name)} is not known (known: {', '.join(DIALECTS)})") from None
