"""Machine set-ups as types: how the blank sits on the machine, and what that set-up can do.

`[machine] axes` chooses one of two set-ups: the gear on the rotary table (axis = X = A, 4 axes) or the blank
lying flat (gear axis = Z, 3 axes). Every layer used to compare `axes` with 3 or 4 and branch; a set-up is one
frozen object that declares its capabilities once (a rotary axis the programs turn, which gear kinds it reaches,
which tools it cuts with, whether it follows flank modifications, which job sections it reads, where its Z
starts), and code asks the set-up (`Machine.setup`), never `axes`. `axes` itself is read only here and in
cam/machine.py: tests/test_kinds.py checks that over spur_cad/ and workbench/.

Each set-up is an instance of its own class (RotaryTable, LyingFlat), which writes its rows of the report's
set-up sheet (`setup_sheet_rows`), names the tool limits that apply to it (`tool_limit_labels`) and words roughing
by levels (`levels_roughing`, `levels_roughing_note`): plain data (label, text, numbers, unit; phrases with named
places) that the report formats, so the report asks the set-up and does not branch on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Protocol

from spur_cad.geometry.kinds import CUTTING_NEEDS


class _Kind(Protocol):
    """What a set-up asks of a gear kind (spur_cad.geometry.kinds.GearKind)."""

    @property
    def cutting_needs(self) -> frozenset[str]: ...


class _Strategy(Protocol):
    """What a set-up asks of a finishing strategy (spur_cad.cam.strategies.FinishingStrategy)."""

    @property
    def lying_flat(self) -> bool: ...


class _SheetFacts(Protocol):
    """What a set-up's sheet reads of the run's set-up facts (spur_cad.result.SetupFacts)."""

    @property
    def machine_name(self) -> str: ...

    @property
    def blank_diameter_mm(self) -> float: ...

    @property
    def blank_x_min_mm(self) -> float: ...

    @property
    def blank_x_max_mm(self) -> float: ...

    @property
    def stub_diameter_mm(self) -> float: ...

    @property
    def stub_length_mm(self) -> float: ...

    @property
    def work_offset(self) -> str: ...

    @property
    def rotary_sign(self) -> int: ...

    @property
    def clearance_mm(self) -> float: ...


class _SheetGear(Protocol):
    """What a set-up's sheet reads of the gear (spur_cad.result.GearFacts)."""

    @property
    def teeth(self) -> int: ...

    @property
    def root_radius_mm(self) -> float: ...

    @property
    def tip_radius_mm(self) -> float: ...

    @property
    def face_width_mm(self) -> float: ...


_BUDGET_KEYS = ("rotary_accuracy_arcsec", "rotary_repeatability_arcsec", "rotary_calibration_file",
                "spindle_runout_um", "tool_runout_um", "tool_radius_error_um", "linear_accuracy_um")
"""The `[machine]` keys an error budget may read (spur_cad.sim.budget), in summary.json's order."""


@dataclass(frozen=True)
class SheetRow:
    """One row of the set-up sheet as plain data: the label, the value's text with a `{}` where each of `numbers`
    goes (the report writes each with `digits` decimals; a text without numbers is shown as it is), the unit."""

    label: str
    text: str
    numbers: tuple[float, ...] = ()
    digits: int = 3
    unit: str = ""


