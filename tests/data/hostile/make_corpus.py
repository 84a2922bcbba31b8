"""Write the hostile-input corpus: the reproducers of issue 13, each the reference job with
`face_width_mm = 3` and `[simulation] enabled = false`, changed only in the key named.

Each file's first line says what must happen: `# expect: ok` (exit 0, valid outputs) or
`# expect: error [section] key` (exit 2, one line naming the file, the key's own line and the key).
Run from the repository root: `python tests/data/hostile/make_corpus.py` (rewrites the .toml files).
"""

from __future__ import annotations

import re
from pathlib import Path

HERE = Path(__file__).resolve().parent
REFERENCE = HERE.parent / "reference_outputs" / "reference_gear.toml"

# (file stem, section, key, TOML value text or None to delete, expectation)
CASES = [
    ("name_newline_injection", "job", "name", '"evil\\nG0 X0 Y0 Z-50\\nM30"', "ok"),
    ("name_control_characters", "job", "name", '"a\\u0000b\\u0007c\\rG0 Z-50\\u001b(x);%"', "ok"),
    ("name_long_unicode", "job", "name", '"' + "Zahnrad \u00e4\u00f6\u00fc \u2699 " * 400 + '"', "ok"),
    ("clearance_nan", "machine", "clearance_mm", "nan", "error"),
    ("clearance_inf", "machine", "clearance_mm", "inf", "error"),
    ("clearance_negative", "machine", "clearance_mm", "-1.0", "error"),
    ("feed_per_tooth_tiny", "tools.finishing", "feed_per_tooth_mm", "1e-300", "error"),
    ("cutting_speed_tiny", "tools.roughing", "cutting_speed_m_min", "1e-300", "error"),
    ("max_feed_tiny", "machine", "max_feed_mm_min", "1e-300", "error"),
    ("rotary_speed_tiny", "machine", "max_rotary_speed_deg_min", "1e-300", "error"),
    ("rapid_feed_tiny", "machine", "rapid_feed_mm_min", "1e-300", "error"),
    ("max_spindle_huge", "machine", "max_spindle_rpm", "1e300", "error"),
    ("tool_number_huge", "tools.roughing", "tool_number", "9223372036854775807", "error"),
    ("radial_allowance_huge", "stock", "radial_allowance_mm", "1e300", "error"),
    ("front_margin_huge", "stock", "front_margin_mm", "1e300", "error"),
    ("back_margin_huge", "stock", "back_margin_mm", "1e300", "error"),
    ("stub_length_huge", "stock", "stub_length_mm", "1e300", "error"),
    ("module_huge_integer", "gear", "module_mm", "1" + "0" * 400, "error"),
    ("module_string", "gear", "module_mm", '"4"', "error"),
    ("face_width_tiny", "gear", "face_width_mm", "1e-9", "error"),
    ("target_scallop_tiny", "finishing", "target_scallop_mm", "1e-9", "error"),
    ("finishing_step_over_tiny", "finishing", "step_over_mm", "1e-9", "error"),
    ("roughing_step_over_tiny", "roughing", "step_over_fraction", "1e-9", "error"),
    ("roughing_level_depth_tiny", "roughing", "max_level_depth_fraction", "1e-9", "error"),
    ("profile_tolerance_tiny", "job", "profile_tolerance_mm", "1e-15", "error"),
    # The gear itself is fine now (it crashed the inspection); its deep roughing would reach the holding
    # stub, which is refused naming the margin to change.
    ("strongly_negative_shift", "gear", "profile_shift_coefficient", "-1.0", "error [stock] back_margin_mm"),
    ("clamp_code_injection", "machine", "rotary_clamp_code", '"M10\\nG0 Z-50"', "error"),
    ("clamp_code_with_motion", "machine", "rotary_clamp_code", '"M10 G0 Z-50"', "error"),
    ("nested_arrays", "job", "name", "[" * 5000 + "]" * 5000, "error"),
    ("helix_angle_nan", "gear", "helix_angle_deg", "nan", "error"),
    ("helix_angle_huge", "gear", "helix_angle_deg", "1e300", "error"),
    ("hand_injection", "gear", "hand", '"right\\nG0 Z-50"', "error"),
]


def base_text() -> str:
    text = REFERENCE.read_text()
    text = re.sub(r"^face_width_mm = .*$", "face_width_mm = 3.0", text, flags=re.M)
    return text + "\n[simulation]\nenabled = false\n"


def with_value(text: str, section: str, key: str, value: str) -> str:
    """`text` with `key` in `[section]` set to `value` (added at the section's end when absent)."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == f"[{section}]")
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("[")), len(lines))
    for i in range(start + 1, end):
        if re.match(rf"\s*{re.escape(key)}\s*=", lines[i]):
            lines[i] = f"{key} = {value}"
            break
    else:
        lines.insert(end, f"{key} = {value}")
    return "\n".join(lines) + "\n"


def main() -> None:
    base = base_text()
    for stem, section, key, value, expect in CASES:
        if expect == "ok":
            header = "# expect: ok"
        else:
            header = f"# expect: {expect}" if expect != "error" else f"# expect: error [{section}] {key}"
        (HERE / f"{stem}.toml").write_text(header + "\n" + with_value(base, section, key, value))


if __name__ == "__main__":
    main()
