"""What a job's run found, typed end to end: `JobResult` and its small frozen parts.

`spur_cad.pipeline.run_job` returns one; summary.json is its one serialisation (`spur_cad.summary`),
and the report, the CLI and the workbench read its fields. The parts hold the lower layers' own types
(the CAM plan's estimates, the tool recommendations, the simulation's places, the `Grading`) rather than
copies in dictionaries.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from spur_cad.cam.setups import ROTARY_TABLE, MachineSetup
from spur_cad.geometry.kinds import EXTERNAL_SPUR, GearKind
from spur_cad.geometry.mate import GearPair, PairFacts
from spur_cad.keys import SectionValues

if TYPE_CHECKING:  # annotations only: the CAD kernel and the simulator load when a job uses them
    from spur_cad.cad.specs import GearSolidReport
    from spur_cad.cam.estimate import Estimate
    from spur_cad.cam.recommend import ToolRecommendations
    from spur_cad.cam.strategies.base import StrategyFacts, ToolAdvice
    from spur_cad.geometry.inspection import InspectionSheet, ModificationInspection
    from spur_cad.geometry.spec import GearFacts
    from spur_cad.grade.grading import Grading
    from spur_cad.sim.budget import BudgetTerms, Deflection
    from spur_cad.sim.simulate import DeviationPlace


@dataclass(frozen=True)
class JobFacts:
    """The job's name and the file it was read from (as shown in messages)."""

    name: str
    file: str


@dataclass(frozen=True)
class SegmentCounts:
    """Sampled profile points per segment of the half tooth space."""

    root: int
    fillet: int
    involute: int
    tip: int


@dataclass(frozen=True)
class ProfileFacts:
    """profile.csv: its chordal tolerance, its points and their segments."""

    tolerance_mm: float
    points: int
    points_per_segment: SegmentCounts


@dataclass(frozen=True)
class CadResult:
    """The CAD stage's facts: the solid's spline-fit report, volumes and STEP file sizes."""

    report: GearSolidReport
    gear_volume_mm3: float
    stock_volume_mm3: float
    step_bytes: dict[str, int]


@dataclass(frozen=True)
class ToolFacts:
    """A chosen tool as the job runs it: shape, spindle speed and feed (tool_number shown for the bottom tool)."""

    kind: str
    diameter_mm: float
    corner_radius_mm: float
    flat_width_mm: float
    spindle_rpm: float
    feed_mm_min: float
    tool_number: int
    flutes: int = 0
    flute_length_mm: float = 0.0  # 0: not given
    stick_out_mm: float = 0.0  # 0: not given


@dataclass(frozen=True)
class SetupFacts:
    """How the part sits on the machine and what the programs reach (the report's set-up sheet): the blank
    (X from the front face), the holding stub, the work offset, A's sense, coolant, the programmed tool-tip Z
    range over every operation, and the roughing's stock, step-down and step-over."""

    machine_name: str
    blank_diameter_mm: float
    blank_x_min_mm: float
    blank_x_max_mm: float
    stub_diameter_mm: float
    stub_length_mm: float
    work_offset: str
    rotary_sign: int
    coolant: bool
    clearance_mm: float
    z_min_mm: float | None
    z_max_mm: float | None
    finish_stock_mm: float
    flank_allowance_mm: float
    roughing_step_down_mm: float | None
    roughing_step_over_mm: float | None
    machine_setup: MachineSetup = ROTARY_TABLE  # [machine] axes's set-up (the sheet describes it)


@dataclass(frozen=True)
class ToolsFacts:
    """The recommendations for the gear, the chosen tools, and the finishing strategy's own tool advice."""

    recommendations: ToolRecommendations
    roughing: ToolFacts | None
    finishing: ToolFacts | None
    advice_strategy: str | None = None  # the strategy whose advice `advice` is
    advice: ToolAdvice | None = None  # the strategy's typed advice dataclass (e.g. GeneratingAdvice)


@dataclass(frozen=True)
class TwoStageFacts:
    """Two-stage roughing: the bottom tool, the split, its own levels and the time saved."""

    bottom_tool: ToolFacts
    split_height_above_root_mm: float
    split_chosen_by: str
    bottom: RoughingFacts
    two_stage_time_s: float
    bottom_tool_alone_time_s: float
    time_saved_s: float


@dataclass(frozen=True)
class DeclinedTwoStageFacts:
    """Two-stage roughing the job's tools allow, not used: the bottom tool alone is quicker."""

    roughing_tool: ToolFacts  # the larger tool, which would have roughed the upper part
    two_stage_time_s: float
    bottom_tool_alone_time_s: float