@dataclass(frozen=True)
class MachineSetup:
    """One set-up and its declared capabilities (validated once, here).

    - `axes`: the `[machine] axes` value that chooses it.
    - `rotary_axis`: the programs turn A (the part on the rotary table): the 4-axis simulation, the rotary
      table's errors in the error budget, the rotary-table finishing strategies and their comparison.
    - `reaches`: the kinds' cutting needs its tool meets (spur_cad.geometry.kinds.CUTTING_NEEDS): helical teeth,
      teeth inward (a ring's spaces); it cuts a kind whose needs it all reaches.
    - `follows_modifications`: it cuts `[modifications]` tables (generating or perimeter finishing).
    - `tool_kinds`: the tool kinds it cuts with (empty: any); `finishing_needs_roughing`: a finishing tool
      alone cannot cut the part (finishing takes only the finish stock).
    - `sections`: the job-file sections read only in this set-up (the workbench enables their fields only here).
    - `z_origin`: where the programs' Z = 0 lies (the set-up sheet).
    """

    name: str
    axes: int
    rotary_axis: bool
    reaches: frozenset[str]
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
        if not self.reaches <= set(CUTTING_NEEDS):
            raise ValueError(f"machine set-up {self.name!r}: unknown cutting needs {sorted(self.reaches)}")
        if self.tool_kinds and not set(self.tool_kinds) <= {"flat", "bull_nose", "ball"}:
            raise ValueError(f"machine set-up {self.name!r}: unknown tool kinds {self.tool_kinds}")

    def cuts(self, kind: _Kind) -> bool:
        """Whether this set-up can cut a gear of this kind."""
        return kind.cutting_needs <= self.reaches

    def accepts_tool_kind(self, tool_kind: str) -> bool:
        """Whether this set-up cuts with a tool of this kind ("flat", "bull_nose", "ball")."""
        return not self.tool_kinds or tool_kind in self.tool_kinds

    def reads_section(self, section: str) -> bool:
        """Whether a job-file section that belongs to one set-up (e.g. "three_axis") applies to this one."""
        return section in self.sections

    def accepts_strategy(self, strategy: _Strategy) -> bool:
        """Whether this set-up finishes with a strategy of the registry declared so: the rotary table with those that
        are not `lying_flat`, lying flat with those that are (none yet: the 3-axis finishing, cam/three_axis.py,
        is the plan's own and takes no [finishing] strategy)."""
        return strategy.lying_flat != self.rotary_axis

    tool_limit_labels: ClassVar[tuple[tuple[str, str], ...]] = ()
    """(ToolRecommendations field, label) of the tool limits the report shows for this set-up."""
    levels_roughing: ClassVar[str] = ""
    """The report's operation-table phrase for roughing by levels here ({levels}: levels per space)."""
    levels_roughing_note: ClassVar[str] = ""
    """The report's sentence on roughing by levels here ({levels}: levels per space; {lowest_above_root_mm}: the
    lowest level above the root circle; {lowest_z_mm}: the lowest level's Z; {tips}: the tip lands' passes or
    nothing; the values written by the report)."""

    def setup_sheet_rows(self, facts: _SheetFacts, gear: _SheetGear) -> tuple[SheetRow, ...]:
        """The set-up sheet's rows (stock, work offset, how the part sits), as a machinist sets the part up."""
        raise NotImplementedError(f"machine set-up {self.name!r} writes no set-up sheet")

    # --- asked by the pipeline, the summary, the post and the workbench (H4, issue 45) ----------------------------
    @property
    def writes_a(self) -> bool:
        """Its programs turn A (the part on the rotary table): the post writes A words and the clamp codes; a set-up
        without a rotary axis refuses a toolpath that turns or clamps A (spur_cad.post.ProgramInfo.writes_a)."""
        return self.rotary_axis

    budget_keys: ClassVar[tuple[str, ...]] = ()
    """The `[machine]` keys its error budget reads (summary.json's error_budget inputs, in this order)."""
    panel_limits_text: ClassVar[str] = ""
    """The workbench's tool limits for this set-up when they are a fixed text (empty: the gear's computed limits
    and the notes beside the tool fields are shown)."""
    default_roughing_strategy: ClassVar[str] = "levels"
    """The [roughing] strategy of a job that leaves it out here (spur_cad.cam.machine.default_roughing_strategy)."""
    error_budget_text: ClassVar[str] = ""
    """The report's sentence on the error budget here, with named places the report fills ({klass}: the expected
    class; {total}, {runout}, {tool_radius}, {linear}, {deflection}: the flank shifts; {thickness}: the tooth
    thickness change; {index_source}, {seed}, {largest_index}: the index errors; {bent}: the tool's deflection;
    {micro}: the micrometre sign)."""

    def budget_inputs(self, machine: object, material: str) -> dict[str, object]:
        """Summary.json's error-budget inputs: the `[machine]` keys its budget reads (budget_keys, values of
        `machine`, a spur_cad.cam.machine.Machine)."""
        return {name: getattr(machine, name) for name in self.budget_keys}

    @property
    def machine_summary(self) -> str:
        """What the workbench adds after the machine's name in its folded Machine group ("" on the rotary table,
        the default; ", 3 axes" lying flat)."""
        return "" if self.rotary_axis else f", {self.axes} axes"

    def program_box_mm(self, blank_radius_mm: float, blank_x_mm: tuple[float, float], stub_length_mm: float,
                       face_width_mm: float) -> tuple[float, float, float, float, float, float]:
        """The blank's box in the programs' frame (x, y, z min then max; Siemens WORKPIECE)."""
        raise NotImplementedError(f"machine set-up {self.name!r} has no program frame")


