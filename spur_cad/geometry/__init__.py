"""Pure-numpy gear geometry: specification, exact rack-generated profile, sampling, inspection."""

from spur_cad.geometry.involute import inverse_involute_function, involute_function
from spur_cad.geometry.profile import SEGMENT_LABELS, ToothSpaceProfile, build_tooth_space_profile, rack_corner
from spur_cad.geometry.sampling import (
    DEFAULT_TOLERANCE_MM,
    ProfileSamples,
    gear_outline,
    sample_profile,
    tooth_space_samples,
)
from spur_cad.geometry.spec import GearSpec

__all__ = [
    "DEFAULT_TOLERANCE_MM",
    "GearSpec",
    "ProfileSamples",
    "SEGMENT_LABELS",
    "ToothSpaceProfile",
    "build_tooth_space_profile",
    "gear_outline",
    "involute_function",
    "inverse_involute_function",
    "rack_corner",
    "sample_profile",
    "tooth_space_samples",
]
