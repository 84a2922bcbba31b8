"""Controller dialects as data: one `Dialect` per controller, and registries of them (`Dialects`, a read-only
mapping name -> Dialect; `DIALECTS` is the default one). Everything that names or lists controllers derives
from a registry: the job file's `[post] dialect` and `[lathe] dialect` choices and their documentation, the
milling, lathe and probing posts (spur_cad.post), the output folder's vocabulary of program file names
(spur_cad.outputs), the program reader of `spur-cad verify` and the CLI. Functions take `dialects=` to use
another registry (e.g. one with a controller defined in a test: `registry(*DIALECTS.values(), MACH3)`).

No other module compares a dialect's name (tests/test_dialect_table.py checks it): each reads the attributes
here. What each dialect relies on is listed in docs/post.md, which also walks through adding one. Only
LinuxCNC is checked by an interpreter here (rs274); the others follow their programming manuals and are
pinned by golden tests. Data only, in the lowest layer (imports spur_cad.errors alone), so that the output
vocabulary and the CAM's [lathe] section can derive from it.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType

from spur_cad.errors import PostError, shown

WORK_OFFSETS = ("G54", "G55", "G56", "G57", "G58", "G59")
"""The work offsets a program may select ([post] and [lathe] work_offset); a dialect says how it writes them."""


class FoldStyle(enum.Enum):
    """How the post writes a tooth space's pattern once and has it run once per space ([post] folded)."""

    NUMBERED_SUBPROGRAM = "numbered subprogram"
    """A subprogram of its own number after the program's (o1001, O1001), before or after the main program,
    run by the dialect's call blocks: LinuxCNC `o<n> call`, Fanuc `G65 P`, Okuma `CALL O`, an `M98 P` after
    parameter assignments."""
    LOCAL_LABEL = "local label"
    """A local subprogram in the same file, labelled by a block number at the top of the numbers' range
    (`N<label>` ... `M99` after the end), run by the call blocks (Haas `M97 P<label>`)."""
    REPEATED_SECTION = "repeated section"
    """The section itself, labelled, written in place at its first use and repeated there after (Siemens
    `REPEAT <start> <end> P=1`)."""


@dataclass(frozen=True)
class Comments:
    """How the post writes a comment, and every comment syntax the control reads (the reader strips them)."""

    style: str  # how the post writes one: "paren" (text) or "semicolon" ; text
    uppercase: bool  # comment text and the program title in upper case
    reads: tuple[str, ...]  # what the control takes as a comment: "paren" ( ... ), "semicolon" ; to the line's end

    def __post_init__(self):
        if self.style not in ("paren", "semicolon") or self.style not in self.reads \
                or not set(self.reads) <= {"paren", "semicolon"}:
            raise ValueError(f"comments: style {self.style!r} must be one of the syntaxes read {self.reads!r} "
                             "(paren, semicolon)")


@dataclass(frozen=True)
class Subprograms:
    """How the post writes a space pattern once and calls it per space (folding; `{...}` are str.format
    templates), and which subprogram structure the reader executes."""

    fold_style: FoldStyle
    x_param: str  # how the body names the X base
    a_param: str  # how the body names the A base
    param_word: str  # an address taking a parameter: {address}, {param}
    param_offset_word: str  # an address taking parameter + offset: {address}, {param}, {offset}
    start: str  # the definition's first block: {sub}
    end: str  # its closing block: {sub}
    call: tuple[str, ...]  # the call's blocks: {sub}, {x}, {a}
    after_end: bool  # definitions follow the main program's end (else they come before its body)
    # What the reader executes: "o_words" (LinuxCNC o<n> sub / endsub / call / repeat, #n parameters),
    # "labels" (Siemens NAME: labels, REPEAT, R<n>= parameters), "numbered" (O<n> ... closing after the end
    # of the main program, #n variables).
    structure: str
    closing: str = "M0*99"  # "numbered": the block closing a subprogram, a regular expression (Okuma RTS)
    named_calls: bool = False  # "numbered": CALL O<n> NAME=value (Okuma) instead of G65 P<n> / M98 P<n>
    local_labels: bool = False  # N<n> local subprograms called with M97 P<n> in the same file (Haas)

    def __post_init__(self):
        if not isinstance(self.fold_style, FoldStyle) or self.structure not in ("o_words", "labels", "numbered"):
            raise ValueError(f"subprograms: unknown fold_style {self.fold_style!r} or structure {self.structure!r}")