@dataclass(frozen=True)
class RotaryTable(MachineSetup):
    """The gear on the rotary table: gear axis = machine X = A, the tool along Z above the part."""

    tool_limit_labels: ClassVar[tuple[tuple[str, str], ...]] = (
        ("roughing_max_diameter_mm", "largest roughing end mill (flat)"),
        ("finishing_generating_max_diameter_mm", "largest finishing tool by generation (corner = rack tip radius)"),
        ("finishing_flat_end_mill_max_diameter_mm", "largest flat end mill that finishes by generation"),
        ("finishing_max_corner_radius_mm", "largest finishing corner radius (the fillet's tightest curve)"),
        ("finishing_max_flat_width_mm", "largest finishing flat width (the root arc)"),
        ("plunge_allowance_mm", "material roughing may leave above the root"),
        ("required_flute_length_mm", "flute length the tools need (blank to root)"),
        ("required_stick_out_mm", "stick-out the tools need"),
    )
    budget_keys: ClassVar[tuple[str, ...]] = _BUDGET_KEYS
    default_roughing_strategy: ClassVar[str] = "flank"
    """Roughing by flanks (constant engagement, docs/method.md 4.1): A turns each flank segment to the tool."""
    error_budget_text: ClassVar[str] = (
        "With the machine's error budget the gear is expected in class {klass}: index errors from the {index_source} "
        "and the repeatability drawn per space (seed {seed}), largest {largest_index} arcsec; every flank moved "
        "{total} {micro} along its normal (runout {runout}, tool radius {tool_radius}, linear axes {linear}, "
        "deflection {deflection}), {bent}; the tooth thickness on the reference circle changes by {thickness} "
        "{micro}.")

    def budget_inputs(self, machine: object, material: str) -> dict[str, object]:
        """Its `[machine]` keys and `[job] material`: the finishing tool's deflection is modelled in it."""
        return {**super().budget_inputs(machine, material), "material": material}

    def program_box_mm(self, blank_radius_mm: float, blank_x_mm: tuple[float, float], stub_length_mm: float,
                       face_width_mm: float) -> tuple[float, float, float, float, float, float]:
        """Along X from the blank's front to the stub's end, about the rotary axis (Y = Z = 0) to the blank radius."""
        r = blank_radius_mm
        return (blank_x_mm[0], -r, -r, blank_x_mm[1] + stub_length_mm, r, r)

    levels_roughing: ClassVar[str] = "z-level roughing, {levels} levels per space"
    levels_roughing_note: ClassVar[str] = ("Roughing: {levels} levels per space, the lowest {lowest_above_root_mm} mm "
                                           "above the root circle{tips}.")

    def setup_sheet_rows(self, facts: _SheetFacts, gear: _SheetGear) -> tuple[SheetRow, ...]:
        """Stock, work offset and A's zero: the blank along X from the gear's front face, the holding stub."""
        rows = [SheetRow("machine", facts.machine_name),
                SheetRow("blank diameter", "{}", (facts.blank_diameter_mm,), unit="mm"),
                SheetRow("blank along X (front face of the gear at X = 0)", "{} to {}",
                         (facts.blank_x_min_mm, facts.blank_x_max_mm), unit="mm")]
        if facts.stub_diameter_mm > 0.0:
            rows.append(SheetRow("holding stub toward the chuck (+X)", "D {} x {}",
                                 (facts.stub_diameter_mm, facts.stub_length_mm), unit="mm"))
        rows += [
            SheetRow("work offset",
                     f"{facts.work_offset}: X = 0 on the gear's front face, Y = 0 and Z = 0 on the rotary axis"),
            SheetRow("A zero", "tooth space 0's axis points to +Z; space k is brought under the tool at A = -k x {}°"
                     + ("" if facts.rotary_sign == 1 else " (the post writes A with the opposite sign)"),
                     (360.0 / gear.teeth,), digits=4),
            SheetRow("gear axis", "machine X = rotary axis A; the tool along Z, above the part"),
            SheetRow("clearance above the blank for moves that turn A", "{}", (facts.clearance_mm,), unit="mm"),
        ]
        return tuple(rows)


