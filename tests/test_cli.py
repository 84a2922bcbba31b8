"""The command line end to end: outputs, their content, and bad input leaving nothing behind."""

from __future__ import annotations

import csv
import gc
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from spur_cad.cli import main

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_JOB = ROOT / "resources" / "examples" / "reference_gear.toml"


def run_cli(*args: str) -> subprocess.CompletedProcess:
    """Run the installed console script as a user would."""
    exe = Path(sys.executable).with_name("spur-cad")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "spur_cad.cli"]
    return subprocess.run(command + list(args), capture_output=True, text=True, cwd=ROOT, timeout=300,
                          check=False)


@pytest.mark.slow
def test_reference_job_writes_profile_summary_and_plot(tmp_path):
    out = tmp_path / "out"
    result = run_cli("run", str(REFERENCE_JOB), "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert {p.name for p in out.iterdir()} >= {"profile.csv", "profile.png", "summary.json", "gear.step",
                                               "stock.step", "job.step", "roughing.ngc", "finishing.ngc"}
    summary = json.loads((out / "summary.json").read_text())
    gear, inspection = summary["gear"], summary["inspection"]
    assert gear["reference_radius_mm"] == pytest.approx(46.0)
    assert gear["base_radius_mm"] == pytest.approx(46.0 * math.cos(math.radians(20)))
    assert gear["tip_radius_mm"] == pytest.approx(50.0)
    assert gear["root_radius_mm"] == pytest.approx(41.0)
    assert gear["base_radius_mm"] < gear["form_radius_mm"] < gear["reference_radius_mm"]
    assert gear["undercut"] is False
    # Root arc half angle from docs/method.md: v = d_1 / r, d_1 = e/2 - B tan(a) - rho / cos(a).
    a = math.radians(20)
    e = 4 * math.pi - 0.95 * 2 * math.pi
    d1 = e / 2 - (46 - 41 - 0.8) * math.tan(a) - 0.8 / math.cos(a)
    assert gear["root_arc_half_angle_deg"] == pytest.approx(math.degrees(d1 / 46), abs=1e-9)
    assert inspection["span_teeth_k"] == 3
    # Textbook W_k = (k - 1) p_b + s_b with s_b = r_b (s / r + 2 inv a), s thinned by the 5 % allowance.
    rb, s = 46.0 * math.cos(a), 0.95 * 2 * math.pi
    invo = math.tan(a) - a
    assert inspection["span_measurement_mm"] == pytest.approx(2 * math.pi * 4 * math.cos(a) + rb * (s / 46 + 2 * invo))
    # Over pins (odd z): inv(a_M) = D / d_b + s / (m z) + inv(a) - pi / z, M = d_b / cos(a_M) cos(pi / 2z) + D.
    pin = inspection["pin_diameter_mm"]
    assert 1.2 * 4 <= pin <= 2.2 * 4
    target = pin / (2 * rb) + s / (4 * 23) + invo - math.pi / 23
    a_m = brentq(lambda x: math.tan(x) - x - target, 1e-6, 1.5)
    assert inspection["dimension_over_pins_mm"] == pytest.approx(2 * rb / math.cos(a_m) * math.cos(math.pi / 46)
                                                                 + pin)
    with open(out / "profile.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["x_mm", "y_mm"]
    pts = np.array(rows[1:], dtype=float)
    assert pts[0] == pytest.approx([0.0, 41.0])
    assert np.hypot(*pts[-1]) == pytest.approx(50.0)
    # root to tip: radius never falls (csv has 1e-9 mm digits)
    assert np.all(np.diff(np.hypot(pts[:, 0], pts[:, 1])) >= -1e-8)
    assert (out / "profile.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    tools, roughing, finishing = summary["tools"], summary["roughing"], summary["finishing"]
    assert tools["finishing_max_corner_radius_mm"] >= 0.8 - 1e-9  # the fillet is never tighter than the rack's round
    assert tools["required_flute_length_mm"] == pytest.approx(50.0 + 0.5 - 41.0)  # blank radius - root radius
    assert 3.5 <= tools["roughing_max_diameter_mm"] < 2 * (math.pi * 4 / 2)  # the chosen 3.5 mm fits; under a pitch
    assert tools["finishing_max_flat_width_mm"] == pytest.approx(2 * d1 / 46 * 41, abs=1e-9)
    assert roughing["levels_per_space"] >= 2 and 0 < roughing["lowest_level_height_mm"] <= 0.5 * 1.0
    # Every level cuts at least once across the face width plus the tool at both ends, in every space.
    assert roughing["cutting_length_mm"] >= 23 * roughing["levels_per_space"] * (20.0 + 3.5)
    # Finishing by generation (the reference job's choice): every pass runs the face width plus the tool
    # radius and the clearance at both ends, in every space.
    assert finishing["strategy"] == "generating"
    assert finishing["cutting_length_mm"] >= 23 * finishing["passes_per_space"] * (20.0 + 2 * (1.0 + 1.0))
    assert finishing["passes_per_space"] == (2 * finishing["flank_passes_per_flank"]
                                             + finishing["tip_mode_passes_per_space"]
                                             + finishing["land_passes_per_space"])
    assert 0.0 < finishing["flat_height_mm"] <= 0.005
    for section in (roughing, finishing):  # no faster than the cutting length at the machine's largest feed
        assert section["estimated_time_s"] >= section["cutting_length_mm"] / 5000.0 * 60.0
        assert section["estimated_time_with_acceleration_s"] >= section["estimated_time_s"] * 0.999
    assert finishing["reference_strategy_moves"] > 50 * finishing["moves"]
    assert finishing["perimeter_time_s"] > 4 * finishing["estimated_time_s"]
    assert 0.9 < finishing["reference_strategy_time_s"] / finishing["perimeter_time_s"] < 1.1
    post = summary["post"]
    assert post["dialect"] == "linuxcnc"
    for name in ("roughing", "finishing"):
        text = (out / f"{name}.ngc").read_text()
        assert post[f"{name}_lines"] == text.count("\n") and text.rstrip().endswith("M30")
    assert post["finishing_bytes"] == (out / "finishing.ngc").stat().st_size
    assert "wrote" in result.stdout


@pytest.mark.slow
def test_quiet_prints_nothing(tmp_path):
    result = run_cli("run", str(REFERENCE_JOB), "--out", str(tmp_path / "o"), "--quiet")
    assert result.returncode == 0 and result.stdout == "" and result.stderr == ""


BAD_JOBS = {
    "unknown key": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\ncolour = 'red'\n",
                    "bad.toml:5: unknown key 'colour' in [gear]"),
    "misspelt key": ("[gear]\nteeth = 23\nmodule = 4.0\nface_width_mm = 20\n",
                     "bad.toml:3: unknown key 'module' in [gear] (did you mean module_mm"),
    "wrong type": ("[gear]\nteeth = 23\nmodule_mm = 'four'\nface_width_mm = 20\n",
                   "bad.toml:3: [gear] module_mm must be a number"),
    "invalid gear": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 2.3\n",
                     "bad.toml:5: invalid gear: rack tip radius 2.3 mm is too large"),
    "bad toml": ("[gear\nteeth = 23\n", "not valid TOML"),
    "unknown section": ("[gears]\nteeth = 23\n", "unknown section [gears]"),
    "too few teeth": ("[gear]\nteeth = 3\nmodule_mm = 4.0\nface_width_mm = 20\n",
                      "bad.toml:2: [gear] teeth must be in 5..1000, got 3"),
    "bore through the root": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nbore_diameter_mm = 80\n",
                              "bad.toml:5: invalid [gear]: bore diameter 80 mm leaves less than one module"),
    "finishing tool too wide": (("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 0.8\n"
                                 "[tools.finishing]\nkind = 'bull_nose'\ndiameter_mm = 3.0\ncorner_radius_mm = 0.5\n"),
                                "bad.toml:8: finishing strategy generating: tool flat width d = 2 mm (D - 2 r_t) is "
                                "wider than the rack's tip flat 2 d_1 = 1.5232 mm"),
    "finishing tool too wide for perimeter": (
        ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 0.8\n"
         "[tools.finishing]\nkind = 'bull_nose'\ndiameter_mm = 3.0\ncorner_radius_mm = 0.5\n"
         "[finishing]\nstrategy = 'perimeter'\n"),
        "bad.toml:8: finishing tool flat width 2.0000 mm (D - 2 r_t) exceeds finishing_max_flat_width_mm"),
    "finishing corner above the rack tip radius": (
        ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\nrack_tip_radius_mm = 0.5\n"
         "[tools.finishing]\nkind = 'bull_nose'\ndiameter_mm = 2.0\ncorner_radius_mm = 0.6\n"),
        "bad.toml:9: finishing strategy generating: tool corner radius r_t = 0.6 mm is larger than the rack tip "
        "radius rho = 0.5 mm"),
    "unknown strategy": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n[finishing]\nstrategy = 'spiral'\n",
                         "bad.toml:6: [finishing] strategy 'spiral' is unknown"),
    "unknown post dialect": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n"
                             "[post]\ndialect = 'heidenhain'\n",
                             ("bad.toml:6: [post] dialect = 'heidenhain' is not known (known: linuxcnc, fanuc, "
                              "haas, siemens, okuma)")),
    "folded wrapped program": (("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n[post]\n"
                                "rotary_mode = 'wrapped'\n"), "bad.toml:6: [post] folded = true needs rotary_mode"),
    "stub without length": ("[gear]\nteeth = 23\nmodule_mm = 4.0\nface_width_mm = 20\n[stock]\nstub_diameter_mm = 60\n",
                            "bad.toml:6: invalid [stock]: a holding stub needs both"),
}