@dataclass(frozen=True)
class Rotary:
    """The A axis's words: decimals, and the direction codes that let a wrapped A (in [0, 360)) turn a chosen
    way; without them a wrapped program needs every A move shorter than 180 deg."""

    decimals: int
    direction_codes: tuple[str, str] | None = None  # (positive, negative) M codes; the reader turns A their way


@dataclass(frozen=True)
class WorkOffsets:
    """How a program selects the work offset G54..G59 (the reader takes any selection as the job's frame)."""

    word: str = "{code}"  # {code} is G54..G59, {number} 1..6 (Okuma's G15 H<n>)
    numbered_code: str | None = None  # the G code that selects offset n as G<code> H<n> in a block of its own


@dataclass(frozen=True)
class LatheWords:
    """The blank's lathe program on this control (docs/lathe.md): what the lathe post writes besides the
    dialect's file frame (extension, % delimiters, program start, comments, coolant, spindle off, end, line
    limit), and what the reader's lathe mode reads."""

    setup: tuple[str, ...]  # plane, units, absolute, feed per revolution, diameter mode
    spindle_limit: str  # the spindle limit under G96 after the work offset, "" for none; {rpm}
    tool_change: str  # {tool}
    constant_speed: str  # {vc} m/min, {rpm} the spindle limit, {direction} M3 / M4 as this control writes it
    feed_codes: tuple[str, str]  # G codes without the G: feed per revolution, feed per minute
    diameter_word: str | None  # what makes X a diameter ("G7", "DIAMON"); None: X always is one (Fanuc)
    workpiece: str = ""  # the bar for the control's simulation, "" for none; {top}, {far}, {end}, {diameter}
    padded_m_codes: bool = False  # M03 rather than M3
    end: tuple[str, ...] = ()  # blocks between spindle off and the program end
    diameter_codes: tuple[str, str] | None = None  # reader: G codes for X as diameter / radius (LinuxCNC 7, 8)
    keywords: bool = False  # reader: LIMS=<rpm> and DIAMON / DIAM90 / DIAMOF keywords (Siemens)
    spindle_limit_code: str | None = None  # reader: the G code read with S as the spindle limit (G50 S, G26 S)
    cycle_codes: tuple[str, ...] = ()  # reader: G codes that are turning cycles here, refused (Fanuc G90, G94)
    turret: bool = False  # a T word indexes the turret at once; else M6 loads the tool
    tool_offset_t: bool = False  # T gives tool and offset in two digits each (T0101)


@dataclass(frozen=True)
class ProbingWords:
    """The on-machine probing program on this control (docs/probing.md): the probe move and how the ball
    centre at each trip is recorded. `{...}` are str.format templates."""

    probe_move: str  # the move that stops when the probe trips: LinuxCNC G38.2 (an error without a trip), G31
    log_open: str  # opens the record of trips: "(PROBEOPEN probe.log)", Fanuc POPEN
    log_close: str  # closes it: "(PROBECLOSE)", PCLOS
    record: str = ""  # a block after each probe move writing the trip position, "" when the control logs itself
    no_trip_check: str = ""  # stops the program when the move ended without a trip: {y}, {z} the target, {tol}
    log_name: str = ""  # what the docs call the record: probe.log, the DPRNT output


