"""docs/architecture.md's claims about the code, checked on the sources: every rotation is written in
spur_cad/geometry/frames.py, except the simulator's numba kernels named there; no module passes the correction's
facts by string key to the report."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ROTATION = re.compile(  # c y - s z / y c + z s and their spelled-out cos/sin forms, the way R(angle) is written
    r"\b(c|cos\w*|np\.cos\([^)]*\)|math\.cos\([^)]*\))\s*\*\s*[\w\[\]:, .]+?\s*[-+]\s*"
    r"(s|sin\w*|np\.sin\([^)]*\)|math\.sin\([^)]*\))\s*\*"
    # c y - s z written out, or R as a matrix [[c, s], [-s, c]]
    r"|\*\s*(c|cos\w*)\s*[-+]\s*[\w\[\]:, .]+?\*\s*(s|sin\w*)\b"
    r"|\[\[\s*(c|cos\w*)\s*,\s*-?\s*(s|sin\w*)\s*\]\s*,\s*\[\s*-?\s*(s|sin\w*)\s*,\s*(c|cos\w*)\s*\]\]")
ROTATION_HOMES = {"spur_cad/geometry/frames.py",
                  "spur_cad/sim/kernel.py", "spur_cad/sim/engagement.py", "spur_cad/sim/section_engagement.py",
                  # the whole gear's outline turns space 0 by a matrix product, whose rounding (fused multiply-adds)
                  # the STEP, DXF/SVG and 3-axis outputs keep byte-identical; turn_points differs in the last bit
                  "spur_cad/geometry/sampling.py"}


def rotations_written_out() -> dict[str, list[str]]:
    """{file: lines} of the package's and the workbench's sources that write a rotation out."""
    found: dict[str, list[str]] = {}
    for folder in ("spur_cad", "workbench"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            lines = [line.strip() for line in path.read_text(encoding="utf-8").splitlines()
                     if ROTATION.search(line.split("#")[0])]
            if lines:
                found[path.relative_to(ROOT).as_posix()] = lines
    return found


def test_the_search_finds_the_rotations_it_looks_for():
    """The pattern recognises R(angle) as the homes write it (else the next test would pass by finding nothing)."""
    for line in ("return np.stack([c * y - s * z, s * y + c * z], axis=-1)",
                 "x, y = points[:, 1] * c - points[:, 2] * s, 0",
                 "u = np.cos(a) * y - np.sin(a) * z",
                 "return np.stack([x * c + y * s, -x * s + y * c], axis=-1)",
                 "chunks.append(space @ np.array([[c, s], [-s, c]]))"):
        assert ROTATION.search(line), line
    for line in ("d = c * y", "rb * (np.sin(t) - t * np.cos(t))", "area = a * b - c * d"):
        assert not ROTATION.search(line), line
    assert set(rotations_written_out()) == ROTATION_HOMES  # each home writes one


def test_no_module_but_frames_and_the_simulator_kernels_writes_a_rotation():
    outside = {name: lines for name, lines in rotations_written_out().items() if name not in ROTATION_HOMES}
    assert outside == {}, "write rotations with spur_cad.geometry.frames (docs/architecture.md, Frames)"



UNTYPED_ALLOWED = {  # the JobResult's fields that are dictionaries, each of one kind of value under a name of its own
    ("CadResult", "step_bytes"): "STEP file name -> its size",
    ("ErrorBudgetFacts", "inputs"): "the [error_budget] section's values, echoed into summary.json (read by no one)",
    ("ErrorBudgetFacts", "share_um"): "ISO 1328 deviation name -> its share, as Grading names them",
    ("ErrorBudgetFacts", "share_percent"): "ISO 1328 deviation name -> its share",
    ("JobResult", "timings_s"): "stage name -> seconds",
    ("JobResult", "files"): "output file name -> bytes",
}


def test_the_job_result_passes_its_facts_typed():
    """docs/architecture.md: no layer passes dictionaries of facts by string key. Every field of the JobResult and
    of its parts (spur_cad/result.py) is a typed value; the dictionaries left are name -> value tables, listed
    above (JobResult.correction, once correction.json's dict read by key in the report, is CorrectionFacts)."""
    import dataclasses

    import spur_cad.result as result

    found = []
    for name, cls in vars(result).items():
        if not (isinstance(cls, type) and dataclasses.is_dataclass(cls) and cls.__module__ == result.__name__):
            continue
        for field in dataclasses.fields(cls):
            annotation = str(field.type)
            if re.search(r"\b(dict|Any|object)\b", annotation) and (name, field.name) not in UNTYPED_ALLOWED:
                found.append(f"{name}.{field.name}: {annotation}")
    assert found == []