@pytest.mark.parametrize("case", list(BAD_JOBS))
def test_bad_job_gives_one_clear_line_and_writes_nothing(tmp_path, case):
    text, expected = BAD_JOBS[case]
    job = tmp_path / "bad.toml"
    job.write_text(text)
    out = tmp_path / "out"
    result = run_cli("run", str(job), "--out", str(out))
    assert result.returncode == 2
    assert result.stderr.startswith("spur-cad: error: ")
    assert expected in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("enabled", [True, False])
def test_a_run_gives_the_cycle_collector_back_as_it_found_it(tmp_path, enabled):
    """The CLI pauses Python's cyclic garbage collector for a run (docs/benchmarks.md); called in-process, as
    scripts may, it leaves the collector as it was, also when the run stops at bad input."""
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD_JOBS["unknown key"][0])
    was = gc.isenabled()
    try:
        gc.enable() if enabled else gc.disable()
        assert main(["run", str(bad), "--out", str(tmp_path / "o")]) == 2
        assert gc.isenabled() is enabled
    finally:
        gc.enable() if was else gc.disable()


@pytest.mark.parametrize("epoch", ["yesterday", "-5", "1e9", "99999999999999"])
def test_a_bad_source_date_epoch_gives_one_line_and_writes_nothing(tmp_path, epoch):
    out = tmp_path / "out"
    exe = Path(sys.executable).with_name("spur-cad")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "spur_cad.cli"]
    result = subprocess.run(command + ["run", str(REFERENCE_JOB), "--out", str(out)], capture_output=True,
                            text=True, cwd=ROOT, timeout=300, check=False,
                            env={**os.environ, "SOURCE_DATE_EPOCH": epoch})
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines() == [
        f"spur-cad: error: SOURCE_DATE_EPOCH must be a whole number of seconds since 1970, got '{epoch}'"]
    assert not out.exists()


