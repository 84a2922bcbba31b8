"""A user's own gear from the command line (issue 28, point 11): the reference job changed to 31 teeth, module
2.5, profile shift 0.2, face 15 mm. With the reference job's tools, one error lists every tool conflict and a
set of tools that fits (and that set runs); with "auto" tool sizes the job runs first time; warnings reach the
terminal; "auto" elsewhere is one clear line."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

from tests.test_cli import REFERENCE_JOB, run_cli

SUGGESTION = re.compile(r"tools that fit: roughing flat D (?P<rough>[\d.]+) mm, finishing (?P<kind>bull_nose|ball) "
                        r"D (?P<fin>[\d.]+) mm r (?P<corner>[\d.]+) mm")


def own_gear_text(**tool_values: str) -> str:
    """The reference job with the gear of issue 28's point 11; `tool_values` replace tool lines, e.g.
    roughing_diameter_mm='"auto"'."""
    text = REFERENCE_JOB.read_text()
    for key, value in (("teeth", "31"), ("module_mm", "2.5"), ("profile_shift_coefficient", "0.2"),
                       ("face_width_mm", "15.0")):
        text, count = re.subn(rf"(?m)^{key} = .*$", f"{key} = {value}", text)
        assert count == 1, key
    for name, value in tool_values.items():
        role, key = name.split("_", 1)
        section = text.index(f"[tools.{role}]")
        end = text.index("\n[", section + 1)
        body, count = re.subn(rf"(?m)^{key} = .*$", f"{key} = {value}", text[section:end])
        assert count == 1, name
        text = text[:section] + body + text[end:]
    return text


def _write(tmp_path: Path, text: str) -> Path:
    job = tmp_path / "own_gear.toml"
    job.write_text(text)
    return job


def _job_without_simulation(folder: Path, text: str) -> tuple[Path, Path]:
    """The job text written to folder/job.toml with [simulation] enabled = false (these tests check tools)."""
    folder.mkdir()
    job = folder / "job.toml"
    job.write_text(text.replace("[simulation]", "[simulation]\nenabled = false") if "[simulation]" in text
                   else text + "\n[simulation]\nenabled = false\n")
    return folder, job


def test_every_tool_conflict_in_one_line_with_a_set_that_fits(tmp_path):
    job = _write(tmp_path, own_gear_text())
    out = tmp_path / "out"
    result = run_cli("run", str(job), "--out", str(out))
    assert result.returncode == 2 and not out.exists()
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    line = lines[0]
    assert "2 tool conflicts; tools that fit: " in line
    assert re.search(r"1\) finishing .*flat width d = 1 mm .*wider than the rack's tip flat", line), line
    assert re.search(r"2\) roughing tool diameter 3\.5000 mm exceeds", line), line
    # The line names the first conflicting key's line: [tools.finishing] diameter_mm.
    finishing = job.read_text().index("[tools.finishing]")
    line_number = job.read_text()[:job.read_text().index("diameter_mm", finishing)].count("\n") + 1
    assert line.startswith(f"spur-cad: error: {job}:{line_number}:")
    match = SUGGESTION.search(line)
    assert match, line
    assert float(match["corner"]) == 0.8  # by generation the tool's corner is the rack's tip radius rho


@pytest.mark.slow  # two whole runs (5 s); the suggestion itself is checked above in the fast tier
def test_the_suggested_set_runs_and_equals_what_auto_takes(tmp_path):
    """The set the error proposes, typed into the job, runs; `auto` takes the same sizes; its tools obey the
    limits the run reports (the roughing tool within its largest diameter, the finishing corner rho)."""
    refused = run_cli("run", str(_write(tmp_path, own_gear_text())), "--out", str(tmp_path / "x"))
    match = SUGGESTION.search(refused.stderr)
    assert match, refused.stderr
    typed = own_gear_text(roughing_diameter_mm=match["rough"], finishing_kind=f'"{match["kind"]}"',
                          finishing_diameter_mm=match["fin"], finishing_corner_radius_mm=match["corner"])
    auto = own_gear_text(roughing_diameter_mm='"auto"', finishing_diameter_mm='"auto"',
                         finishing_corner_radius_mm='"auto"')
    summaries = {}
    for name, text in (("typed", typed), ("auto", auto)):
        folder, job = _job_without_simulation(tmp_path / name, text)
        result = run_cli("run", str(job), "--out", str(folder / "out"), "--quiet")
        assert result.returncode == 0, result.stderr
        summaries[name] = json.loads((folder / "out" / "summary.json").read_text())
    typed_tools, auto_tools = summaries["typed"]["tools"], summaries["auto"]["tools"]
    for role in ("roughing", "finishing"):
        assert auto_tools[role] == typed_tools[role]
    assert auto_tools["roughing"]["diameter_mm"] <= auto_tools["roughing_max_diameter_mm"]
    # The next 0.1 mm size up would not fit: the suggestion is the largest, not merely one that fits. Since
    # finishing by generation lets roughing leave 0.5 D above the root (not the plunge allowance), the roughing
    # limit (2.76 mm) is above what passes beside the reference job's holding stub (stub radius 40 mm above this
    # gear's root: the tool's far edge, D + clearance 1 mm behind the back face, within back_margin_mm = 2 mm):
    # that bounds the suggestion here.
    stub_limit = 2.0 - 1.0
    assert auto_tools["roughing"]["diameter_mm"] <= stub_limit
    assert auto_tools["roughing"]["diameter_mm"] + 0.1 > min(auto_tools["roughing_max_diameter_mm"], stub_limit)
    assert auto_tools["finishing"]["corner_radius_mm"] == 0.8
    assert math.isclose(auto_tools["finishing"]["diameter_mm"] % 0.05, 0.0, abs_tol=1e-9) or \
        math.isclose(auto_tools["finishing"]["diameter_mm"] % 0.05, 0.05, abs_tol=1e-9)


@pytest.mark.parametrize("section, key", [("gear", "module_mm"), ("tools.roughing", "flutes"),
                                          ("stock", "radial_allowance_mm")])
def test_auto_where_no_suggestion_exists_is_one_line_naming_the_key(tmp_path, section, key):
    text = REFERENCE_JOB.read_text()
    start = text.index(f"[{section}]")
    end = text.find("\n[", start + 1)
    end = len(text) if end < 0 else end
    body = text[start:end]
    body = (re.sub(rf"(?m)^{key} = .*$", f'{key} = "auto"', body) if re.search(rf"(?m)^{key} = ", body)
            else body.rstrip("\n") + f'\n{key} = "auto"\n')
    job = _write(tmp_path, text[:start] + body + text[end:])
    result = run_cli("run", str(job), "--out", str(tmp_path / "out"))
    assert result.returncode == 2 and not (tmp_path / "out").exists()
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1
    line_number = (text[:start] + body).split(f'{key} = "auto"')[0].count("\n") + 1
    assert lines[0].startswith(f"spur-cad: error: {job}:{line_number}: [{section}] {key} = \"auto\"")


@pytest.mark.slow  # two whole CLI runs (12 s)
def test_warnings_reach_the_terminal_and_no_flat_end_mill_warning_for_a_bull_nose(tmp_path):
    """The own gear's largest flat finishing end mill (0.75 mm) is below the smallest end mill: a warning only
    when the job finishes with a flat end mill; the warnings on the terminal are summary.json's."""
    common = dict(roughing_diameter_mm='"auto"')
    bull = own_gear_text(**common, finishing_diameter_mm='"auto"', finishing_corner_radius_mm='"auto"')
    flat = own_gear_text(**common, finishing_kind='"flat"', finishing_diameter_mm="0.7",
                         finishing_corner_radius_mm="0.0")
    flat = re.sub(r"(?m)^radial_allowance_mm = .*$", "radial_allowance_mm = 0.3", flat)  # a 0.7 mm tool's land pass
    for name, text in (("bull", bull), ("flat", flat)):
        folder, job = _job_without_simulation(tmp_path / name, text)
        result = run_cli("run", str(job), "--out", str(folder / "out"))
        assert result.returncode == 0, result.stderr
        warnings = json.loads((folder / "out" / "summary.json").read_text())["warnings"]
        printed = [line.removeprefix("spur-cad: warning: ") for line in result.stderr.splitlines()
                   if line.startswith("spur-cad: warning: ")]
        assert printed == warnings
        flat_warning = [w for w in warnings if "flat end mill for finishing by generation" in w]
        assert bool(flat_warning) == (name == "flat"), warnings


def test_auto_sizes_bound_the_roughing_work_before_choosing(tmp_path):
    """The suggestion tries roughing tools against the job's levels: with levels of runaway depth the work bound
    answers first (one line naming the key), as without "auto", instead of computing millions of levels."""
    text = own_gear_text(roughing_diameter_mm='"auto"', finishing_diameter_mm='"auto"',
                         finishing_corner_radius_mm='"auto"')
    text, count = re.subn(r"(?m)^max_level_depth_fraction = .*$", "max_level_depth_fraction = 0.000001", text)
    assert count == 1
    job = _write(tmp_path, text)
    result = run_cli("run", str(job), "--out", str(tmp_path / "out"))
    assert result.returncode == 2
    line_number = text[:text.index("max_level_depth_fraction = 0.000001")].count("\n") + 1
    assert result.stderr.startswith(f"spur-cad: error: {job}:{line_number}: roughing would need about")
    assert result.stderr.strip().endswith("raise [roughing] max_level_depth_fraction")
