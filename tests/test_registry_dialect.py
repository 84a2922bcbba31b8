"""A dialect is one table entry: a Mach3-like controller defined here, in the test, and handed on as a registry
of its own (`registry(*DIALECTS.values(), MACH3)`, passed as `dialects=`), is taken by the job loader's
`[post] dialect`, listed by the generated key documentation, written by the run (its `.tap` programs, the
dialect in summary.json and the report), accepted by the output folder's vocabulary and read back by the
program reader of `spur-cad verify`, whose simulation of the programs passes. No other module knows it, and
nothing global changes: the default registry stays as it was (checked last).

What is checked against an independent reference: the programs' M98 calls and #101 / #102 assignments are
checked block by block as Mach3's manual writes a subprogram call (parameters in common variables, then
`M98 P<n>`, `O<n>` ... `M99` after `M30`); the reader's moves are the planned toolpath within the dialect's
precision; the simulated cut of the read programs is judged against the design gear.
"""

from __future__ import annotations

import json
import re
from dataclasses import replace

import numpy as np
import pytest

from spur_cad.dialects import (
    DIALECTS,
    FANUC,
    Comments,
    FoldStyle,
    Rotary,
    program_extensions,
    registry,
)
from spur_cad.errors import JobFileError
from spur_cad.job import parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.outputs import VOCABULARY, ForeignFileError, Vocabulary, check_output_folder, write_output_set
from spur_cad.verify.reader import ProgramReadError, read_program
from tests.workbench_helper import small_job_text

# Mach3 (ArtSoft): a Fanuc-like control with .tap files, M3 / M6 without padding, 4 decimals, and subprograms
# O<n> ... M99 after M30 called by M98 P<n>, their parameters handed over in the common variables #101, #102.
MACH3 = replace(
    FANUC, name="mach3", title="Mach3", extension="tap", program_start="",
    comments=Comments("paren", False, ("paren", "semicolon")), tool_change=("T{tool} M6", "G43 H{tool}"),
    spindle_on="S{rpm} M3", coolant_on="M8", coolant_off="M9", spindle_off="M5", linear_decimals=4,
    inverse_feed_decimals=4, rotary=Rotary(4),
    subprograms=replace(FANUC.subprograms, fold_style=FoldStyle.NUMBERED_SUBPROGRAM, x_param="#101",
                        a_param="#102", call=("#101={x}", "#102={a}", "M98 P{sub:04d}")),
    lathe=None, probing=None)
WITH_MACH3 = registry(*DIALECTS.values(), MACH3)
RESOLUTION_MM = 0.02
JOB = (small_job_text() + f'\n[post]\ndialect = "mach3"\n\n[simulation]\nresolution_mm = {RESOLUTION_MM}\n'
       "enabled = false\n")


def test_the_loader_takes_the_dialect_from_the_registry_it_is_given():
    job = parse_job(JOB, "mach3.toml", dialects=WITH_MACH3)
    assert job.post.dialect == "mach3" and job.dialects == WITH_MACH3
    line = JOB.splitlines().index('dialect = "mach3"') + 1
    with pytest.raises(JobFileError) as caught:
        parse_job(JOB, "mach3.toml")  # the default registry does not know it
    assert str(caught.value) == (f"mach3.toml:{line}: [post] dialect = 'mach3' is not known "
                                 "(known: linuxcnc, fanuc, haas, siemens, okuma)")
    with pytest.raises(JobFileError, match=rf"^mach3\.toml:{line}: \[post\] dialect = 'mach4' is not known "
                                           r"\(known: linuxcnc, fanuc, haas, siemens, okuma, mach3\)$"):
        parse_job(JOB.replace('"mach3"', '"mach4"'), "mach3.toml", dialects=WITH_MACH3)


def test_a_registry_without_the_default_dialect_defaults_to_its_first():
    job = parse_job(small_job_text(), "only.toml", dialects=registry(MACH3))
    assert job.post.dialect == "mach3"
    with pytest.raises(JobFileError, match=r"\[lathe\] dialect = 'siemens' is not known \(known: no dialect "
                                           r"with lathe words\)"):
        parse_job(small_job_text() + "\n[lathe]\n", "only.toml", dialects=registry(MACH3))


def test_the_key_documentation_lists_the_dialect():
    text = job_file_reference_markdown(dialects=WITH_MACH3)
    row = next(line for line in text.splitlines() if line.startswith("| `dialect` |") and "PostDialect" in line)
    assert "`linuxcnc`, `fanuc`, `haas`, `siemens`, `okuma`, `mach3`" in row and "mach3 (Mach3, .tap)" in row
    lathe_row = next(line for line in text.splitlines() if "LatheDialect" in line)
    assert "mach3" not in lathe_row  # no lathe words, so not a lathe's control
    assert "mach3" not in job_file_reference_markdown()