@dataclass(frozen=True)
class SuggestedTopToolFacts:
    """Roughing by flanks with one tool: a larger top tool the job does not give would save time (cam.plan
    suggested_top_tool)."""

    top_tool_diameter_mm: float
    two_stage_time_s: float
    roughing_tool_alone_time_s: float


@dataclass(frozen=True)
class FlankSuggestionFacts:
    """Roughing by levels: roughing by flanks with the same tool and cutting data would save time (cam.plan
    suggested_flank_roughing)."""

    flank_time_s: float
    levels_time_s: float
    passes_per_space: int


@dataclass(frozen=True)
class LevelsSuggestionFacts:
    """Roughing by flanks: roughing by levels with the same tool and cutting data would save time (cam.plan
    suggested_levels_roughing)."""

    levels_time_s: float
    flank_time_s: float
    levels_per_space: int


@dataclass(frozen=True)
class RoughingFacts:
    """One roughing operation: its levels and its estimate (and two-stage roughing's bottom operation)."""

    levels_per_space: int
    lowest_level_height_mm: float
    level_heights_mm: tuple[float, ...]
    estimate: Estimate
    two_stage: TwoStageFacts | None = None
    tip_heights_mm: tuple[float, ...] = ()  # passes over each tip land (tooth axis up), top to bottom
    # Measured on the simulated stock over every roughing move (both operations of two-stage roughing); None
    # without a simulation (spur_cad.sim.engagement).
    max_radial_engagement_fraction: float | None = None  # a_e / D
    max_axial_depth_mm: float | None = None  # a_p
    mean_removal_rate_mm3_min: float | None = None  # removed volume / time of the moves removing it
    # The flank strategy (cam.flank_roughing): passes of one space and its flank segments' turns of A; None / ()
    # for roughing by levels.
    passes_per_space: int | None = None
    flank_turns_deg: tuple[float, ...] = ()
    two_stage_declined: DeclinedTwoStageFacts | None = None
    two_stage_suggested: SuggestedTopToolFacts | None = None
    flank_suggested: FlankSuggestionFacts | None = None
    # roughing by flanks as the job file's default, not used (cam.plan.plan_cam): why; roughing is by levels
    flank_fallback: str | None = None
    levels_suggested: LevelsSuggestionFacts | None = None


@dataclass(frozen=True)
class FinishingFacts:
    """The finishing operation: its strategy, the strategy's own typed facts (its summary fields and report
    sentence), its estimate, and the comparison estimates (None when not estimated)."""

    strategy: str
    strategy_facts: StrategyFacts
    report_text: str
    estimate: Estimate
    perimeter: Estimate | None
    reference_strategy: Estimate | None


@dataclass(frozen=True)
class ProgramFacts:
    """One posted program: its operation, lines, bytes and subprograms."""

    operation: str
    lines: int
    bytes: int
    subprograms: int


@dataclass(frozen=True)
class PostFacts:
    """The post: dialect, folding and each program's size, and the programs' file extension (the dialect's)."""

    dialect: str
    folded: bool
    programs: tuple[ProgramFacts, ...]
    extension: str

    def program(self, operation: str) -> ProgramFacts | None:
        return next((p for p in self.programs if p.operation == operation), None)


@dataclass(frozen=True)
class FeatureDeviation:
    """The simulated deviations on one feature of the tooth space (mm)."""

    feature: str
    max_gouge_mm: float
    max_leftover_mm: float
    mean_mm: float


@dataclass(frozen=True)
class SimulationFacts:
    """The simulated cut measured against the design (mm); only `enabled` and the resolution when off."""

    enabled: bool
    resolution_mm: float
    max_gouge_mm: float = 0.0
    max_leftover_mm: float = 0.0
    removed_volume_mm3: float = 0.0
    seconds: float = 0.0
    design_points: int = 0
    points_per_space: int = 0
    rows: int = 0
    point_spacing_mm: float = 0.0
    uncut_points: int = 0
    scallop_mean_mm: float = 0.0
    scallop_p95_mm: float = 0.0
    scallop_p99_mm: float = 0.0
    worst_gouge: DeviationPlace | None = None
    worst_leftover: DeviationPlace | None = None
    per_feature: tuple[FeatureDeviation, ...] = ()
    moves: int = 0
    poses_clipped: int = 0
    x_sweeps: int = 0
    gouge_range_mm: float = 0.0
    leftover_range_mm: float = 0.0

    def feature(self, name: str) -> FeatureDeviation | None:
        return next((f for f in self.per_feature if f.feature == name), None)


