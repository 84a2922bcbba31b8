"""Regenerate the reference job's G-code (every dialect, folded and flat) and profile.csv.

How the committed files were made: at commit d7e374b (the last commit before the architecture
rework of issue 12), from the repository root:

    .venv/bin/python tests/data/make_reference_outputs.py tests/data/reference_outputs

The job is tests/data/reference_outputs/reference_gear.toml, a copy of the reference job file
of that commit (kept here so later changes to resources/examples do not move the target).
Programs are stored xz-compressed (the flat finishing programs are about 30 MB each as text).
tests/test_reference_outputs.py checks that the current code writes exactly these bytes.
"""

from __future__ import annotations

import dataclasses
import lzma
import sys
from pathlib import Path

from spur_cad.job import load_job
from spur_cad.pipeline import build_programs, plan_cam, profile_csv
from spur_cad.geometry.sampling import sample_profile

DIALECTS = ("linuxcnc", "fanuc", "haas", "siemens", "okuma")
HERE = Path(__file__).resolve().parent


def reference_files(job_path: Path) -> dict[str, bytes]:
    """name -> bytes of every reference output (program names carry dialect and folding)."""
    job = load_job(job_path)
    plan = plan_cam(job)
    files = {"profile.csv": profile_csv(sample_profile(job.gear.tooth_space_profile(),
                                                         job.job.profile_tolerance_mm))}
    for dialect in DIALECTS:
        for folded in (True, False):
            variant = dataclasses.replace(job, post=dataclasses.replace(job.post, dialect=dialect, folded=folded))
            _, programs = build_programs(variant, plan)
            for name, content in programs.items():
                files[f"{'folded' if folded else 'flat'}-{dialect}-{name}"] = content
    return files


def main(out_dir: str) -> None:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name, content in reference_files(out / "reference_gear.toml").items():
        target = out / (name if name == "profile.csv" else name + ".xz")
        target.write_bytes(content if name == "profile.csv" else lzma.compress(content, preset=9))
        print(target, len(content))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(HERE / "reference_outputs"))
