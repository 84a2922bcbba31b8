"""summary.json keeps its keys and values: the reference and helical examples' summaries equal the ones
recorded before the typed result (tests/data/golden/, made by `spur-cad run` of commit 8accc5c), key for key
and in the same order; only the run's own timings may differ, and two figures changed on purpose since
(KEY_REL_TOL, and gear.step / stock.step's sizes: their PRODUCT is named after the part since issue 27,
where OCCT named it 'Open CASCADE STEP translator 7.9 <n>', n counting the shapes the process wrote before,
so that a long test run or a second Export wrote other sizes), and roughing since issue 29: its passes over the
tip lands (roughing.tip_pass_heights_mm, one cut to the tip circle + finish stock per tooth in both examples)
add 4 moves per tooth to the reference gear's roughing, 6 (two passes) to the helical one's, with their
lengths and times, the roughing programs' lines and the simulation's move counts; the finishing programs and
the simulated deviations are unchanged (the helical removed volume grew by 0.003 mm^3, in the margins). Since
issue 29's point 5, what roughing may leave above the root is the finishing strategy's rule: both examples
finish by generation, which never plunges, so tools.plunge_allowance_mm is 0.5 x D of their 2 mm finishing tool
(it was A_p, half its flat width) and tools.roughing_max_diameter_mm the space's width at that height
(CHANGED_ON_PURPOSE); their tools, programs and everything else are unchanged. Issue 30 added one key to the
recorded summaries, `error_budget` after `grading` (the expected grade with the machine's error budget, from the
[machine] accuracy keys' defaults): `grading` stays the ideal machine's, unchanged, and no other key changed.
Issue 29's suggestions added `roughing.flank_suggested` to the reference gear's (it roughs by levels; what roughing
by flanks with the same tool would take: the job planned with [roughing] strategy = "flank"); the helical gear gets
none (not suggested for helical gears), and nothing else changed.

Issue 48 made roughing by flanks the job files' default, and both examples leave [roughing] strategy out: the
summaries were recorded again (`spur-cad run` of each example; their earlier values of plunge_allowance_mm and
roughing_max_diameter_mm, changed on purpose above, are now simply recorded). Checked key for key against the
summaries before (tools/plunge_allowance_mm and roughing_max_diameter_mm as above): only roughing's figures
changed (moves, lengths, times, its measured axial depth and removal rate; `strategy`, `passes_per_space` and
`flank_segment_turns_deg` added, the reference gear's `flank_suggested` gone: it roughs by flanks now), the
roughing programs' lines and bytes, and the simulation's move, clipped-pose and sweep counts; the reference
gear's 2316 s of roughing are the 2316 s its flank_suggested said. The simulated deviations, the grades, the
error budget, the finishing figures and programs and the STEP files are unchanged; the helical removed volume
grew by 0.03 mm^3 (the roughing's passes in the margins), the reference gear's is the same.

Issue 45 added one key, `job_file` after `job`: every key of every section of the job as the run used it (read from
the sections' classes, spur_cad.job.Job.section_values; tests/test_registry_job_key.py checks each against the job
file and the keys' defaults). It was inserted into both recorded summaries from each example's job; no other key
changed, and the STEP files and programs are byte-identical (the hashes below).

Their STEP files and programs are byte-identical to that run's (SHA-256 below), but for the header's time
(set to a fixed value before hashing; SOURCE_DATE_EPOCH sets it, tested below) and, in job.step, the order
of the two parts' colour styles, which OCCT wrote in an order that changed from run to run when the goldens were
recorded: job.step's entities are compared with them as a set, each with its references' numbers left out, and
its styles must now come in the parts' order (gear, stock) so that two runs write the same bytes (docs/cad.md).

The STEP files are compared by their structure and their numbers, not their bytes, since a machine without AVX-512
(an AMD EPYC) wrote the helical gear.step 2 bytes longer than the Intel Xeons the goldens were recorded on: numpy's
float64 sin, cos, tan, arctan, exp and log take Intel's SVML code on AVX-512 and the C library's elsewhere, which
agree within one unit in the last place but not always in it, and one last digit printed differently. Same machine,
same bytes (test_two_runs_with_source_date_epoch_write_the_same_files); across machines, the same entities and
integers exactly and every real within STEP_REAL_ABS_TOL (step_fingerprint;
tests/data/golden/step_fingerprints.json, recorded by `python -m tests.test_summary_golden --record`), and
summary.json's cad.step_bytes within STEP_BYTES_REL_TOL."""