@dataclass(frozen=True)
class Dialect:
    """Everything that differs between controllers; `{...}` fields are str.format templates."""

    name: str  # as the job file and the command line name it
    title: str  # as messages name the controller
    extension: str
    percent_delimited: bool  # the file starts and ends with a "%" line
    program_start: str  # first block, "" for none; {number}, {title}
    comments: Comments
    setup: str  # units, absolute, feed per minute, plane, cancel compensation / cycles
    tool_change: tuple[str, ...]  # {tool}
    spindle_on: str  # {rpm}
    coolant_on: str
    coolant_off: str
    spindle_off: str
    program_end: str
    linear_decimals: int
    feed_decimals: int
    inverse_feed_decimals: int
    inverse_time: bool  # G93/G94 available; else F is compensated (docs/post.md)
    rotary: Rotary
    subprograms: Subprograms
    max_line_length: int = 128  # longest block the control takes (every line is checked; comments are cut to fit)
    work_offsets: WorkOffsets = WorkOffsets()
    workpiece: str = ""  # the blank for the control's own simulation; {x_min} ... {z_max} of the blank's box
    assigned_words: bool = False  # the reader takes address=expression words (A=R2+1.5, A=ASP-1.5)
    extra_setup_g: tuple[str, ...] = ()  # G codes (without the G) the reader takes as setup here only (840D G71)
    ignored_words: str = "HDP"  # address letters the reader skips: tool offsets, G64 P, G96 D, G15 H
    lathe: LatheWords | None = None  # None: no lathe program (the lathe post and the reader's lathe mode refuse)
    rs274_checkable: bool = False  # LinuxCNC's interpreter rs274 reads these programs (spur-cad verify)
    probing: ProbingWords | None = None  # None: no probing program (the [probe] section refuses the dialect)


LINUXCNC = Dialect(
    name="linuxcnc", title="LinuxCNC", extension="ngc", max_line_length=250,
    percent_delimited=False, program_start="", comments=Comments("paren", False, ("paren", "semicolon")),
    setup="G21 G90 G94 G17 G40 G49 G80 G64 P0.001", tool_change=("T{tool} M6", "G43 H{tool}"),
    spindle_on="S{rpm} M3", coolant_on="M8", coolant_off="M9", spindle_off="M5", program_end="M30",
    linear_decimals=4, feed_decimals=1, inverse_feed_decimals=4, inverse_time=True, rotary=Rotary(4),
    subprograms=Subprograms(
        fold_style=FoldStyle.NUMBERED_SUBPROGRAM, x_param="#1", a_param="#2", param_word="{address}{param}",
        param_offset_word="{address}[{param}{offset}]", start="o{sub} sub", end="o{sub} endsub",
        call=("o{sub} call [{x}] [{a}]",), after_end=False, structure="o_words"),
    lathe=LatheWords(setup=("G7", "G18 G21 G90 G40 G95"), spindle_limit="", tool_change="T{tool} M6 G43",
                     constant_speed="G96 D{rpm} S{vc} {direction}", feed_codes=("95", "94"), diameter_word="G7",
                     diameter_codes=("7", "8")),
    # G38.2 stops at the trip and logs the 9 axes (X Y Z A B C U V W) to the PROBEOPEN file; no trip is an error.
    probing=ProbingWords(probe_move="G38.2", log_open="(PROBEOPEN probe.log)", log_close="(PROBECLOSE)",
                         log_name="probe.log"),
    rs274_checkable=True)