@dataclass(frozen=True)
class LyingFlat(MachineSetup):
    """The blank lying flat on a 3-axis machine: gear axis = machine Z, Z = 0 on its top face; a ring (its root
    outside its tip) clamped on its rim."""

    tool_limit_labels: ClassVar[tuple[tuple[str, str], ...]] = (  # the side cuts: no generating tool, corner, flat
        ("roughing_max_diameter_mm", "largest roughing end mill (flat)"),
        ("finishing_flat_end_mill_max_diameter_mm", "largest finishing flat end mill (its side leaves the involute "
                                                    "no higher than the active profile's start)"),
        ("required_flute_length_mm", "flute length the tools need (the face width and the break-through)"),
        ("required_stick_out_mm", "stick-out the tools need"),
    )
    budget_keys: ClassVar[tuple[str, ...]] = tuple(name for name in _BUDGET_KEYS if not name.startswith("rotary_"))
    """No rotary table indexes the spaces: its keys are not read (no index error, no deflection modelled)."""
    default_roughing_strategy: ClassVar[str] = "levels"
    """No table turns a flank to the tool: by levels, each a series of passes offset from the outline."""
    error_budget_text: ClassVar[str] = (
        "With the 3-axis machine's error budget the gear is expected in class {klass}: no index error (no rotary "
        "table indexes the spaces); every flank moved {total} {micro} along its normal (runout {runout}, tool radius "
        "{tool_radius}, linear axes {linear}; the side of a flat end mill cutting a whole step-down is not the "
        "deflection model's cut: a measured figure goes in as tool_radius_error_um); the tooth thickness on the "
        "reference circle changes by {thickness} {micro}.")
    panel_limits_text: ClassVar[str] = (
        "3 axes, the gear lying flat: flat end mills; the finishing tool's radius is the root fillet's at least, and "
        "its side must reach the active profile (docs/cam.md).")

    def program_box_mm(self, blank_radius_mm: float, blank_x_mm: tuple[float, float], stub_length_mm: float,
                       face_width_mm: float) -> tuple[float, float, float, float, float, float]:
        """The disc of the face width about the gear axis (Z), Z = 0 on its top face."""
        r = blank_radius_mm
        return (-r, -r, -face_width_mm, r, r, 0.0)

    levels_roughing: ClassVar[str] = "3-axis roughing, {levels} levels of passes offset from the blank inward"
    levels_roughing_note: ClassVar[str] = ("Roughing on 3 axes: {levels} levels down to Z {lowest_z_mm} mm, each a "
                                           "series of passes offset from the blank inward to the finish stock.")

    def setup_sheet_rows(self, facts: _SheetFacts, gear: _SheetGear) -> tuple[SheetRow, ...]:
        """The blank's diameter and thickness, the work offset on its axis and top face, how it is clamped."""
        if gear.root_radius_mm > gear.tip_radius_mm:
            blank, centre = "blank diameter (the rim's outside, not cut)", "the ring's axis (the rim's centre)"
            axis = ("machine Z: the ring clamped flat on its rim (outside the tip circle), relieved 0.5 mm under the "
                    "hole (the programs mill the hole away through the face width)")
        else:
            blank, centre = "blank diameter", "the gear axis (the bore's centre)"
            axis = ("machine Z: the blank clamped flat on its bore or a fixture, relieved 0.5 mm under the outline "
                    "(the programs cut through unless [three_axis] leaves tabs or a skin)")
        return (
            SheetRow("machine", facts.machine_name),
            SheetRow(blank, "{}", (facts.blank_diameter_mm,), unit="mm"),
            SheetRow("blank thickness (faced to the face width)", "{}", (gear.face_width_mm,), unit="mm"),
            SheetRow("work offset", f"{facts.work_offset}: X = 0 and Y = 0 on {centre}, Z = 0 on the blank's top face"),
            SheetRow("tooth space 0", "its axis points to +Y"),
            SheetRow("gear axis", axis),
        )


ROTARY_TABLE = RotaryTable("rotary table", axes=4, rotary_axis=True, reaches=frozenset({"helical teeth"}),
                           follows_modifications=True, tool_kinds=(), finishing_needs_roughing=False, sections=(),
                           z_origin="the rotary axis")
LYING_FLAT = LyingFlat("lying flat", axes=3, rotary_axis=False, reaches=frozenset({"teeth inward"}),
                       follows_modifications=False, tool_kinds=("flat",), finishing_needs_roughing=True,
                       sections=("three_axis",), z_origin="the blank's top face")

SETUPS: dict[int, MachineSetup] = {setup.axes: setup for setup in (ROTARY_TABLE, LYING_FLAT)}
"""Every set-up, by its `[machine] axes` value."""

SETUP_SECTIONS = frozenset(section for setup in SETUPS.values() for section in setup.sections)
"""The job-file sections that belong to one set-up only."""


def setup_for_axes(axes: int) -> MachineSetup:
    """The set-up `[machine] axes` chooses (KeyError for a value no set-up has: Machine's key refuses those)."""
    return SETUPS[axes]