from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from spur_cad.cad.solid import build_stock_shape
from spur_cad.cad.step import GEAR_COLOUR, STOCK_COLOUR, step_files
from spur_cad.cad_worker import CadWorker
from spur_cad.job import load_job
from spur_cad.pipeline import run_job

pytestmark = pytest.mark.slow  # two full runs: make test-all

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"
TIMED = {("timings_s",), ("simulation", "seconds")}  # wall-clock figures of the run itself: values not compared
NUMBER_REL_TOL = 1e-9  # floating-point noise across machines (the same machine reproduces every bit)
STEP_BYTES_REL_TOL = 1e-5
"""summary.json's STEP sizes: a real whose last digit differs across machines may print one or two characters
longer (the helical gear.step: 3,343,779 bytes on an Intel Xeon, 3,343,781 on an AMD EPYC); the files themselves
are compared by step_fingerprint."""
KEY_REL_TOL = {("cad", "gear_volume_mm3"): 1e-6,
               **{("cad", "step_bytes", name): STEP_BYTES_REL_TOL for name in ("gear.step", "stock.step", "job.step")}}
"""The gear's volume is the front face's area times the face width since issue 27 (exact for the section
moved along X), where the recorded run integrated the solid: the helical solid's pipe shell approximates
its screw surfaces, and its integral was 4.5e-7 smaller (docs/cad.md)."""

CHANGED_ON_PURPOSE: dict[str, dict[tuple[str, str], object]] = {"reference_gear": {}, "helical_gear": {}}
"""Recorded values changed on purpose since the goldens were last recorded (issue 48; see the module docstring):
path -> the value now."""

ISSUE_46_BUDGET = json.loads((GOLDEN / "error_budget_issue46.json").read_text())
"""Issue 46: the error budget's table error acts at the A that cut each flank point (spur_cad.sim.contact), not as a
rigid turn of each space at its index angle: the reference gear's once-per-turn 15 arcsec makes an eccentric gear
(F_p 8.27 um where the per-space turns gave 8.70) whose error varies along each flank (f_Halpha 1.59 um, was 0.10),
so its `error_budget` grading, shares and index_source changed (recorded in error_budget_issue46.json from the run
of that commit); the helical gear keeps the per-space turn (its contacts are not a transverse section's) and only
its index_source says so. Nothing else changed."""
for _example, _changed in ISSUE_46_BUDGET.items():
    CHANGED_ON_PURPOSE[_example].update({("error_budget", key): value for key, value in _changed.items()})

STEP_FILES = ("gear.step", "stock.step", "job.step")
STEP_FINGERPRINTS = GOLDEN / "step_fingerprints.json"
STEP_REAL_ABS_TOL = 1e-7
"""How far each real checksum of a STEP file may move (step_fingerprint): a last-digit difference in a few thousand
coordinates of 50 mm moves it by about 1e-12, a point moved by 0.2 nm moves at least one of them past this."""
STEP_REAL_CHECKSUMS = 16
STEP_TOKENS = re.compile(rb"'(?:[^']|'')*'|(?<![#\w.])[-+]?\d+\.\d*(?:E[-+]?\d+)?|\s+")
"""A STEP file's strings (kept), reals (compared within STEP_REAL_ABS_TOL) and white space (dropped: OCCT breaks
its lines at 80 characters, so a real printed one digit longer can move a line break)."""

