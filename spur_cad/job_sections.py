"""The job file's own sections ([job], [gear], [gear.modifications], [simulation], [export], [tools]) and the
table of every section the file may hold (SECTIONS) with its dataclass; the other sections are declared beside
the code they set up (stock, machine, roughing, finishing, post, lathe, probe, mate). spur_cad.job reads them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from spur_cad.cad.specs import BlankFeatures, StockSpec
from spur_cad.cam.machine import Machine, RoughingParams
from spur_cad.cam.materials import DEFAULT_MATERIAL, MATERIALS
from spur_cad.cam.probing import ProbeSection
from spur_cad.cam.strategies import FinishingParams
from spur_cad.cam.three_axis_tabs import ThreeAxisSection
from spur_cad.cam.tools import Tool
from spur_cad.cam.turning import LatheSection
from spur_cad.errors import GearSpecError, JobFileError, SimulationError
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.spec import MAX_TEETH, MIN_TEETH, GearSpec
from spur_cad.keys import check_section, key
from spur_cad.mate_section import MateSection
from spur_cad.post.settings import PostSettings


@dataclass(frozen=True)
class JobSection:
    """[job]: name and the chordal tolerance of sampled profiles."""

    name: str = key("gear job", label="JobName", group="Job", meaning="job name (summary, program headers)")
    profile_tolerance_mm: float = key(0.001, unit="mm", low=0.0001, high=0.1, label="ProfileTolerance", group="Job",
                                      meaning="chordal tolerance of sampled profiles (profile.csv)")
    report_template: str = key("", label="ReportTemplate", group="Job",
                               meaning="report.html's Jinja2 template, a file relative to the job file, in its "
                                       "folder or a --side-files folder (empty: spur_cad's own, "
                                       "spur_cad/report/templates/report.html.j2: copy it to start)")
    material: str = key(DEFAULT_MATERIAL, choices=tuple(MATERIALS), label="Material", group="Job",
                        meaning="the gear's material: its specific cutting force (Kienzle k_c1.1, m_c; "
                                "spur_cad/cam/materials.py) sets the finishing tool's deflection in the error budget")

    def __post_init__(self) -> None:
        """Every key in its declared range or choices, checked once when the section is made."""
        check_section(self, "job", JobFileError)


@dataclass(frozen=True)
class GearSection:
    """[gear]: the gear as ISO 21771 names it, plus the blank's bore and keyway."""

    teeth: int = key(low=MIN_TEETH, high=MAX_TEETH, label="Teeth", group="Gear", meaning="number of teeth z")
    module_mm: float = key(unit="mm", low=0.05, high=100.0, label="Module", group="Gear", meaning="module m")
    face_width_mm: float = key(unit="mm", low=0.5, high=2000.0, label="FaceWidth", group="Gear",
                               meaning="face width b, along the rotary axis X")
    pressure_angle_deg: float = key(20.0, unit="deg", low=10.0, high=35.0, label="PressureAngle", group="Gear",
                                    meaning="pressure angle alpha")
    profile_shift_coefficient: float = key(0.0, low=-2.0, high=3.0, label="ProfileShift", group="Gear",
                                           meaning="profile shift coefficient x")
    addendum_coefficient: float = key(1.0, low=0.5, high=2.0, label="AddendumCoefficient", group="Rack",
                                      meaning="addendum coefficient h_a* of the generated gear")
    dedendum_coefficient: float = key(1.25, low=0.5, high=2.5, label="DedendumCoefficient", group="Rack",
                                      meaning="dedendum coefficient h_f* of the generated gear")
    rack_tip_radius_mm: float = key(0.0, unit="mm", low=0.0, high=60.0, label="RackTipRadius", group="Rack",
                                    meaning="tip corner radius rho of the generating rack (at most 0.6 x module)")
    thickness_allowance_percent: float = key(0.0, unit="%", low=0.0, high=20.0, label="ThicknessAllowancePercent",
                                             group="Allowance",
                                             meaning="nominal tooth thickness reduced by this percentage "
                                                     "(the reference process's profile clearance, 0-5 % typical)")
    thickness_allowance_mm: float = key(0.0, unit="mm", low=0.0, high=50.0, label="ThicknessAllowance",
                                        group="Allowance",
                                        meaning="further absolute tooth thickness reduction (at most 0.5 x module; "
                                                "normal section for helical gears)")
    helix_angle_deg: float = key(0.0, unit="deg", low=0.0, high=45.0, label="HelixAngle", group="Gear",
                                 meaning="helix angle beta on the reference cylinder, 0: spur gear (module, pressure "
                                         "angle, shift, coefficients and rack tip radius are then normal-section "
                                         "values)")
    hand: str = key("right", label="Hand", group="Gear", choices=("right", "left"),
                    meaning="hand of the helix (helical gears)")
    internal: bool = key(False, label="Internal", group="Gear",
                         meaning="internal spur gear (ring gear) cut by a pinion-type shaper cutter; its CAM needs the "
                                 "3-axis variant (docs/geometry.md, Internal gears)")
    shaper_cutter_teeth: int = key(20, low=MIN_TEETH, high=MAX_TEETH, label="ShaperCutterTeeth", group="Gear",
                                   meaning="internal gears: teeth z_0 of the shaper cutter (the external gear the rack "
                                           "generates, tip corners rounded by rack_tip_radius_mm)")
    shaper_cutter_profile_shift_coefficient: float = key(
        0.0, low=-1.0, high=1.5, label="ShaperCutterProfileShift", group="Gear",
        meaning="internal gears: profile shift coefficient x_0 of the shaper cutter")
    rim_outer_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=4000.0, label="RimOuterDiameter", group="Gear",
                                       meaning="internal gears: outside diameter of the ring's rim (at least 2 modules "
                                               "below the root circle)")
    mating_pinion_teeth: int = key(0, low=0, high=MAX_TEETH, label="MatingPinionTeeth", group="Gear",
                                   meaning="internal gears: teeth of the mating pinion for the tip interference check, "
                                           "0: not checked")
    bore_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="BoreDiameter", group="Bore",
                                  meaning="through bore diameter, 0: none")
    keyway_width_mm: float = key(0.0, unit="mm", low=0.0, high=500.0, label="KeywayWidth", group="Bore",
                                 meaning="hub keyway width, 0: none")
    keyway_depth_mm: float = key(0.0, unit="mm", low=0.0, high=200.0, label="KeywayDepth", group="Bore",
                                 meaning="hub keyway depth from the bore surface, 0: none")

    def __post_init__(self) -> None:
        """Every key in its declared range or choices, checked once when the section is made (what the keys decide
        together is GearSpec's to check: to_spec)."""
        check_section(self, "gear", GearSpecError)

    def to_spec(self) -> GearSpec:
        """The GearSpec ([gear] internal = true: an InternalGearSpec, spur only)."""
        common: dict[str, Any] = dict(
            teeth=self.teeth, module_mm=self.module_mm, pressure_angle_deg=self.pressure_angle_deg,
            profile_shift_coefficient=self.profile_shift_coefficient,
            addendum_coefficient=self.addendum_coefficient, dedendum_coefficient=self.dedendum_coefficient,
            rack_tip_radius_mm=self.rack_tip_radius_mm,
            thickness_allowance_fraction=self.thickness_allowance_percent / 100.0,
            thickness_allowance_mm=self.thickness_allowance_mm, face_width_mm=self.face_width_mm,
            helix_angle_deg=self.helix_angle_deg, hand=self.hand,
        )
        if not self.internal:
            return GearSpec(**common)
        return InternalGearSpec(**common, shaper_cutter_teeth=self.shaper_cutter_teeth,
                                shaper_cutter_profile_shift_coefficient=self.shaper_cutter_profile_shift_coefficient,
                                rim_outer_diameter_mm=self.rim_outer_diameter_mm,
                                mating_pinion_teeth=self.mating_pinion_teeth)

    def blank_features(self) -> BlankFeatures:
        return BlankFeatures(self.bore_diameter_mm, self.keyway_width_mm, self.keyway_depth_mm)