@dataclass(frozen=True)
class LatheFacts:
    """The blank's lathe program: the control, the bar and the part it turns (mm)."""

    dialect: str
    bar_diameter_mm: float
    blank_diameter_mm: float
    blank_length_mm: float
    stub_diameter_mm: float
    stub_length_mm: float
    part_off: bool
    work_offset: str


@dataclass(frozen=True)
class ErrorBudgetFacts:
    """The simulated gear cut on the machine of the job's error budget (spur_cad.sim.budget): the budget's
    inputs, the terms as applied, the finishing tool's deflection, the expected grade, each deviation's share
    from the budget (expected minus ideal, um and percent of the expected) and the change of the tooth
    thickness (arc on the reference circle, um; + thicker)."""

    inputs: dict[str, Any]
    terms: BudgetTerms
    deflection: Deflection | None
    grading: Grading
    share_um: dict[str, float]
    share_percent: dict[str, float | None]
    tooth_thickness_change_um: float


@dataclass(frozen=True)
class HarmonicFacts:
    """One kept order h of the rotary table's error e(A) = amplitude x sin(h A + phase) (arcsec, deg)."""

    order: int
    amplitude_arcsec: float
    phase_deg: float
    uncertainty_arcsec: float


@dataclass(frozen=True)
class SlopeFacts:
    """One side's profile or helix slope (um): as identified with its uncertainty, before and as predicted after, and
    for the profile the pressure angle change as cut it means (deg; None for a helix slope)."""

    side: str
    value_um: float
    uncertainty_um: float
    before_um: float
    after_um: float
    pressure_angle_change_deg: float | None = None


@dataclass(frozen=True)
class PitchFacts:
    """One side's total pitch deviation F_p (um) before and as predicted after the table's correction."""

    side: str
    before_um: float
    after_um: float


@dataclass(frozen=True)
class CorrectionFacts:
    """spur-cad correct's correction as the report of the corrected set shows it (correction.json is its full
    serialisation; spur_cad.correct.summary makes both): where the measured gear came from, the size error and the
    finishing tool programmed for it, the table's kept orders (None when a probe log could not see the table), the
    flanks' F_p and slopes before and predicted after, and what is not corrected and why, one line each."""

    measured: str
    points_used: int
    size_um: float
    size_uncertainty_um: float
    tool_before_mm: float
    tool_programmed_mm: float
    flank_position_before_um: float
    flank_position_after_um: float
    table_kept: tuple[HarmonicFacts, ...] | None  # None: the table was not seen
    table_orders_tested: tuple[int, int] | None  # (lowest, highest); None when none was tested
    a_words_moved: bool  # every block's A moved by -e(A)
    y_z_words_moved: bool  # order 1 taken for the blank's offset: every block's Y and Z moved
    unfolded: bool  # the programs written unfolded
    pitch: tuple[PitchFacts, ...]  # the sides whose every flank was measured
    profile_slopes: tuple[SlopeFacts, ...]
    helix_slopes: tuple[SlopeFacts, ...]
    slopes_corrected: bool
    notes: tuple[str, ...]


@dataclass(frozen=True)
class JobResult:
    """Everything a run found, and the output set's files ({name: bytes}, written by spur_cad.outputs)."""

    version: str
    job: JobFacts
    gear: GearFacts
    inspection: InspectionSheet
    profile: ProfileFacts
    cad: CadResult | None  # None only while a run's CAD worker still builds (a finished run's result has it)
    tools: ToolsFacts
    roughing: RoughingFacts | None
    finishing: FinishingFacts | None
    warnings: tuple[str, ...]
    post: PostFacts
    simulation: SimulationFacts
    grading: Grading | None
    lathe: LatheFacts | None
    timings_s: dict[str, float]
    files: dict[str, bytes] = field(default_factory=dict)
    setup: SetupFacts | None = None  # the report's set-up sheet (not in summary.json)
    error_budget: ErrorBudgetFacts | None = None  # the expected grade with the machine's errors (None: no simulation)
    correction: CorrectionFacts | None = None  # spur-cad correct's correction of a corrected set (the report)
    modifications: ModificationInspection | None = None  # the flank modifications on the inspection sheet
    kind: GearKind = EXTERNAL_SPUR  # the gear's kind (spur_cad.geometry.kinds; not in summary.json)
    pair: GearPair | None = None  # the gear and its [mate] (None: no [mate], the checks assume the basic rack)
    mate: PairFacts | None = None  # the pair's ISO 21771 quantities (summary.json's `mate`)
    # every key of every section of the job as the run used it (summary.json's `job_file`, the report's
    # "Job file"; spur_cad.job.Job.section_values)
    job_file: tuple[SectionValues, ...] = ()