FILE_SHA256 = {
    "reference_gear": {
        "finishing.ngc": "a412b900207c83c6e9216c7c7a664fad482160b5308cab6ab3d60fdf66c260df",
        "roughing.ngc": "f3cc0cc0a2e2c61bcb8e68520f81ededd35b6eb3e88678013e46e4d06e0e33a7",
    },
    "helical_gear": {
        "finishing.ngc": "8b25588cef4d2c29ac1a8bfaeadbf5e899d7510c72619d3f0e06036ee1cbcb4e",
        "roughing.ngc": "348c4fea6ec48af374540a81fd0dd307ce7b1ef67a460131cb6cbded21eb80ed",
    },
}


def differences(expected: object, actual: object, path: tuple = ()) -> list[str]:
    """Where two JSON values differ: keys (in order), types, and values (numbers within NUMBER_REL_TOL)."""
    where = "/".join(map(str, path)) or "<top>"
    if path in TIMED:  # the run's own timings: their keys stay (new stages may add keys), their values vary
        missing = [k for k in expected if k not in actual] if isinstance(expected, dict) else []
        return [f"{where}: keys {missing} are gone"] if missing else []
    if isinstance(expected, dict) and isinstance(actual, dict):
        if list(expected) != list(actual):
            return [f"{where}: keys {list(expected)} became {list(actual)}"]
        return [d for k in expected for d in differences(expected[k], actual[k], path + (k,))]
    if isinstance(expected, list) and isinstance(actual, list):
        if len(expected) != len(actual):
            return [f"{where}: {len(expected)} items became {len(actual)}"]
        return [d for i, (e, a) in enumerate(zip(expected, actual)) for d in differences(e, a, path + (i,))]
    if type(expected) is not type(actual):
        return [f"{where}: {expected!r} became {actual!r}"]
    if isinstance(expected, float) or path in KEY_REL_TOL:
        same = math.isclose(expected, actual, rel_tol=KEY_REL_TOL.get(path, NUMBER_REL_TOL), abs_tol=1e-12)
        return [] if same else [f"{where}: {expected!r} became {actual!r}"]
    return [] if expected == actual else [f"{where}: {expected!r} became {actual!r}"]


def test_the_comparison_sees_a_changed_key_order_value_and_type():
    golden = {"a": 1.0, "b": {"c": [1, 2]}, "timings_s": {"cam": 1.0}}
    timings = {"cam": 9.0, "grading": 0.1}
    assert differences(golden, {"a": 1.0, "b": {"c": [1, 2]}, "timings_s": timings}) == []
    assert differences(golden, {"a": 1.0, "b": {"c": [1, 2]}, "timings_s": {"grading": 0.1}})  # a timing gone
    assert differences(golden, {"b": {"c": [1, 2]}, "a": 1.0, "timings_s": timings})  # order
    assert differences(golden, {"a": 1.001, "b": {"c": [1, 2]}, "timings_s": timings})  # value
    assert differences(golden, {"a": 1, "b": {"c": [1, 2]}, "timings_s": timings})  # type
    assert differences(golden, {"a": 1.0, "b": {"c": [1]}, "timings_s": timings})  # length


@pytest.mark.parametrize(("example", "cad_in_worker"), [("reference_gear", False), ("helical_gear", False),
                                                          ("reference_gear", True)])
def test_the_summary_and_the_files_of_the_examples_are_unchanged(example, cad_in_worker, monkeypatch):
    """Also with the CAD stage in a worker process, as the command line runs it (spur_cad.cad_worker)."""
    monkeypatch.chdir(ROOT)  # the summary shows the job file as given, relative to the working folder
    job = load_job(Path("resources") / "examples" / f"{example}.toml")
    files = run_job(job, cad_worker=CadWorker() if cad_in_worker else None).files
    expected = json.loads((GOLDEN / f"{example}_summary.json").read_text())
    for (section, key), value in CHANGED_ON_PURPOSE[example].items():
        assert expected[section][key] != value  # still a change against the recorded run
        expected[section][key] = value
    assert differences(expected, json.loads(files["summary.json"])) == []
    for name, digest in FILE_SHA256[example].items():
        assert hashlib.sha256(files[name]).hexdigest() == digest, name
    recorded = json.loads(STEP_FINGERPRINTS.read_text())[example]
    for name in STEP_FILES:
        assert step_differences(recorded[name], step_fingerprint(files[name], name)) == [], name
    assert _colours_in_file_order(files["job.step"]) == [GEAR_COLOUR[:3], STOCK_COLOUR[:3]]


