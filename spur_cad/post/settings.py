"""[post] settings: which dialect, and how the program is numbered, folded and turned."""

from __future__ import annotations

from dataclasses import dataclass

from spur_cad.errors import SpurCadError

DIALECT_NAMES = ("linuxcnc", "fanuc", "haas", "siemens", "okuma")


class PostError(SpurCadError, ValueError):
    """A post setting or a toolpath the chosen controller cannot take; the message names it."""


@dataclass(frozen=True)
class PostSettings:
    """[post]: G-code dialect and formatting.

    `rotary_sign` -1 is for tables whose A turns the other way (CONVENTIONS.md); `rotary_mode`
    "unwound" writes A as the toolpath has it, "wrapped" writes it in [0, 360) (flat programs only).
    Block numbers are off by default; when on they never pass `max_line_number` ("wrap" restarts
    the count, "stop" stops numbering).
    """

    dialect: str = "linuxcnc"
    line_numbers: bool = False
    line_number_step: int = 1
    max_line_number: int = 99999
    line_number_overflow: str = "wrap"
    folded: bool = True
    rotary_sign: int = 1
    rotary_mode: str = "unwound"
    program_number: int = 1000
    coolant: bool = True

    def validate(self) -> None:
        if self.dialect not in DIALECT_NAMES:
            raise PostError(f"[post] dialect = {self.dialect!r} is not known (known: {', '.join(DIALECT_NAMES)})")
        if self.rotary_sign not in (1, -1):
            raise PostError(f"[post] rotary_sign must be 1 or -1, got {self.rotary_sign}")
        if self.rotary_mode not in ("unwound", "wrapped"):
            raise PostError(f"[post] rotary_mode must be 'unwound' or 'wrapped', got {self.rotary_mode!r}")
        if self.line_number_overflow not in ("wrap", "stop"):
            raise PostError(f"[post] line_number_overflow must be 'wrap' or 'stop', got {self.line_number_overflow!r}")
        if not 1 <= self.max_line_number <= 99_999_999:
            raise PostError(f"[post] max_line_number must be in 1..99999999, got {self.max_line_number}")
        if not 1 <= self.line_number_step <= self.max_line_number:
            raise PostError(f"[post] line_number_step must be in 1..max_line_number ({self.max_line_number}), "
                            f"got {self.line_number_step}")
        if not 1 <= self.program_number <= 9999:
            raise PostError(f"[post] program_number must be in 1..9999 (it numbers the subprograms after it), "
                            f"got {self.program_number}")
        if self.folded and self.rotary_mode == "wrapped":
            raise PostError("[post] folded = true needs rotary_mode = 'unwound': a folded space pattern adds "
                            "its angles to the space's base angle, which cannot stay inside [0, 360); "
                            "set folded = false to write a wrapped program")
