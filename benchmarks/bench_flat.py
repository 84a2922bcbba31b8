"""Issues 31 and 32: the modified gear's loft, the internal gear's ring, the arc outline and the 2-D export,
and a 3-axis run of the reference gear (median wall seconds of several runs, same machine)."""

from __future__ import annotations

from pathlib import Path

from benchmarks.common import median_seconds

EXAMPLES = Path(__file__).resolve().parent.parent / "resources" / "examples"

EVERY_MODIFICATION = (
    "[gear.modifications]\ntip_relief_um = 12\ntip_relief_start_diameter_mm = 37\n"
    "root_relief_um = 8\nroot_relief_start_diameter_mm = 34.5\nroot_relief_shape = \"parabolic\"\n"
    "profile_crowning_um = 3\nlead_crowning_um = 6\nend_relief_um = 10\nend_relief_length_mm = 2\n"
    "[gear.modifications.left]\ntip_relief_um = 6\ntip_relief_shape = \"parabolic\"\n"
    "profile_slope_um = -2\nlead_crowning_um = 3\nhelix_slope_um = 4\n")
"""A 17-tooth module-2 gear with every modification, different on its two sides (the hardest loft)."""


def _modified_job(helix_angle_deg: float):
    from spur_cad.job import parse_job

    return parse_job(f"[gear]\nteeth = 17\nmodule_mm = 2.0\nface_width_mm = 16\nhelix_angle_deg = {helix_angle_deg}\n"
                     + EVERY_MODIFICATION, "every_modification.toml")


def figures(runs: int) -> dict:
    """Wall seconds (median of `runs`): the lofted modified solids, the ring's B-rep, the arc outline, the
    wire-EDM example's DXF and SVG, and `run_job` of the reference gear lying flat (axes = 3, flat D2 finishing
    tool, simulation on)."""
    from spur_cad.cad.solid import build_gear_shape
    from spur_cad.geometry.outline2d import gear_outline_arcs
    from spur_cad.job import load_job, parse_job
    from spur_cad.pipeline import export_files, run_job

    spur, helical = _modified_job(0.0), _modified_job(20.0)
    ring = load_job(EXAMPLES / "ring_gear.toml")
    reference = load_job(EXAMPLES / "reference_gear.toml")
    edm = load_job(EXAMPLES / "wire_edm_gear.toml")
    flat_text = (EXAMPLES / "reference_gear.toml").read_text().replace("[machine]", "[machine]\naxes = 3", 1).replace(
        'kind = "bull_nose"\ndiameter_mm = 2.0\ncorner_radius_mm = 0.5', 'kind = "flat"\ndiameter_mm = 2.0')
    flat = parse_job(flat_text, "reference_gear_3_axes.toml")
    return {
        "loft_every_modification_spur_s": median_seconds(
            lambda: build_gear_shape(spur.gear, modifications=spur.modifications), runs),
        "loft_every_modification_helical_20deg_s": median_seconds(
            lambda: build_gear_shape(helical.gear, modifications=helical.modifications), runs),
        "ring_z60_m2_brep_s": median_seconds(lambda: build_gear_shape(ring.gear), runs),
        "reference_outline_arcs_1um_s": median_seconds(lambda: gear_outline_arcs(reference.gear, 0.001), runs),
        "reference_outline_arcs": len(gear_outline_arcs(reference.gear, 0.001).segments),
        "wire_edm_example_export_s": median_seconds(lambda: export_files(edm), runs),
        "reference_3_axes_run_job_s": median_seconds(lambda: run_job(flat), max(1, runs // 2)),
    }


if __name__ == "__main__":
    import json

    print(json.dumps(figures(5), indent=2))
