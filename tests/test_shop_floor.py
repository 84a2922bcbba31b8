"""The shop-floor limits and settings of issue 18: the machine's physical limits ([machine]), the blank's size
against the tip circle and the finishing tool, the work offset every program selects ([post] work_offset).

References: the blank's weight and overhang from the CadQuery stock solid (OCP's volume and bounding box), the
tip circle from the gear's own definition (z m / 2 + (1 + x) m), LinuxCNC's rs274 for the work offset, the
programs' own text for the other dialects."""

from __future__ import annotations

import dataclasses
import re

import pytest

from spur_cad.cad.solid import solid_volume_mm3, stock_shape
from spur_cad.cli import main
from spur_cad.errors import JobFileError, SpurCadError
from spur_cad.job import load_job, parse_job
from spur_cad.pipeline import build_programs, plan_cam
from tests.ocp_helper import exact_bounds
from tests.rs274_helper import run_rs274
from tests.tiers import sweep
from tests.workbench_helper import small_job_text

REFERENCE = "resources/examples/reference_gear.toml"


def _with(text: str, section: str, lines: str) -> str:
    """The job text with `lines` added at the top of `section` (created at the end when missing)."""
    header = f"[{section}]\n"
    return text.replace(header, header + lines + "\n", 1) if header in text else text + f"\n{header}{lines}\n"


@pytest.fixture(scope="module")
def reference_text():
    with open(REFERENCE) as handle:
        return handle.read()


def test_the_blank_weight_and_overhang_are_those_of_the_stock_solid(reference_text):
    job = load_job(REFERENCE)
    stock = stock_shape(job.gear, job.stock)
    volume_dm3 = solid_volume_mm3(stock) * 1e-6
    weight = volume_dm3 * job.stock.density_kg_dm3
    x_min, _, z_min, x_max, _, z_max = exact_bounds(stock)
    overhang = job.stock.stub_length_mm and (x_max - job.stock.stub_length_mm) - x_min
    # just under and just over each limit: the limit holds at the solid's own figures
    for key, value in (("max_part_weight_kg", weight), ("max_overhang_mm", overhang),
                       ("max_part_diameter_mm", z_max - z_min)):
        parse_job(_with(reference_text, "machine", f"{key} = {value * 1.001:.6f}"), "ok.toml")
        with pytest.raises(JobFileError, match=rf"ref.toml:\d+: \[machine\] {key} = "):
            parse_job(_with(reference_text, "machine", f"{key} = {value * 0.999:.6f}"), "ref.toml")


def test_the_spindle_nose_must_clear_the_tool_over_the_safe_height(reference_text):
    job = load_job(REFERENCE)
    safe = job.stock.blank_radius_mm(job.gear) + job.machine.clearance_mm
    stick_out = max(job.tools.roughing.stick_out_mm, job.tools.finishing.stick_out_mm)
    parse_job(_with(reference_text, "machine", f"spindle_nose_top_mm = {safe + stick_out + 0.01:.4f}"), "ok.toml")
    with pytest.raises(JobFileError, match=r"spindle_nose_top_mm = .* stick-out .* needs"):
        parse_job(_with(reference_text, "machine", f"spindle_nose_top_mm = {safe + stick_out - 0.01:.4f}"), "r.toml")
    # a given gauge length counts instead of the stick-out
    text = _with(_with(reference_text, "machine", f"spindle_nose_top_mm = {safe + stick_out + 0.01:.4f}"),
                 "tools.finishing", "gauge_length_mm = 90.0")
    with pytest.raises(JobFileError, match=r"finishing tool's gauge length 90 mm"):
        parse_job(text, "gauge.toml")


def test_a_tool_below_the_smallest_end_mill_is_a_warning_not_an_error():
    small = small_job_text(finishing_diameter=1.5)
    plan = plan_cam(parse_job(_with(small, "machine", "smallest_end_mill_mm = 1.6"), "small.toml"))
    assert any("finishing tool's diameter 1.5 mm is below the smallest end mill" in w for w in plan.warnings)
    plan = plan_cam(parse_job(small, "small.toml"))  # the catalogue's 1 mm: no warning for 1.5 and 2 mm
    assert not any("smallest end mill" in w and "tool's diameter" in w for w in plan.warnings)