def step_fingerprint(content: bytes, name: str) -> dict:
    """What of a STEP file must not change across machines: its structure (every entity, reference, integer and
    string, the header's clock and counters set to fixed values; job.step's entities as a sorted set, each with its
    own and its references' numbers left out, see the module docstring) as a SHA-256, the count of its reals, and
    STEP_REAL_CHECKSUMS weighted sums of its reals (in file order; job.step's sorted), each real weighted by a fixed
    pseudo-random number in [-1, 1) and summed exactly (math.fsum), so that every real counts and a last-digit
    difference moves a sum by no more than it moves the real."""
    reals: list[float] = []

    def placeholder(match: re.Match) -> bytes:
        token = match.group()
        if token.startswith(b"'"):
            return token
        if token.isspace():
            return b""
        reals.append(float(token))
        return b"R"

    structure = STEP_TOKENS.sub(placeholder, _without_clock_and_counters(content))
    if name == "job.step":
        structure, reals = _entities_without_numbers(structure), sorted(reals)
    weights = np.random.default_rng(20261205).uniform(-1.0, 1.0, (STEP_REAL_CHECKSUMS, len(reals)))
    return {"structure_sha256": hashlib.sha256(structure).hexdigest(), "reals": len(reals),
            "real_checksums": [math.fsum((row * np.asarray(reals)).tolist()) for row in weights]}


def step_differences(recorded: dict, actual: dict) -> list[str]:
    """Where a STEP file's fingerprint differs from the recorded one: structure or count exactly, the checksums
    within STEP_REAL_ABS_TOL."""
    found = [f"{key}: {recorded[key]} became {actual[key]}" for key in ("structure_sha256", "reals")
             if recorded[key] != actual[key]]
    return found or [f"real checksum {i}: {old!r} became {new!r}" for i, (old, new)
                     in enumerate(zip(recorded["real_checksums"], actual["real_checksums"], strict=True))
                     if abs(new - old) > STEP_REAL_ABS_TOL]


def test_the_step_comparison_sees_a_moved_point_an_entity_or_a_name_but_not_a_last_digit():
    """Planted as machines and regressions make them, on the reference gear's stock.step as written by the CAD
    stage: the last digit of every coordinate (what another CPU's sin and cos do) and a line broken elsewhere are no
    difference; one point moved by
    1 nm, a renamed product or a changed entity is."""
    content = _reference_stock_step()
    recorded = step_fingerprint(content, "stock.step")
    assert recorded["reals"] > 100

    def last_digit_up(match: re.Match) -> bytes:
        value = float(match.group())
        return f"{math.nextafter(value, math.inf):.16E}".encode() if value else match.group()

    data_at = content.index(b"DATA;")
    noisy = content[:data_at] + re.sub(rb"(?<=[(,])-?\d+\.\d+(?:E[-+]?\d+)?(?=[,)])", last_digit_up,
                                       content[data_at:])
    assert noisy != content
    assert step_differences(recorded, step_fingerprint(noisy, "stock.step")) == []
    rewrapped = content[:data_at] + content[data_at:].replace(b"));", b")\n  );", 1)
    assert rewrapped != content
    assert step_differences(recorded, step_fingerprint(rewrapped, "stock.step")) == []
    point = re.search(rb"CARTESIAN_POINT\('',\((-?[1-9]\d*\.\d*(?:E[-+]?\d+)?),", content[data_at:])
    assert point is not None
    moved_value = f"{float(point.group(1)) + 1e-6:.16E}".encode()
    moved = content[:data_at] + content[data_at:].replace(point.group(0),
                                                        point.group(0).replace(point.group(1), moved_value), 1)
    assert step_differences(recorded, step_fingerprint(moved, "stock.step"))
    renamed = content.replace(b"PRODUCT('stock'", b"PRODUCT('stack'", 1)
    assert renamed != content and step_differences(recorded, step_fingerprint(renamed, "stock.step"))
    dropped = content.replace(b"CARTESIAN_POINT", b"CARTESIAN_POINTS", 1)
    assert step_differences(recorded, step_fingerprint(dropped, "stock.step"))