def _amount(label: str, meaning: str, signed: bool = False):
    """A modification amount key (um): 0 = none; beyond 10 % of the module is refused with the gear."""
    return key(0.0, unit="um", low=-10000.0 if signed else 0.0, high=10000.0, label=label,
               group="Flank modifications", meaning=meaning)


@dataclass(frozen=True)
class ModificationsSection:
    """[gear.modifications] / [gear.modifications.left] / [gear.modifications.right]: flank modifications
    (micro-geometry, ISO 21771 names; docs/geometry.md), amounts in um removed along the flank normal, lengths in mm.
    [gear.modifications] sets both flank sides; a .left or .right table overrides the keys it gives for that side.
    Amounts are at most 10 % of the module; reliefs start on the usable involute (form to tip diameter)."""

    tip_relief_um: float = _amount("TipRelief", "tip relief C_a: removed at the tip diameter")
    tip_relief_start_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=5000.0, label="TipReliefStartDiameter",
                                              group="Flank modifications",
                                              meaning="diameter d_Ca where the tip relief starts (needed with it)")
    tip_relief_shape: str = key("linear", choices=("linear", "parabolic"), label="TipReliefShape",
                                group="Flank modifications",
                                meaning="tip relief along the roll length: linear or parabolic")
    root_relief_um: float = _amount("RootRelief", "root relief C_f: removed at the form diameter (start of the "
                                                  "usable involute)")
    root_relief_start_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=5000.0, label="RootReliefStartDiameter",
                                               group="Flank modifications",
                                               meaning="diameter d_Cf where the root relief starts, toward the root "
                                                       "(needed with it)")
    root_relief_shape: str = key("linear", choices=("linear", "parabolic"), label="RootReliefShape",
                                 group="Flank modifications",
                                 meaning="root relief along the roll length: linear or parabolic")
    profile_crowning_um: float = _amount("ProfileCrowning", "profile crowning C_alpha: removed at both ends of the "
                                                            "usable involute, parabolic, none at its middle")
    profile_slope_um: float = _amount("ProfileSlope", "design profile slope f_Halpha: the material grows by this "
                                                      "from the form diameter to the tip (signed, none at "
                                                      "mid-profile)", signed=True)
    lead_crowning_um: float = _amount("LeadCrowning", "lead crowning C_beta: removed at both faces, parabolic, none "
                                                      "at mid-face")
    end_relief_um: float = _amount("EndRelief", "end relief C_I / C_II: removed at the face(s), linear")
    end_relief_length_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="EndReliefLength",
                                      group="Flank modifications",
                                      meaning="length L_I / L_II of the end relief from the face (needed with it)")
    end_relief_faces: str = key("both", choices=("both", "front", "back"), label="EndReliefFaces",
                                group="Flank modifications",
                                meaning="faces with end relief: both, front (X = 0) or back (X = b)")
    helix_slope_um: float = _amount("HelixSlope", "design helix slope f_Hbeta: the material grows by this from the "
                                                  "front face to the back face (signed, none at mid-face)",
                                    signed=True)

    def __post_init__(self) -> None:
        """Every key in its declared range or choices, checked once when the table is made (the amounts against the
        gear: spur_cad.geometry.modifications.flank_modification)."""
        check_section(self, "gear.modifications", GearSpecError)