def test_a_blank_smaller_than_the_tip_circle_is_refused_and_a_larger_one_cut():
    spec = parse_job(small_job_text(), "s.toml").gear
    tip_diameter = spec.teeth * spec.module_mm + 2 * (1 + spec.profile_shift_coefficient) * spec.module_mm
    # the thickness allowance thins the teeth, not the tip circle
    assert 2 * spec.tip_radius_mm == pytest.approx(tip_diameter)
    text = _with(small_job_text(), "stock", f"blank_diameter_mm = {tip_diameter - 0.02:.4f}")
    with pytest.raises(JobFileError, match=r"blank_diameter_mm = .* smaller than the tip diameter .* 0\.0100 mm short"):
        parse_job(text, "small.toml")
    job = parse_job(_with(small_job_text(), "stock", f"blank_diameter_mm = {tip_diameter + 0.6:.4f}"), "s.toml")
    assert job.stock.blank_radius_mm(job.gear) == pytest.approx(tip_diameter / 2 + 0.3)


ROUGHING_TOOL = '[tools.roughing]\nkind = "flat"\ndiameter_mm = 2.0\nflutes = 3\n\n'


def _allowance(allowance_mm: float, roughing: bool = True) -> str:
    """The small job with its blank `allowance_mm` above the tip circle (and without its roughing tool)."""
    text = _with(small_job_text(), "stock", f"radial_allowance_mm = {allowance_mm}").replace(
        "radial_allowance_mm = 0.5\n", "")
    assert ROUGHING_TOOL in text
    return text if roughing else text.replace(ROUGHING_TOOL, "")


