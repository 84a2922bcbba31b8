"""What a run does when a package spur_cad can live without is missing: one line saying what to install, exit 2,
nothing written (OCP, which comes from an extra; Jinja2, which FreeCAD's Addon Manager cannot install), or plain
progress lines (tqdm, optional).

Each case runs the real command line in a fresh Python in which the package cannot be imported: its entry in
sys.modules is None, which is how Python itself marks a module as absent (`import` then raises ImportError and
importlib's find_spec refuses it), so nothing else of the environment changes. The real absence (a venv without
the package) is what FreeCAD's Addon Manager makes; tests/test_addon_manager.py runs that route."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "resources" / "examples" / "reference_gear.toml"


def run_without(absent: list[str], *argv: str, cwd: Path) -> subprocess.CompletedProcess:
    code = ("import sys\n"
            f"for name in {absent!r}:\n"
            "    sys.modules[name] = None\n"
            "from spur_cad.cli import main\n"
            f"sys.exit(main({list(argv)!r}))\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600, cwd=cwd,
                          check=False)


@pytest.mark.parametrize("absent, names", [
    (["jinja2"], ["Jinja2", "pip install jinja2"]),
    (["OCP"], ["OCP", "spur_cad[cadquery]", "spur_cad[build123d]", "spur_cad[ocp]"]),
])
def test_a_run_without_a_needed_package_says_what_to_install_in_one_line_and_writes_nothing(tmp_path, absent, names):
    out = tmp_path / "out"
    done = run_without(absent, "run", str(REFERENCE), "--out", str(out), cwd=tmp_path)
    assert done.returncode == 2, done.stderr[-3000:]
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("spur-cad: error: ") and "Traceback" not in done.stderr
    for name in names:
        assert name in lines[0]
    assert not out.exists()


def test_a_job_naming_a_report_template_without_jinja2_is_refused_before_any_work(tmp_path):
    (tmp_path / "shop.html.j2").write_text("<p>{{ gear.teeth }}</p>\n", encoding="utf-8")
    text = REFERENCE.read_text(encoding="utf-8")
    assert "[job]" in text
    job = tmp_path / "job.toml"
    job.write_text(text.replace("[job]\n", "[job]\nreport_template = \"shop.html.j2\"\n", 1), encoding="utf-8")
    done = run_without(["jinja2"], "run", str(job), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 2 and "Jinja2" in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_progress_without_tqdm_is_one_plain_line_per_stage():
    code = ("import io, sys\n"
            "sys.modules['tqdm'] = None\n"
            "from spur_cad.cli import ProgressBars\n"
            "stream = io.StringIO()\n"
            "bars = ProgressBars(stream)\n"
            "for stage in ('toolpaths', 'simulation'):\n"
            "    for fraction in (0.0, 0.5, 1.0, 1.0):\n"
            "        bars(stage, fraction)\n"
            "bars.close()\n"
            "print(stream.getvalue(), end='')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["    toolpaths: done", "   simulation: done"]
