"""The gears the tests use: the reference gear plus cases that stress other parts of the method."""

from __future__ import annotations

from pathlib import Path

from hypothesis import strategies as st

from spur_cad.cam.recommend import recommend_tools
from spur_cad.cam.strategies import REGISTRY
from spur_cad.cam.tools import Tool
from spur_cad.errors import GearSpecError
from spur_cad.geometry import GearSpec
from tests.textbook import Textbook

REFERENCE_JOB = Path(__file__).resolve().parents[1] / "resources" / "examples" / "reference_gear.toml"


def reference_job_text(strategy: str) -> str:
    """The reference job file with another finishing strategy (it ships with "generating")."""
    text = REFERENCE_JOB.read_text()
    line = next(line for line in text.splitlines() if line.startswith("strategy = "))
    return text.replace(line, f'strategy = "{strategy}"')


def with_roughing_strategy(text: str, strategy: str) -> str:
    """A job file's text with [roughing] strategy given (the shipped examples leave it to the default, flank: given,
    it is planned or refused as given, never falling back to levels)."""
    assert "[roughing]\n" in text
    return text.replace("[roughing]\n", f"[roughing]\nstrategy = \"{strategy}\"\n", 1)


# name: (teeth, module, pressure angle, shift, rack tip radius, allowance fraction, allowance mm)
GEAR_CASES = {
    "reference_z23_m4": (23, 4.0, 20.0, 0.0, 0.8, 0.05, 0.0),
    "undercut_z8": (8, 2.0, 20.0, 0.0, 0.6, 0.0, 0.0),
    "undercut_negative_shift_z14": (14, 1.5, 20.0, -0.3, 0.3, 0.02, 0.0),
    "many_teeth_z120": (120, 1.0, 20.0, 0.0, 0.25, 0.0, 0.02),
    "shifted_z12": (12, 3.0, 20.0, 0.5, 0.5, 0.03, 0.0),
    "small_module_z30": (30, 0.5, 20.0, 0.0, 0.1, 0.0, 0.0),
    "pa14_5_z40": (40, 2.0, 14.5, 0.2, 0.5, 0.0, 0.0),
    "pa25_sharp_rack_z17": (17, 5.0, 25.0, 0.0, 0.0, 0.0, 0.0),
    "big_shift_corner_above_rolling_line_z30": (30, 2.0, 20.0, 1.0, 0.8, 0.0, 0.0),
}


def spec_of(name: str) -> GearSpec:
    z, m, pa, x, rho, frac, mm = GEAR_CASES[name]
    return GearSpec(teeth=z, module_mm=m, pressure_angle_deg=pa, profile_shift_coefficient=x,
                    rack_tip_radius_mm=rho, thickness_allowance_fraction=frac, thickness_allowance_mm=mm,
                    face_width_mm=10.0)


def textbook_of(name: str) -> Textbook:
    z, m, pa, x, rho, frac, mm = GEAR_CASES[name]
    return Textbook(z=z, m=m, alpha_deg=pa, x=x, rho=rho, allowance_fraction=frac, allowance_mm=mm)


# --- CAM test gears and their tools (shared by the CAM, silhouette and post tests) ---------------------

CAM_GEARS = ["reference_z23_m4", "undercut_z8", "many_teeth_z120", "shifted_z12", "small_module_z30"]


def tools_for(name: str) -> tuple[Tool, Tool]:
    """Roughing and finishing tools sized from each gear's limits (as a user would pick them)."""
    spec = spec_of(name)
    perimeter = REGISTRY["perimeter"]  # sized for the contact strategies: the roughing within its plunge allowance
    rec = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0, strategy=perimeter)
    r_t = round(0.6 * min(rec.finishing_max_corner_radius_mm, spec.rack_tip_radius_mm), 3)
    d = round(0.6 * rec.finishing_max_flat_width_mm, 3)
    finishing = Tool(diameter_mm=d + 2 * r_t, kind="bull_nose", corner_radius_mm=r_t)
    rec_f = recommend_tools(spec, spec.tip_radius_mm + 0.5, 1.0, finishing, strategy=perimeter)
    roughing = Tool(diameter_mm=round(0.8 * rec_f.roughing_max_diameter_mm, 3), kind="flat", flutes=3)
    return roughing, finishing


# --- swept gear parameters (shared by the geometry and CAD sweeps) -------------------------------------

_SPUR_PARAMETERS = {
    "teeth": st.integers(6, 200),
    "module_mm": st.floats(0.3, 20.0),
    "pressure_angle_deg": st.floats(14.5, 30.0),
    "profile_shift_coefficient": st.floats(-0.5, 1.0),
    "rack_tip_fraction": st.floats(0.0, 0.45),
    "thickness_allowance_fraction": st.floats(0.0, 0.05),
}
gear_parameters = st.fixed_dictionaries(_SPUR_PARAMETERS)
helical_parameters = st.fixed_dictionaries({**_SPUR_PARAMETERS, "helix_angle_deg": st.floats(0.0, 45.0),
                                            "hand": st.sampled_from(["right", "left"])})


def spec_or_category(params: dict, face_width_mm: float) -> GearSpec | tuple[str, str]:
    """The GearSpec for swept parameters (rack tip radius given as a fraction of the module), or
    the failure category: ('rejected', message) or ('crash', repr)."""
    params = dict(params)
    params["rack_tip_radius_mm"] = params.pop("rack_tip_fraction") * params["module_mm"]
    try:
        return GearSpec(face_width_mm=face_width_mm, **params)
    except GearSpecError as exc:
        return ("rejected", str(exc)) if str(exc) else ("crash", "empty GearSpecError message")
    except Exception as exc:  # noqa: BLE001 - the category is the point
        return "crash", f"{type(exc).__name__}: {exc}"
