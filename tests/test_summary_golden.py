"""summary.json keeps its keys and values: the reference and helical examples' summaries equal the ones
recorded before the typed result (tests/data/golden/, made by `spur-cad run` of commit 8accc5c), key for key
and in the same order; only the run's own timings may differ. Their STEP files and programs are
byte-identical to that run's (SHA-256 below; a STEP header's FILE_NAME carries the time it was written,
which is set to the recorded run's before hashing)."""

from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path

import pytest

from spur_cad.job import load_job
from spur_cad.pipeline import run_job

pytestmark = pytest.mark.slow  # two full runs: make test-all

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"
TIMED = {("timings_s",), ("simulation", "seconds")}  # wall-clock figures of the run itself
NUMBER_REL_TOL = 1e-9  # floating-point noise across machines (the same machine reproduces every bit)

FILE_SHA256 = {
    "reference_gear": {
        "gear.step": "dfc0dfaa8f57265c93cda9f2aee86bf29323da3f1de3d9138ffda5e7d8df6e8d",
        "job.step": "a5b6db9c336ae85837c048c9cd403e7fe87353f2b8086d388ae13bd9667d1f96",
        "stock.step": "ac962b9c1573da5b5602e9b79453b463c7d0d6fca35e4685b3a4c7741f8a3ce6",
        "finishing.ngc": "a412b900207c83c6e9216c7c7a664fad482160b5308cab6ab3d60fdf66c260df",
        "roughing.ngc": "79d62a50184a1a1549274e6aeedd197fc4fdc22ecfb598cef592c47784e62bf0",
    },
    "helical_gear": {
        "gear.step": "033e58b75231791bb17736bc34d835965f29ce778d3c9abe464b4dcc26f3ca40",
        "job.step": "07aedd8addf34c4686a3206bc32194ea9c50acefa193449fa1bb0d4833c7e332",
        "stock.step": "b769ebe88873e2d51c1bc9bde94bf233cb502fe35f7696cdd92299395a5fc746",
        "finishing.ngc": "8b25588cef4d2c29ac1a8bfaeadbf5e899d7510c72619d3f0e06036ee1cbcb4e",
        "roughing.ngc": "fb327f77c54e481ea34e95c05220de66074d188506956f5893a00fa85219e889",
    },
}


def differences(expected: object, actual: object, path: tuple = ()) -> list[str]:
    """Where two JSON values differ: keys (in order), types, and values (numbers within NUMBER_REL_TOL)."""
    if path in TIMED:
        return []
    where = "/".join(map(str, path)) or "<top>"
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
    if isinstance(expected, float):
        same = math.isclose(expected, actual, rel_tol=NUMBER_REL_TOL, abs_tol=1e-12)
        return [] if same else [f"{where}: {expected!r} became {actual!r}"]
    return [] if expected == actual else [f"{where}: {expected!r} became {actual!r}"]


def test_the_comparison_sees_a_changed_key_order_value_and_type():
    golden = {"a": 1.0, "b": {"c": [1, 2]}, "timings_s": {"cam": 1.0}}
    assert differences(golden, {"a": 1.0, "b": {"c": [1, 2]}, "timings_s": {"cam": 9.0}}) == []
    assert differences(golden, {"b": {"c": [1, 2]}, "a": 1.0, "timings_s": {}})  # order
    assert differences(golden, {"a": 1.001, "b": {"c": [1, 2]}, "timings_s": {}})  # value
    assert differences(golden, {"a": 1, "b": {"c": [1, 2]}, "timings_s": {}})  # type
    assert differences(golden, {"a": 1.0, "b": {"c": [1]}, "timings_s": {}})  # length


@pytest.mark.parametrize("example", ["reference_gear", "helical_gear"])
def test_the_summary_and_the_files_of_the_examples_are_unchanged(example, monkeypatch):
    monkeypatch.chdir(ROOT)  # the summary shows the job file as given, relative to the working folder
    job = load_job(Path("resources") / "examples" / f"{example}.toml")
    files = run_job(job).files
    expected = json.loads((GOLDEN / f"{example}_summary.json").read_text())
    assert differences(expected, json.loads(files["summary.json"])) == []
    for name, digest in FILE_SHA256[example].items():
        assert hashlib.sha256(_recorded_time(example, files[name])).hexdigest() == digest, name


RECORDED_TIME = {"reference_gear": b"2026-11-25T16:21:38", "helical_gear": b"2026-11-25T16:21:49"}


def _recorded_time(example: str, content: bytes) -> bytes:
    """A STEP file with its header's time stamp set to the recorded run's (other files unchanged)."""
    return re.sub(rb"(FILE_NAME\('[^']*',')[0-9T:-]+'", lambda m: m.group(1) + RECORDED_TIME[example] + b"'",
                  content, count=1)