def test_without_roughing_a_blank_standing_above_the_tips_more_than_the_finishing_tool_takes_is_refused(tmp_path,
                                                                                                        capsys):
    # the finishing tool (D 1.5 mm) takes at most 0.5 x D = 0.75 mm off the tips in one pass
    plan_cam(parse_job(_allowance(0.74, roughing=False), "ok.toml"))
    text = _allowance(0.8, roughing=False)
    job = tmp_path / "big.toml"
    job.write_text(text)
    line = next(n for n, row in enumerate(text.splitlines(), 1) if row.startswith("radial_allowance_mm"))
    assert main(["run", str(job), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"spur-cad: error: {job}:{line}: radial_allowance_mm: the blank "
                                               "stands 0.800 mm above the tip circle")
    assert not (tmp_path / "out").exists()


def test_with_roughing_the_tips_are_roughed_to_the_finish_stock_and_a_larger_stock_is_refused():
    """Roughing takes the blank down to the tip circle + finish_stock_mm: any allowance runs; a finish stock
    more than the finishing tool takes off the tips in one pass (0.75 mm) is refused, naming its key."""
    job = parse_job(_allowance(1.8), "big.toml")
    plan = plan_cam(job)
    tips = plan.roughing.tip_heights_mm
    # 1.8 mm in cuts of at most 0.5 x D 2 mm: two, the last at the tip circle + the finish stock
    assert len(tips) == 2 and tips[-1] == pytest.approx(job.gear.tip_radius_mm + job.roughing.finish_stock_mm)
    assert tips[0] - tips[-1] <= 1.0 + 1e-9 and job.stock.blank_radius_mm(job.gear) - tips[0] <= 1.0 + 1e-9
    with pytest.raises(SpurCadError, match=r"finish_stock_mm = 0.8: roughing leaves that much on the tip lands") as err:
        plan_cam(parse_job(_with(_allowance(1.8), "roughing", "finish_stock_mm = 0.8\nflank_allowance_mm = 1.0"),
                           "stock.toml"))
    assert (err.value.section, err.value.field) == ("roughing", "finish_stock_mm")


WORK_OFFSET_CASES = [(dialect, expected, offset) for dialect, expected in
                     [("linuxcnc", "{g}"), ("fanuc", "{g}"), ("haas", "{g}"), ("siemens", "{g}"), ("okuma", "G15 H{n}")]
                     for offset in ("G54", "G57", "G59")]
WORK_OFFSET_IDS = [f"{offset}-{dialect}" for dialect, _, offset in WORK_OFFSET_CASES]


@pytest.mark.parametrize("dialect, expected, offset", sweep(  # each dialect in the fast tier, at one offset each
    WORK_OFFSET_CASES, fast=["G54-linuxcnc", "G57-fanuc", "G59-haas", "G57-siemens", "G59-okuma"], ids=WORK_OFFSET_IDS))
def test_every_program_selects_the_work_offset_before_the_tool(dialect, expected, offset):
    job = parse_job(_with(small_job_text(), "post", f'dialect = "{dialect}"\nwork_offset = "{offset}"'), "s.toml")
    files = build_programs(job, plan_cam(job))[1]
    want = expected.format(g=offset, n=int(offset[1:]) - 53)
    for name, data in files.items():
        lines = data.decode().splitlines()
        assert lines.count(want) == 1, name
        tool = next(i for i, line in enumerate(lines) if re.match(r"T\d", line))
        assert lines.index(want) < tool
        if dialect == "siemens":  # the blank's box for the control's simulation, before the setup
            radius = job.stock.blank_radius_mm(job.gear)
            box = [line for line in lines if line.startswith("WORKPIECE(")]
            assert box == [f'WORKPIECE(,"",,"BOX",112,{radius:.1f},{-radius:.1f},-80,'
                           f"{-job.stock.front_margin_mm:.1f},{-radius:.1f},{job.gear.face_width_mm + 1:.1f},"
                           f"{radius:.1f})"]


@pytest.mark.linuxcnc
def test_rs274_applies_the_selected_work_offset(tmp_path):
    job = parse_job(_with(small_job_text(), "post", 'work_offset = "G55"'), "s.toml")
    path = tmp_path / "roughing.ngc"
    path.write_bytes(build_programs(job, plan_cam(job))[1]["roughing.ngc"])
    ok, canon, messages = run_rs274(path)
    assert ok, messages
    assert any(line.startswith("SELECT_PLANE") for line in canon)
    # LinuxCNC reports the coordinate system change (G55 is system 2) before the first move
    first_move = next(i for i, line in enumerate(canon) if line.startswith("STRAIGHT_"))
    assert any("SET_G5X_OFFSET(2," in line for line in canon[:first_move]), canon[:first_move]


def test_an_unknown_work_offset_is_refused_naming_the_key():
    with pytest.raises(JobFileError, match=r"\[post\] work_offset .*G54"):
        parse_job(_with(small_job_text(), "post", 'work_offset = "G92"'), "s.toml")
    with pytest.raises(SpurCadError):
        dataclasses.replace(parse_job(small_job_text(), "s.toml").post, work_offset="G53")


def test_a_job_with_a_lathe_section_writes_the_blank_program_with_the_set(tmp_path):
    text = small_job_text() + '\n[lathe]\ndialect = "linuxcnc"\n\n[simulation]\nenabled = false\n'
    job = tmp_path / "small.toml"
    job.write_text(text)
    assert main(["run", str(job), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    program = (tmp_path / "out" / "blank.ngc").read_text()
    assert "G7" in program and "G95" in program and program.rstrip().endswith("M30")
    import json

    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    spec = parse_job(text, "s.toml").gear
    assert summary["lathe"]["blank_diameter_mm"] == pytest.approx(2 * spec.tip_radius_mm + 1.0)


def test_a_bar_smaller_than_the_blank_is_one_line_naming_the_lathe_key(tmp_path, capsys):
    text = small_job_text() + "\n[lathe]\nbar_diameter_mm = 40.0\n"
    job = tmp_path / "small.toml"
    job.write_text(text)
    assert main(["run", str(job), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    line = text.splitlines().index("bar_diameter_mm = 40.0") + 1
    assert len(err) == 1 and err[0].startswith(f"spur-cad: error: {job}:{line}: ") and "bar_diameter_mm" in err[0]
    assert not (tmp_path / "out").exists()
