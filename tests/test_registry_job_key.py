"""A job key is one field: a [post] key declared here, in the test, on a subclass of the [post] section and handed
to the loader as `sections=`, is parsed, range-checked with the file, line and key in its messages, refused by
the standard loader, listed in the generated key documentation and given its workbench property, its value
reaches the post with the settings and a run's summary.json (`job_file`) and report ("Job file"), with no other
module knowing it. The standard sections stay as they were, and every key of every one of them is in `job_file`
with the value the file gives or the key's declared default.

What a key changes in the programs is the business of the code that reads it (tests/test_post.py and the
golden programs for the keys [post] has); here the declaration alone is followed.
"""

from __future__ import annotations

import dataclasses
import html
import json
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

from spur_cad.errors import JobFileError
from spur_cad.job import MODIFICATION_SECTIONS, SECTIONS, job_sections, parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.keys import key, key_of, keys_of
from spur_cad.post.settings import PostSettings
from spur_cad.report.job_file import JOB_FILE_TEXT_CHARS, job_file_tables
from spur_cad.summary import job_file_json
from tests.workbench_helper import small_job_text


@dataclass(frozen=True)
class PostWithDwell(PostSettings):
    """[post] with one key more: a dwell after the spindle starts (a key being added, declared in the test)."""

    dwell_after_spindle_s: float = key(0.0, unit="s", low=0.0, high=60.0, label="DwellAfterSpindle", group="Post",
                                       meaning="a dwell (G4) after the spindle starts, for it to reach its speed")


SECTIONS_WITH_DWELL = {"post": PostWithDwell}
JOB = small_job_text() + '\n[post]\ndialect = "fanuc"\ndwell_after_spindle_s = 2.5\n'
LINE = JOB.splitlines().index("dwell_after_spindle_s = 2.5") + 1


def test_the_loader_takes_the_key_and_checks_its_range_at_its_line():
    job = parse_job(JOB, "dwell.toml", sections=SECTIONS_WITH_DWELL)
    assert isinstance(job.post, PostWithDwell) and job.post.dwell_after_spindle_s == 2.5
    assert job.post.dialect == "fanuc"  # the section's other keys as before
    for value, problem in (("99", "must be in [0, 60] s, got 99"), ("nan", "must be a finite number, got nan"),
                           ('"long"', "must be a number, got 'long'")):
        with pytest.raises(JobFileError) as caught:
            parse_job(JOB.replace("= 2.5", f"= {value}"), "dwell.toml", sections=SECTIONS_WITH_DWELL)
        assert str(caught.value) == f"dwell.toml:{LINE}: [post] dwell_after_spindle_s {problem}"
    with pytest.raises(JobFileError, match=rf"^dwell\.toml:{LINE}: unknown key 'dwell_after_spindle_s' in \[post\]"):
        parse_job(JOB, "dwell.toml")  # the standard [post] section does not have it


def test_the_default_applies_without_the_key_and_the_section_s_own_checks_still_run():
    job = parse_job(small_job_text(), "plain.toml", sections=SECTIONS_WITH_DWELL)
    assert isinstance(job.post, PostWithDwell) and job.post.dwell_after_spindle_s == 0.0
    with pytest.raises(JobFileError, match=r"\[post\] folded = true needs rotary_mode = 'unwound'"):
        parse_job(JOB + 'rotary_mode = "wrapped"\n', "dwell.toml", sections=SECTIONS_WITH_DWELL)


def test_the_key_documentation_has_its_row():
    text = job_file_reference_markdown(replaced=SECTIONS_WITH_DWELL)
    assert ("| `dwell_after_spindle_s` | number | s | `0.0` | [0, 60] | a dwell (G4) after the spindle starts, for "
            "it to reach its speed | `DwellAfterSpindle` |") in text
    assert "dwell_after_spindle_s" not in job_file_reference_markdown()