MODIFICATION_SECTIONS: dict[str, type] = {
    "gear.modifications": ModificationsSection,
    "gear.modifications.left": ModificationsSection,
    "gear.modifications.right": ModificationsSection,
}
"""The flank modification tables: read with [gear] (in the workbench, the gear's "Flank modifications" groups)."""


@dataclass(frozen=True)
class SimulationSection:
    """[simulation]: verification by simulated cutting (see docs/simulation.md)."""

    enabled: bool = key(True, label="SimulationEnabled", group="Simulation",
                        meaning="cut the stock with the roughing and finishing IR and measure it against the design "
                                "(summary simulation.*, deviation map in report.html)")
    # The simulator's blades reach 0.5 mm into the material, at least 10 x the resolution: 0.05 mm at most.
    resolution_mm: float = key(0.005, unit="mm", low=0.0005, high=0.05, label="SimulationResolution",
                               group="Simulation",
                               meaning="bound of the simulation's own error; finer is slower (about 4 x per halving)")

    def __post_init__(self) -> None:
        """Raise SimulationError for a value outside its declared range, once, when the section is made (e.g. with
        the resolution the workbench's Simulate command asks for)."""
        check_section(self, "simulation", SimulationError)


@dataclass(frozen=True)
class ExportSection:
    """[export]: the gear's transverse outline as 2-D drawings for wire EDM, laser and waterjet (docs/geometry.md):
    closed loops of arcs and lines within [job] profile_tolerance_mm, offset by offset_mm."""

    dxf: bool = key(False, label="ExportDxf", group="2-D export",
                    meaning="write gear.dxf: one closed LWPOLYLINE with arcs per loop, layers OUTLINE and BORE, mm "
                            "(spur gears only)")
    svg: bool = key(False, label="ExportSvg", group="2-D export",
                    meaning="write gear.svg: the same loops as SVG paths with arcs, in mm (spur gears only)")
    offset_mm: float = key(0.0, unit="mm", low=-10.0, high=10.0, label="ExportOffset", group="2-D export",
                           meaning="loops offset this far away from the material (outside the gear, inside the bore): "
                                   "wire radius plus spark gap for wire EDM, half the kerf for laser and waterjet, "
                                   "so the file is the path of the cut's centre; 0: the part's own outline")

    def __post_init__(self) -> None:
        """Every key in its declared range, checked once when the section is made (the offset against the gear's
        root: spur_cad.job's export check)."""
        check_section(self, "export", JobFileError)


@dataclass(frozen=True)
class ToolsSection:
    """[tools]: the roughing and finishing tools (without them the job stops after the CAD stage)."""

    roughing: Tool | None = None
    finishing: Tool | None = None
    bottom: Tool | None = None  # two-stage roughing: a smaller tool for the bottom of the spaces
    roughing_top: Tool | None = None  # two-stage roughing offered: a larger tool for the upper part of the spaces


# Every section of the job file and its dataclass, in the order of the documentation and the workbench.
SECTIONS: dict[str, type] = {
    "job": JobSection,
    "gear": GearSection,
    "mate": MateSection,
    "stock": StockSpec,
    "tools.roughing": Tool,
    "tools.finishing": Tool,
    "tools.bottom": Tool,
    "tools.roughing_top": Tool,
    "roughing": RoughingParams,
    "finishing": FinishingParams,
    "machine": Machine,
    "three_axis": ThreeAxisSection,
    "simulation": SimulationSection,
    "export": ExportSection,
    "post": PostSettings,
    "lathe": LatheSection,
    "probe": ProbeSection,
}
