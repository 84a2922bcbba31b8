"""The gears the tests use: the reference gear plus cases that stress other parts of the method."""

from __future__ import annotations

from spur_cad.geometry import GearSpec
from tests.textbook import Textbook

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