FANUC = Dialect(
    name="fanuc", title="Fanuc", extension="nc", percent_delimited=True, program_start="O{number:04d} ({title})",
    comments=Comments("paren", True, ("paren",)), setup="G21 G90 G94 G17 G40 G49 G80",
    tool_change=("T{tool} M06", "G43 H{tool}"), spindle_on="S{rpm} M03", coolant_on="M08", coolant_off="M09",
    spindle_off="M05", program_end="M30", linear_decimals=3, feed_decimals=1, inverse_feed_decimals=3,
    inverse_time=True, rotary=Rotary(3),
    subprograms=Subprograms(
        fold_style=FoldStyle.NUMBERED_SUBPROGRAM, x_param="#24", a_param="#1", param_word="{address}{param}",
        param_offset_word="{address}[{param}{offset}]", start="O{sub:04d}", end="M99",
        call=("G65 P{sub:04d} X{x} A{a}",), after_end=True, structure="numbered", closing="M0*99"),
    # A Fanuc lathe in G-code system A: U / W incremental, G90 and G94 turning cycles, G99 feed per revolution.
    lathe=LatheWords(setup=("G21 G18 G40 G99",), spindle_limit="G50 S{rpm}", tool_change="T{tool:02d}{tool:02d}",
                     constant_speed="G96 S{vc} {direction}", feed_codes=("99", "98"), diameter_word=None,
                     padded_m_codes=True, end=("G97",), spindle_limit_code="50", cycle_codes=("90", "94"),
                     turret=True, tool_offset_t=True),
    # G31 (skip) stops at the trip; #5061..#5064 hold X Y Z A there (the block's end when nothing tripped, which
    # the check turns into alarm 3000); DPRNT writes them to the POPEN device (docs/probing.md).
    probing=ProbingWords(probe_move="G31", log_open="POPEN", log_close="PCLOS",
                         record="DPRNT[X#5061[44]Y#5062[44]Z#5063[44]A#5064[34]]",
                         no_trip_check="IF[[ABS[#5062-[{y}]]+ABS[#5063-[{z}]]]LT{tol}]THEN#3000=1(PROBE NOT TRIPPED)",
                         log_name="the DPRNT output"))

# Haas differs from Fanuc in the program number's digits and in folding: local subprograms
# (M97 P<N label> in the same file) with their parameters in common variables. No lathe words.
HAAS = replace(FANUC, name="haas", title="Haas", program_start="O{number:05d} ({title})", lathe=None,
               subprograms=replace(FANUC.subprograms, fold_style=FoldStyle.LOCAL_LABEL, x_param="#101", a_param="#102",
                                   start="N{sub}", call=("#101={x}", "#102={a}", "M97 P{sub}"), local_labels=True))

SIEMENS = Dialect(
    name="siemens", title="Siemens 840D", extension="mpf", max_line_length=200,
    percent_delimited=False, program_start="", comments=Comments("semicolon", False, ("semicolon",)),
    setup="G71 G90 G94 G17 G40", tool_change=("T{tool} D1", "M6"),
    spindle_on="S{rpm} M3", coolant_on="M8", coolant_off="M9", spindle_off="M5", program_end="M30",
    linear_decimals=4, feed_decimals=1, inverse_feed_decimals=4, inverse_time=True, rotary=Rotary(4),
    subprograms=Subprograms(
        fold_style=FoldStyle.REPEATED_SECTION, x_param="R1", a_param="R2", param_word="{address}={param}",
        param_offset_word="{address}={param}{offset}", start="SPACE{sub}:", end="SPACE{sub}_END:",
        call=("R1={x} R2={a}", "REPEAT SPACE{sub} SPACE{sub}_END P=1"), after_end=False, structure="labels"),
    workpiece='WORKPIECE(,"",,"BOX",112,{z_max},{z_min},-80,{x_min},{y_min},{x_max},{y_max})',
    assigned_words=True, extra_setup_g=("71",), ignored_words="HDPN",
    # WORKPIECE(...) of SINUMERIK Operate: the bit value 192 marks ZI and ZB as absolute (docs/lathe.md).
    lathe=LatheWords(setup=("G18 G90 G71 G95 G40 DIAMON",), spindle_limit="LIMS={rpm}", tool_change="T{tool} D1",
                     constant_speed="G96 S{vc} {direction}", feed_codes=("95", "94"), diameter_word="DIAMON",
                     workpiece='WORKPIECE(,,,"CYLINDER",192,{top},{far},{end},{diameter})', keywords=True,
                     spindle_limit_code="26", turret=True))

