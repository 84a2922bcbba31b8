"""[post] settings: which dialect, and how the program is numbered, folded and turned."""

from __future__ import annotations

import functools
from dataclasses import dataclass

from spur_cad.dialects import DIALECTS, WORK_OFFSETS, Dialects, dialect_names, dialects_meaning
from spur_cad.errors import PostError, shown
from spur_cad.keys import check_section, key, key_of, with_key

__all__ = ["WORK_OFFSETS", "PostError", "PostSettings", "dialect_names", "post_settings_type"]

DEFAULT_DIALECT = "linuxcnc"


@dataclass(frozen=True)
class PostSettings:
    """[post]: G-code dialect and formatting (see docs/post.md).

    `rotary_sign` -1 is for tables whose A turns the other way (docs/architecture.md); `rotary_mode`
    "unwound" writes A as the toolpath has it, "wrapped" writes it in [0, 360) (flat programs only).
    Block numbers are off by default; when on they never pass `max_line_number` ("wrap" restarts
    the count, "stop" stops numbering).
    """

    dialect: str = key(DEFAULT_DIALECT, label="PostDialect", group="Post", names_from=dialect_names,
                       meaning=f"G-code dialect: {dialects_meaning()}; see docs/post.md")
    line_numbers: bool = key(False, label="LineNumbers", group="Post", meaning="write N block numbers")
    line_number_step: int = key(1, low=1, high="max_line_number", label="LineNumberStep", group="Post",
                                meaning="increment of the N words")
    max_line_number: int = key(99999, low=1, high=99_999_999, label="MaxLineNumber", group="Post",
                               meaning="N never passes this (the controller's limit)")
    line_number_overflow: str = key("wrap", choices=("wrap", "stop"), label="LineNumberOverflow", group="Post",
                                    meaning="at the limit: wrap restarts at the step, stop stops numbering")
    folded: bool = key(True, label="Folded", group="Post",
                       meaning="each tooth space written once as a subprogram / repeat section, called per space")
    rotary_sign: int = key(1, choices=(1, -1), label="RotarySign", group="Post",
                           meaning="-1 for a table whose A turns the other way")
    rotary_mode: str = key("unwound", choices=("unwound", "wrapped"), label="RotaryMode", group="Post",
                           meaning="unwound writes A as the toolpath has it, wrapped in [0, 360) "
                                   "(flat programs only; Okuma adds M15/M16)")
    program_number: int = key(1000, low=1, high=9999, label="ProgramNumber", group="Post",
                              meaning="O number (Fanuc, Haas, Okuma); subprograms take the next numbers")
    work_offset: str = key("G54", choices=WORK_OFFSETS, label="WorkOffset", group="Post",
                           meaning="work offset every program selects (Okuma: G15 H1..H6 for G54..G59; Siemens "
                                   "also describes the blank with WORKPIECE)")
    coolant: bool = key(True, label="Coolant", group="Post", meaning="M8 after the spindle starts, M9 before it stops")

    def __post_init__(self) -> None:
        """Every key in its range, the dialect known and the keys agreeing, checked once when the settings are made
        (PostError naming the key): the posts trust them."""
        check_section(self, "post", PostError)
        names = key_of(type(self), "dialect").names  # the registry's this section was made for
        if self.dialect not in names:
            raise PostError(f"[post] dialect = {shown(self.dialect)} is not known (known: {', '.join(names)})",
                            field="dialect")
        if self.folded and self.rotary_mode == "wrapped":
            raise PostError("[post] folded = true needs rotary_mode = 'unwound': a folded space pattern adds "
                            "its angles to the space's base angle, which cannot stay inside [0, 360); "
                            "set folded = false to write a wrapped program", field="folded")


def post_settings_type(dialects: Dialects = DIALECTS) -> type[PostSettings]:
    """The [post] section for a registry of dialects: PostSettings for the default registry, else a subclass
    whose `dialect` key takes the registry's names (its default linuxcnc when the registry has it, else its
    first dialect) and lists them in its meaning."""
    names = dialect_names(dialects)
    return _post_settings_type(names, f"G-code dialect: {dialects_meaning(None, dialects)}; see docs/post.md")


@functools.cache
def _post_settings_type(names: tuple[str, ...], meaning: str) -> type[PostSettings]:
    declared = key_of(PostSettings, "dialect")
    if names == declared.names and meaning == declared.meaning:
        return PostSettings
    if not names:
        raise ValueError("a [post] section needs a registry of at least one dialect")
    return with_key(PostSettings, "dialect", key(DEFAULT_DIALECT if DEFAULT_DIALECT in names else names[0],
                                                 label=declared.label, group=declared.group, meaning=meaning,
                                                 names_from=lambda: names))