def test_the_workbench_gives_it_a_property(monkeypatch):
    from pathlib import Path

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "workbench"))
    from spur_cad_workbench import schema

    field = schema._key_field("post", key_of(PostWithDwell, "dwell_after_spindle_s"))
    assert (field.prop, field.group, field.section, field.key) == ("DwellAfterSpindle", "Post", "post",
                                                                   "dwell_after_spindle_s")
    assert field.doc.startswith("a dwell (G4)")


def test_the_post_takes_the_section_with_the_key_and_writes_what_it_wrote_before():
    """Until code reads it, a key added changes no program: the post takes the section (a PostSettings) and
    writes the same bytes as for the standard section with the same values."""
    from spur_cad.cam.finishing import finishing_toolpath
    from spur_cad.post import ProgramInfo, post_program

    job = parse_job(JOB, "dwell.toml", sections=SECTIONS_WITH_DWELL)
    plain = PostSettings(**{k.name: getattr(job.post, k.name) for k in keys_of(PostSettings)})
    path = finishing_toolpath(job.gear, job.tools.finishing, job.machine, job.finishing,
                              job.stock.blank_radius_mm(job.gear))
    info = ProgramInfo("dwell", ("gear: z = 12",))
    assert post_program(path, job.post, info).text == post_program(path, plain, info).text
    assert dataclasses.replace(job.post, dwell_after_spindle_s=1.0).dwell_after_spindle_s == 1.0


def test_a_replacement_must_derive_from_the_section_it_replaces():
    with pytest.raises(TypeError, match=r"\[post\] must be a subclass of the section it replaces"):
        job_sections(sections={"post": dict})
    with pytest.raises(TypeError, match=r"\[unknown\] must be a subclass"):
        job_sections(sections={"unknown": PostWithDwell})
    assert job_sections()["post"] is SECTIONS["post"] is PostSettings
    assert "dwell_after_spindle_s" not in {k.name for k in keys_of(PostSettings)}


def test_summary_json_and_the_report_s_job_file_hold_the_key_with_its_value_and_unit():
    """summary.json's `job_file` and the report's "Job file" tables, from the parsed job (the run's own files:
    the slow test below)."""
    for text, dwell in ((JOB, 2.5), (small_job_text(), 0.0)):  # given, and its default
        job = parse_job(text, "dwell.toml", sections=SECTIONS_WITH_DWELL)
        post = job_file_json(job.section_values())["post"]
        assert post["dwell_after_spindle_s"] == dwell and post["dialect"] == ("fanuc" if text == JOB else "linuxcnc")
        assert list(post)[-1] == "dwell_after_spindle_s"  # declared last, on the subclass
        table = next(t for t in job_file_tables(job.section_values()) if t.head == ("[post]",))
        assert ("dwell_after_spindle_s", repr(dwell), "s") in table.rows
    standard = job_file_json(parse_job(JOB.replace("dwell_after_spindle_s = 2.5\n", ""), "plain.toml")
                             .section_values())
    assert "dwell_after_spindle_s" not in standard["post"]


HOSTILE_NAME = r'<script>alert(1)</script> & \"quoted\"\n' + "x" * 300  # as TOML writes it: quotes, a line break


@pytest.fixture(scope="module")
def dwell_run():
    """A whole run of the job with the key (simulation off; about 4 s, so the slow tier), its [machine] named
    with markup, quotes, an escape and 300 more characters."""
    from spur_cad.pipeline import run_job

    text = JOB + f'\n[simulation]\nenabled = false\n\n[machine]\nname = "{HOSTILE_NAME}"\n'
    return run_job(parse_job(text, "dwell.toml", sections=SECTIONS_WITH_DWELL)).files


@pytest.mark.slow
def test_a_run_s_summary_json_and_report_show_the_key(dwell_run):
    summary = json.loads(dwell_run["summary.json"])
    assert summary["job_file"]["post"]["dwell_after_spindle_s"] == 2.5
    report = dwell_run["report.html"].decode()
    assert '<tr><th>dwell_after_spindle_s</th><td class="num">2.5</td><td class="unit">s</td></tr>' in report