OKUMA = Dialect(
    name="okuma", title="Okuma OSP", extension="min", percent_delimited=False, program_start="O{number:04d} ({title})",
    comments=Comments("paren", True, ("paren",)), setup="G21 G90 G94 G17 G40 G80",
    tool_change=("T{tool} M06", "G56 H{tool}"), spindle_on="S{rpm} M03", coolant_on="M08", coolant_off="M09",
    spindle_off="M05", program_end="M30", linear_decimals=3, feed_decimals=1, inverse_feed_decimals=3,
    inverse_time=False, rotary=Rotary(3, direction_codes=("M15", "M16")),
    subprograms=Subprograms(
        fold_style=FoldStyle.NUMBERED_SUBPROGRAM, x_param="XST", a_param="ASP", param_word="{address}={param}",
        param_offset_word="{address}={param}{offset}", start="O{sub:04d}", end="RTS",
        call=("CALL O{sub:04d} XST={x} ASP={a}",), after_end=True, structure="numbered", closing="RTS",
        named_calls=True),
    work_offsets=WorkOffsets("G15 H{number}", numbered_code="15"), assigned_words=True)

Dialects = Mapping[str, Dialect]
"""A registry of dialects: name -> Dialect, in the order messages, documentation and the workbench list them."""


def registry(*dialects: Dialect) -> Dialects:
    """A read-only registry of `dialects`, in their order (names must differ)."""
    table = {d.name: d for d in dialects}
    if len(table) != len(dialects) or not all(isinstance(d, Dialect) for d in dialects):
        raise ValueError("a dialect registry takes Dialects of different names")
    return MappingProxyType(table)


DIALECTS: Dialects = registry(LINUXCNC, FANUC, HAAS, SIEMENS, OKUMA)
"""The default registry (read-only: another registry is a new one passed as `dialects=`)."""


def dialect(name: str | Dialect, dialects: Dialects = DIALECTS) -> Dialect:
    """The dialect called `name` in `dialects`, or a PostError listing the known ones; a `Dialect` is returned as
    it is (a controller in no registry, e.g. one being added: docs/post.md)."""
    if isinstance(name, Dialect):
        return name
    try:
        return dialects[name]
    except (KeyError, TypeError):
        raise PostError(f"[post] dialect = {shown(name)} is not known (known: {', '.join(dialects)})",
                        field="dialect", section="post") from None


def dialect_names(dialects: Dialects = DIALECTS) -> tuple[str, ...]:
    """The names of the registry's dialects, in its order ([post] dialect's choices)."""
    return tuple(dialects)


def lathe_names(dialects: Dialects = DIALECTS) -> tuple[str, ...]:
    """The names of the dialects with lathe words, in the registry's order ([lathe] dialect's choices)."""
    return tuple(d.name for d in dialects.values() if d.lathe is not None)


def probing_names(dialects: Dialects = DIALECTS) -> tuple[str, ...]:
    """The names of the dialects with probing words, in the registry's order (those [probe] takes)."""
    return tuple(d.name for d in dialects.values() if d.probing is not None)


def program_extensions(dialects: Dialects = DIALECTS) -> tuple[str, ...]:
    """Every program file extension of the registry's dialects (milling, lathe and probing programs share
    their dialect's), once each, in its order: the output folder's vocabulary of program names."""
    return tuple(dict.fromkeys(d.extension for d in dialects.values()))


def dialects_meaning(names: tuple[str, ...] | None = None, dialects: Dialects = DIALECTS) -> str:
    """The registry's dialects called `names` (None: all) as the key documentation lists them:
    'linuxcnc (LinuxCNC, .ngc), fanuc (Fanuc, .nc), ...'."""
    chosen = [d for d in dialects.values() if names is None or d.name in names]
    return ", ".join(f"{d.name} ({d.title}, .{d.extension})" for d in chosen)
