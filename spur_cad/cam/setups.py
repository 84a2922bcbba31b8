"""Machine set-ups as types: how the blank sits on the machine, and what that set-up can do.

`[machine] axes` chooses one of two set-ups: the gear on the rotary table (axis = X = A, 4 axes) or the blank
lying flat (gear axis = Z, 3 axes). Every layer used to compare `axes` with 3 or 4 and branch; a set-up is one
frozen object that declares its capabilities once (a rotary axis the programs turn, which gear kinds it reaches,
which tools it cuts with, whether it follows flank modifications, which job sections it reads, where its Z
starts), and code asks the set-up (`Machine.setup`), never `axes`. `axes` itself is read only here and in
cam/machine.py: tests/test_kinds.py checks that over spur_cad/ and workbench/.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol


class _Kind(Protocol):
    """What a set-up asks of a gear kind (spur_cad.geometry.kinds.GearKind)."""

    @property
    def prismatic(self) -> bool: ...

    @property
    def teeth_inward(self) -> bool: ...


@dataclass(frozen=True)
class MachineSetup:
    """One set-up and its declared capabilities (validated once, here).

    - `axes`: the `[machine] axes` value that chooses it.
    - `rotary_axis`: the programs turn A (the part on the rotary table): the 4-axis simulation, the rotary
      table's errors in the error budget, the rotary-table finishing strategies and their comparison.
    - `cuts_helical` / `cuts_teeth_inward`: whether its tool reaches a helical gear's / a ring's spaces.
    - `follows_modifications`: it cuts `[modifications]` tables (generating or perimeter finishing).
    - `tool_kinds`: the tool kinds it cuts with (empty: any); `finishing_needs_roughing`: a finishing tool
      alone cannot cut the part (finishing takes only the finish stock).
    - `sections`: the job-file sections read only in this set-up (the workbench enables their fields only here).
    - `z_origin`: where the programs' Z = 0 lies (the set-up sheet).
    """

    name: str
    axes: int
    rotary_axis: bool
    cuts_helical: bool
    cuts_teeth_inward: bool
    follows_modifications: bool
    tool_kinds: tuple[str, ...]
    finishing_needs_roughing: bool
    sections: tuple[str, ...]
    z_origin: str

    def __post_init__(self) -> None:
        if self.axes not in (3, 4, 5):
            raise ValueError(f"machine set-up {self.name!r}: axes = {self.axes} is not 3, 4 or 5")
        if self.rotary_axis != (self.axes > 3):
            raise ValueError(f"machine set-up {self.name!r}: a rotary axis means more than 3 axes")
        if self.tool_kinds and not set(self.tool_kinds) <= {"flat", "bull_nose", "ball"}:
            raise ValueError(f"machine set-up {self.name!r}: unknown tool kinds {self.tool_kinds}")

    def cuts(self, kind: _Kind) -> bool:
        """Whether this set-up can cut a gear of this kind."""
        return (kind.prismatic or self.cuts_helical) and (not kind.teeth_inward or self.cuts_teeth_inward)

    def accepts_tool_kind(self, tool_kind: str) -> bool:
        """Whether this set-up cuts with a tool of this kind ("flat", "bull_nose", "ball")."""
        return not self.tool_kinds or tool_kind in self.tool_kinds

    def reads_section(self, section: str) -> bool:
        """Whether a job-file section that belongs to one set-up (e.g. "three_axis") applies to this one."""
        return section in self.sections


ROTARY_TABLE = MachineSetup("rotary table", axes=4, rotary_axis=True, cuts_helical=True, cuts_teeth_inward=False,
                            follows_modifications=True, tool_kinds=(), finishing_needs_roughing=False, sections=(),
                            z_origin="the rotary axis")
LYING_FLAT = MachineSetup("lying flat", axes=3, rotary_axis=False, cuts_helical=False, cuts_teeth_inward=True,
                          follows_modifications=False, tool_kinds=("flat",), finishing_needs_roughing=True,
                          sections=("three_axis",), z_origin="the blank's top face")

SETUPS: dict[int, MachineSetup] = {setup.axes: setup for setup in (ROTARY_TABLE, LYING_FLAT)}
"""Every set-up, by its `[machine] axes` value."""

SETUP_SECTIONS = frozenset(section for setup in SETUPS.values() for section in setup.sections)
"""The job-file sections that belong to one set-up only."""


def setup_for_axes(axes: int) -> MachineSetup:
    """The set-up `[machine] axes` chooses (KeyError for a value no set-up has: Machine's key refuses those)."""
    return SETUPS[axes]
