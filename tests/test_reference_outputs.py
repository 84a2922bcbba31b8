"""The reference job's G-code (every dialect, folded and flat) and profile.csv are byte-identical
to the files generated before the architecture rework (tests/data/make_reference_outputs.py says
how they were made). A refactoring that changes one byte of a program fails here.

The roughing programs were stored again for issue 29 (roughing's passes over the tip lands): each differs from
the earlier one only by the inserted tip-pass blocks (four per tooth: index A half a pitch on, down to the tip
circle + finish stock, one pass along X, up) and the header's estimated time, checked line by line before
they were written."""

from __future__ import annotations

import lzma
from pathlib import Path

import pytest

from spur_cad.job import load_job
from tests.data.make_reference_outputs import reference_files

REFERENCE_DIR = Path(__file__).resolve().parent / "data" / "reference_outputs"


def _added_blocks(dialect: str) -> tuple[str, ...]:
    """Blocks added on purpose since the reference files were made (issue 18: every program selects its work
    offset, G54 by default; Siemens also describes the blank's box, X from the front margin to the stub's end,
    Y and Z +-blank radius, with WORKPIECE). Each must be there exactly once, in front of the tool change;
    without them the programs must be the reference bytes."""
    if dialect == "okuma":
        return ("G15 H1",)
    if dialect != "siemens":
        return ("G54",)
    job = load_job(REFERENCE_DIR / "reference_gear.toml")
    r = job.stock.blank_radius_mm(job.gear)
    x_max = job.gear.face_width_mm + job.stock.back_margin_mm + job.stock.stub_length_mm
    return (f'WORKPIECE(,"",,"BOX",112,{r:.1f},{-r:.1f},-80,{-job.stock.front_margin_mm:.1f},{-r:.1f},{x_max:.1f},'
            f'{r:.1f})', "G54")


def _without_added_blocks(name: str, content: bytes) -> bytes:
    if not name.endswith((".ngc", ".nc", ".mpf", ".min")):
        return content
    dialect = name.split("-")[1]
    lines = content.decode().split("\n")
    first_tool = next(i for i, line in enumerate(lines) if line.startswith(("T1 ", "T2 ")))
    for block in _added_blocks(dialect):
        assert lines.count(block) == 1 and lines.index(block) < first_tool, (name, block)
        lines.remove(block)
    return "\n".join(lines).encode()


def _first_difference(expected: bytes, actual: bytes) -> str:
    old, new = expected.decode().splitlines(), actual.decode().splitlines()
    for number, (a, b) in enumerate(zip(old, new), start=1):
        if a != b:
            return f"line {number}: expected {a!r}, got {b!r}"
    return f"line counts differ: expected {len(old)}, got {len(new)}"


@pytest.mark.slow
def test_reference_job_outputs_are_byte_identical() -> None:
    files = reference_files(REFERENCE_DIR / "reference_gear.toml")
    stored = sorted(p.name for p in REFERENCE_DIR.iterdir() if p.name.endswith((".xz", ".csv")))
    assert sorted(name if name == "profile.csv" else name + ".xz" for name in files) == stored
    for name, content in files.items():
        path = REFERENCE_DIR / (name if name == "profile.csv" else name + ".xz")
        expected = path.read_bytes() if name == "profile.csv" else lzma.decompress(path.read_bytes())
        content = _without_added_blocks(name, content)
        assert content == expected, f"{name}: {_first_difference(expected, content)}"


@pytest.mark.slow
def test_a_zero_helix_angle_of_either_hand_gives_the_same_bytes(tmp_path) -> None:
    """helix_angle_deg = 0 is a spur gear whatever the hand: the reference job with both keys written out
    makes the stored files byte for byte (G-code of every dialect, profile.csv)."""
    text = (REFERENCE_DIR / "reference_gear.toml").read_text()
    assert "helix_angle_deg" not in text and "[gear]\n" in text
    job = tmp_path / "reference_gear.toml"
    job.write_text(text.replace("[gear]\n", '[gear]\nhelix_angle_deg = 0.0\nhand = "left"\n', 1))
    files = reference_files(job)
    for name, content in files.items():
        path = REFERENCE_DIR / (name if name == "profile.csv" else name + ".xz")
        expected = path.read_bytes() if name == "profile.csv" else lzma.decompress(path.read_bytes())
        content = _without_added_blocks(name, content)
        assert content == expected, f"{name}: {_first_difference(expected, content)}"