def _reference_stock_step() -> bytes:
    """The reference gear's stock.step as the run writes it (the CAD stage's writer, no other stage)."""
    job = load_job(ROOT / "resources" / "examples" / "reference_gear.toml")
    stock = build_stock_shape(job.gear, job.stock)
    return step_files(stock, stock, timestamp="2026-01-01T00:00:00")["stock.step"]


def _colours_in_file_order(content: bytes) -> list[tuple[float, ...]]:
    """The COLOUR_RGB values of a STEP file in the order it writes them (to 6 decimals)."""
    return [tuple(round(float(value), 6) for value in match.groups()) for match in
            re.finditer(rb"COLOUR_RGB\('[^']*',([0-9.eE+-]+),([0-9.eE+-]+),([0-9.eE+-]+)\)", content)]


def _without_clock_and_counters(content: bytes) -> bytes:
    """A STEP file with the writer's time stamp and process-wide counters set to fixed values (other files
    unchanged: they have none)."""
    content = re.sub(rb"(FILE_NAME\('[^']*',')[0-9T:-]+'", rb"\1T'", content, count=1)
    content = re.sub(rb"(Open CASCADE STEP translator [0-9.]+) \d+'", rb"\1 N'", content)
    return re.sub(rb"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('\d+'", rb"NEXT_ASSEMBLY_USAGE_OCCURRENCE('N'", content)


def _entities_without_numbers(content: bytes) -> bytes:
    """A STEP file's DATA entities, sorted, each with its own and its references' numbers replaced by '#'."""
    data = content.decode().split("DATA;", 1)[1]
    entities = (re.sub(r"#\d+", "#", " ".join(text.split())) for text in data.split(";") if text.strip())
    return "\n".join(sorted(entities)).encode()


def test_two_runs_with_source_date_epoch_write_the_same_files(monkeypatch):
    """SOURCE_DATE_EPOCH (the reproducible-builds convention) sets the STEP headers' time: two runs of one job
    give identical files, but for the wall-clock timings in summary.json and report.html."""
    monkeypatch.chdir(ROOT)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    job = load_job(Path("resources") / "examples" / "reference_gear.toml")
    first, second = run_job(job).files, run_job(job).files
    assert sorted(first) == sorted(second)
    assert b"'2023-11-14T22:13:20'" in first["gear.step"] and b"PRODUCT('gear','gear'" in first["gear.step"]
    for name in first:
        if name in ("summary.json", "report.html"):
            assert len(first[name]) > 0
        else:
            assert first[name] == second[name], name
    timed = json.loads(first["summary.json"]), json.loads(second["summary.json"])
    assert differences(*timed) == []


def record_step_fingerprints() -> None:
    """Write tests/data/golden/step_fingerprints.json from a run of each example: only when the STEP files change
    on purpose, said in the commit (`python -m tests.test_summary_golden --record`)."""
    recorded = {}
    for example in ("reference_gear", "helical_gear"):
        files = run_job(load_job(ROOT / "resources" / "examples" / f"{example}.toml")).files
        recorded[example] = {name: step_fingerprint(files[name], name) for name in STEP_FILES}
    STEP_FINGERPRINTS.write_text(json.dumps(recorded, indent=1) + "\n")


if __name__ == "__main__":
    import sys

    if sys.argv[1:] != ["--record"]:
        sys.exit("usage: python -m tests.test_summary_golden --record")
    record_step_fingerprints()