@pytest.fixture(scope="module")
def run():
    from spur_cad.pipeline import plan_cam, run_job

    job = parse_job(JOB, "mach3.toml", dialects=WITH_MACH3)
    plan = plan_cam(job)
    return job, run_job(job, plan=plan), plan


def test_the_run_writes_the_dialect_s_programs_summary_and_report(run):
    _, result, _ = run
    assert {"roughing.tap", "finishing.tap"} <= set(result.files) and not any(
        name.endswith((".ngc", ".nc")) for name in result.files)
    summary = json.loads(result.files["summary.json"])
    assert summary["post"]["dialect"] == "mach3" and summary["post"]["finishing_subprograms"] >= 1
    report = result.files["report.html"].decode()
    assert "post mach3, folded into subprograms" in report
    assert "finishing.tap" in report and "roughing.tap" in report  # the program files in the tables


def test_the_programs_call_their_subprograms_as_mach3_does(run):
    _, result, _ = run
    lines = result.files["finishing.tap"].decode().splitlines()
    assert lines[0] == lines[-1] == "%" and lines[1].startswith("(spur_cad ")  # the title as a comment
    end = lines.index("M30")
    calls = [i for i, line in enumerate(lines) if line.startswith("M98 ")]
    assert calls and all(i < end for i in calls)
    for i in calls:  # the parameters in the common variables, then the call of a subprogram after the end
        assert re.fullmatch(r"#101=-?\d+\.\d{1,4}", lines[i - 2]) and re.fullmatch(r"#102=-?\d+\.\d{1,4}",
                                                                                       lines[i - 1])
        number = re.fullmatch(r"M98 P(\d{4})", lines[i]).group(1)
        start = lines.index(f"O{number}")
        assert start > end and "M99" in lines[start:]
    assert any(re.search(r"A(#102|\[#102[+-]\d+\.\d{1,4}\])( |$)", line) for line in lines[end + 1:])


def test_the_output_vocabulary_takes_the_dialect_s_programs(run, tmp_path):
    _, result, _ = run
    vocabulary = Vocabulary(program_extensions(WITH_MACH3))
    assert vocabulary.matches("finishing.tap") and vocabulary.matches("roughing_space5.tap")
    assert not VOCABULARY.matches("finishing.tap")  # the default registry's vocabulary
    written = write_output_set(tmp_path / "out", result.files, vocabulary=vocabulary)
    assert {path.name for path in written} == set(result.files)
    with pytest.raises(ValueError, match="output vocabulary"):
        write_output_set(tmp_path / "default", result.files)
    with pytest.raises(ForeignFileError, match="names finishing.tap"):  # its manifest, read with the default's
        check_output_folder(tmp_path / "out")


def test_verify_reads_the_programs_back_and_their_cut_passes(run):
    from spur_cad.verify.verify import verify_moves

    job, result, plan = run
    programs = []
    for name in ("roughing", "finishing"):
        text = result.files[f"{name}.tap"].decode()
        moves = read_program(text, "mach3", f"{name}.tap", dialects=WITH_MACH3)
        path = getattr(plan, name).toolpath
        poses = path.poses()[path.motion_mask]
        poses = poses[np.concatenate([[True], np.any(np.abs(np.diff(poses, axis=0)) > 1e-9, axis=1)])]
        read = np.column_stack([moves.x, moves.y, moves.z, moves.a])
        # 4 decimals: X, Y, Z rounded, A the run's rounded base plus the rounded relative angle (docs/post.md)
        assert read.shape == poses.shape and np.all(np.abs(read - poses) <= np.array([0.5e-4] * 3 + [1e-4]) + 1e-9)
        programs.append(moves)
        with pytest.raises(ProgramReadError, match="unknown dialect 'mach3'"):
            read_program(text, "mach3", f"{name}.tap")  # the default registry's reader does not know it
    verdict = verify_moves(replace(job, simulation=replace(job.simulation, enabled=True)), programs)
    assert verdict.passed, verdict.lines()
    assert verdict.max_gouge_mm <= RESOLUTION_MM


def test_the_default_registry_is_unchanged_and_read_only():
    assert tuple(DIALECTS) == ("linuxcnc", "fanuc", "haas", "siemens", "okuma")
    with pytest.raises(TypeError):
        DIALECTS["mach3"] = MACH3  # type: ignore[index]
    with pytest.raises(ValueError, match="different names"):
        registry(*DIALECTS.values(), replace(MACH3, name="fanuc"))