def test_missing_job_file(tmp_path):
    result = run_cli("run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o"))
    assert result.returncode == 2 and "job file not found" in result.stderr


@pytest.mark.slow
def test_out_path_that_is_a_file_is_an_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["run", str(REFERENCE_JOB), "--out", str(blocker), "--quiet"]) == 2
    assert blocker.read_text() == "x"


@pytest.mark.slow
def test_existing_outputs_are_replaced_whole(tmp_path):
    """A LinuxCNC set replaced by a Fanuc set of another gear: the folder then holds exactly the new set
    (no .ngc left), the new summary, and no temporaries."""
    text = REFERENCE_JOB.read_text().replace("face_width_mm = 20.0", "face_width_mm = 3.0") + \
        "\n[simulation]\nenabled = false\n"
    first, second = tmp_path / "first.toml", tmp_path / "second.toml"
    first.write_text(text)
    second.write_text(text.replace("teeth = 23", "teeth = 25").replace('dialect = "linuxcnc"', 'dialect = "fanuc"'))
    out = tmp_path / "o"
    assert main(["run", str(first), "--out", str(out), "--quiet"]) == 0
    assert {"roughing.ngc", "finishing.ngc"} <= set(os.listdir(out))
    assert main(["run", str(second), "--out", str(out), "--quiet"]) == 0
    names = sorted(p for p in os.listdir(out) if not p.startswith("."))
    assert names == sorted(["profile.csv", "profile.png", "gear.step", "stock.step", "job.step", "roughing.nc",
                            "finishing.nc", "report.html", "summary.json"])
    assert json.loads((out / "summary.json").read_text())["gear"]["teeth"] == 25
    assert sorted(p for p in os.listdir(out) if p.startswith(".")) == [".spur_cad-set.json"]  # no temporaries


def run_cli_on_a_terminal(*args: str) -> tuple[int, str, str]:
    """Run the console script with stderr on a pseudo-terminal (as in an interactive shell)."""
    import pty

    exe = Path(sys.executable).with_name("spur-cad")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "spur_cad.cli"]
    master, slave = pty.openpty()
    proc = subprocess.Popen(command + list(args), stdout=subprocess.PIPE, stderr=slave, cwd=ROOT)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # EIO: the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    stdout = proc.stdout.read().decode()
    proc.stdout.close()
    return proc.wait(timeout=300), stdout, b"".join(chunks).decode(errors="replace")


@pytest.mark.slow
def test_progress_bars_on_the_terminal_and_nothing_with_quiet(tmp_path):
    job = tmp_path / "coarse.toml"
    job.write_text(REFERENCE_JOB.read_text() + "\n[simulation]\nresolution_mm = 0.02\n")
    out = tmp_path / "o"
    code, stdout, terminal = run_cli_on_a_terminal("run", str(job), "--out", str(out))
    assert code == 0, terminal
    for stage in ("CAD and STEP", "toolpaths", "simulation", "report"):
        assert re.search(rf"{stage}: +100%", terminal), stage
    assert "wrote" in stdout and "%" not in stdout
    assert (out / "report.html").read_bytes().startswith(b"<!DOCTYPE html>")
    assert json.loads((out / "summary.json").read_text())["simulation"]["resolution_mm"] == 0.02
    code, stdout, terminal = run_cli_on_a_terminal("run", str(job), "--out", str(out), "--quiet")
    assert code == 0 and stdout == "" and terminal == ""