@pytest.mark.slow
def test_text_from_the_file_stays_as_given_in_json_and_escaped_and_bounded_in_the_report(dwell_run):
    name = tomllib.loads(f'name = "{HOSTILE_NAME}"')["name"]
    assert json.loads(dwell_run["summary.json"])["job_file"]["machine"]["name"] == name  # data, as given
    report = dwell_run["report.html"].decode()
    assert "<script>" not in report
    row = re.search(r"<tr><th>name</th><td class=\"text\">(&#34;&lt;script&gt;[^<]*)</td>", report)
    assert row, "the [machine] name's row"
    shown = html.unescape(row[1])
    assert shown.startswith(f'"{HOSTILE_NAME[:40]}')  # as the file writes it: TOML's escapes, one line
    assert shown.endswith(f'..." ({len(name):,} characters)')  # cut, its length said
    assert shown.count("x") == JOB_FILE_TEXT_CHARS - name.index("x")


REFERENCE_JOB = Path(__file__).resolve().parents[1] / "resources" / "examples" / "reference_gear.toml"
EVERY_SECTION = """
[mate]
teeth = 40

[tools.bottom]
kind = "flat"
diameter_mm = 1.5
flutes = 2

[lathe]

[probe]

[export]
dxf = true

[simulation]
enabled = false

[gear.modifications]
lead_crowning_um = 5.0

[gear.modifications.left]
lead_crowning_um = 3.0
"""
ROUGHING_TOP = '\n[tools.roughing_top]\nkind = "flat"\ndiameter_mm = 6.0\nflutes = 3\n'
RESOLVED = {("roughing", "strategy"): "flank",  # left out: the rotary table's default (spur_cad.cam.setups)
            ("tools.bottom", "tool_number"): 3, ("tools.roughing_top", "tool_number"): 4}  # their default numbers
"""Values the job resolves where the file gives none, other than the key's declared default (docs/job-file.md)."""


@pytest.mark.parametrize("extra", ["", EVERY_SECTION, EVERY_SECTION.split("[lathe]")[1] + ROUGHING_TOP],
                         ids=["reference", "every-section", "roughing-top"])
def test_every_key_of_every_section_the_job_has_is_in_job_file_with_its_value(extra):
    """From the registry (job_sections, keys_of), not a list: each section the file gives (and each always present:
    a default section object) holds every key its class declares, in order; a key the file gives has the file's
    value (read here with tomllib), any other the key's default. [gear.modifications.left] takes the common table's
    values for the keys it does not give."""
    text = REFERENCE_JOB.read_text() + extra
    given = tomllib.loads(text)
    job = parse_job(text, "every.toml")
    found = job_file_json(job.section_values())
    types: dict[str, type] = {}  # the standard sections, the flank modification tables after [gear]
    for name, cls in job_sections().items():
        types.update({name: cls, **(MODIFICATION_SECTIONS if name == "gear" else {})})
    optional = {"mate", "lathe", "probe", *MODIFICATION_SECTIONS,
                *(f"tools.{role}" for role in ("roughing", "finishing", "bottom", "roughing_top"))}
    present = {name for name in types if name not in optional or _table(given, name) is not None}
    assert set(found) == present and list(found) == [name for name in types if name in present]
    for name, values in found.items():
        keys = keys_of(types[name])
        assert list(values) == [k.name for k in keys], name
        table = _table(given, name) or {}
        for k in keys:
            if k.name in table:
                expected = table[k.name]
            elif name.startswith("gear.modifications."):  # a side's table
                expected = found["gear.modifications"][k.name]
            else:
                expected = RESOLVED.get((name, k.name), k.default)
            assert values[k.name] == expected and type(values[k.name]) is k.type, (name, k.name)
    assert json.loads(json.dumps(found)) == found  # JSON's own values


def _table(data: dict, name: str) -> dict | None:
    for part in name.split("."):
        data = data.get(part) if isinstance(data, dict) else None
    return data
