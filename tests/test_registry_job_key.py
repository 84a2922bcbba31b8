"""A job key is one field: a [post] key declared here, in the test, on a subclass of the [post] section and handed
to the loader as `sections=`, is parsed, range-checked with the file, line and key in its messages, refused by
the standard loader, listed in the generated key documentation and given its workbench property, and its value
reaches the post with the settings, with no other module knowing it. The standard sections stay as they were.

What a key changes in the programs is the business of the code that reads it (tests/test_post.py and the
golden programs for the keys [post] has); here the declaration alone is followed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import pytest

from spur_cad.errors import JobFileError
from spur_cad.job import SECTIONS, job_sections, parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.keys import key, key_of, keys_of
from spur_cad.post.settings import PostSettings
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
