"""The documents' claims about where things are, checked against the repository (issue 45): every repository
path that docs/*.md and README.md name exists, every `spur_cad.module.name` they give resolves, and docs/post.md's
table of the dialects agrees with the registry. docs/architecture.md's own claims: tests/test_architecture_claims.py.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [*sorted(p.name for p in (ROOT / "docs").glob("*.md")), "../README.md"]


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


# --- every path the documents name exists -----------------------------------------------------------------------


ROOTS = ("spur_cad/", "tests/", "workbench/", "benchmarks/", ".ci/", "docs/", "resources/")


def named_paths(text: str) -> set[str]:
    """The repository paths the page names in backticks or in its layer block (spur_cad/..., tests/...,
    workbench/..., benchmarks/...; `.py` files and folders)."""
    tokens = set(re.findall(r"`([^`\s]+)`", text)) | set(text.split())
    found = {t.rstrip(".,;:)") for t in tokens if t.startswith(ROOTS)}
    return {t for t in found if re.fullmatch(r"[\w./-]+", t) and re.fullmatch(r"[\w-]*(\.(py|md|toml|txt|sh|json))?/?",
                                                                        t.rsplit("/", 1)[-1] or "x")}


def short_paths(text: str) -> set[str]:
    """Module paths the page names relative to spur_cad/ (`cam/plan.py`, `strategies/base.py`, `post/header.py`)."""
    folders = {p.name for p in (ROOT / "spur_cad").rglob("*") if p.is_dir()}
    return {t for t in re.findall(r"`([\w/]+\.py)`", text)
            if "/" in t and t.split("/")[0] in folders and not t.startswith(ROOTS)}


EXAMPLES = {"spur_cad/cam/strategies/tip_first.py"}
"""Paths the page names as what a reader would add (its worked example)."""


def missing_paths(text: str) -> list[str]:
    """The paths the text names that do not exist (short ones: no module of spur_cad/ ends with them)."""
    missing = [p for p in sorted(named_paths(text) - EXAMPLES) if not (ROOT / p).exists()]
    modules = [_relative(f) for f in (ROOT / "spur_cad").rglob("*.py")]
    missing += [short for short in sorted(short_paths(text)) if not any(m.endswith("/" + short) for m in modules)]
    return missing


@pytest.mark.parametrize("document", DOCUMENTS)
def test_every_path_the_documents_name_exists(document):
    """The same for every page of docs/ and the README (paths of this repository; others' are not read)."""
    assert missing_paths((ROOT / "docs" / document).read_text(encoding="utf-8")) == []


# --- docs/post.md's table of the five dialects ---------------------------------------------------------------


def post_table(text: str) -> dict[str, dict[str, str]]:
    """{row name: {controller title: cell}} of docs/post.md's dialect table."""
    after = text.split("## One post, five dialects", 1)[1].split("\n|", 1)[1]
    lines = ("|" + after.split("\n\n", 1)[0]).splitlines()
    titles = [cell.strip() for cell in lines[0].strip("|").split("|")][1:]
    table = {}
    for line in lines[2:]:
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        table[cells[0]] = dict(zip(titles, cells[1:], strict=True))
    return table


def post_table_disagreements(text: str) -> list[str]:
    """Cells of the table that the registry's dialects contradict."""
    from spur_cad.dialects import DIALECTS

    table, wrong = post_table(text), []
    by_title = {d.title: d for d in DIALECTS.values()}
    assert set(table["file"]) == set(by_title)
    for title, d in by_title.items():
        setup = table["setup"][title]
        setup = table["setup"][setup.removeprefix("same as ")] if setup.startswith("same as ") else setup
        checks = {
            "file": table["file"][title].startswith(f"`.{d.extension}`") and ("%" in table["file"][title])
            == d.percent_delimited,
            "setup": setup == f"`{d.setup}`",
            "decimals": table["decimals mm / deg"][title] == f"{d.linear_decimals} / {d.rotary.decimals}",
            "feed": ("G93" in table["simultaneous feed"][title]) == d.inverse_time,
            "folding": d.subprograms.x_param in table["folding"][title] and
            d.subprograms.a_param in table["folding"][title],
            "comments": (("( )" in table["comments"][title]) == (d.comments.style == "paren")) and
            (("upper case" in table["comments"][title]) == d.comments.uppercase),
        }
        wrong += [f"{title}: {row}" for row, ok in checks.items() if not ok]
    return wrong


def test_the_dialect_table_of_post_md_agrees_with_the_registry():
    assert post_table_disagreements((ROOT / "docs" / "post.md").read_text(encoding="utf-8")) == []


def test_a_wrong_cell_of_the_dialect_table_is_found():
    text = (ROOT / "docs" / "post.md").read_text(encoding="utf-8")
    assert post_table_disagreements(text.replace("| 4 / 4 | 3 / 3 | 3 / 3 |", "| 4 / 4 | 4 / 4 | 3 / 3 |")) == [
        "Fanuc: decimals"]
    assert post_table_disagreements(text.replace("`G71 G90 G94 G17 G40`", "`G71 G90 G94 G17 G40 G49`")) == [
        "Siemens 840D: setup"]


# --- every dotted spur_cad name the documents give resolves ---------------------------------------------------


def unresolved_names(text: str) -> list[str]:
    """The `spur_cad.module.name` references of a text that name no module, attribute or dataclass field."""
    import importlib

    unresolved = []
    for dotted in sorted(set(re.findall(r"\bspur_cad(?:\.[A-Za-z_]\w*)+", text))):
        parts = dotted.split(".")
        for split in range(len(parts), 0, -1):
            try:
                found: object = importlib.import_module(".".join(parts[:split]))
            except ImportError:
                continue
            for part in parts[split:]:
                fields = {f.name for f in dataclasses.fields(found)} if dataclasses.is_dataclass(found) else set()
                if part in fields:
                    break
                if not hasattr(found, part):
                    unresolved.append(dotted)
                    break
                found = getattr(found, part)
            break
    return unresolved


@pytest.mark.parametrize("document", DOCUMENTS)
def test_every_spur_cad_name_the_documents_give_resolves(document):
    assert unresolved_names((ROOT / "docs" / document).read_text(encoding="utf-8")) == []


def test_a_moved_name_is_found():
    assert unresolved_names("`spur_cad.post.program.inert_comment_text`, `spur_cad.post.header.inert_comment_text`, "
                            "`spur_cad.cam.ir.Toolpath.start_poses`, `spur_cad.cam.ir.Toolpath.feed`") == [
        "spur_cad.post.program.inert_comment_text"]


# --- docs/architecture.md: the keyword arguments and fields it names ---------------------------------------


KEYWORDS = {  # the keyword arguments the page says each entry point takes
    ("spur_cad.job", "parse_job"): {"strategies", "dialects", "sections"},
    ("spur_cad.keydocs", "job_file_reference_markdown"): {"strategies", "dialects", "replaced"},
    ("spur_cad.pipeline", "run_job"): {"cad_worker"},
}
FIELDS = {  # the fields the page says a dataclass has
    ("spur_cad.cam.plan", "CamInputs"): {"strategies"},
    ("spur_cad.cam.machine", "Machine"): {"axes"},
    ("spur_cad.result", "JobResult"): {"setup", "kind", "files", "correction"},
    ("spur_cad.result", "SetupFacts"): {"machine_setup"},
}


def missing_keywords_and_fields(keywords: dict, fields: dict) -> list[str]:
    import importlib
    import inspect

    missing = []
    for (module, name), expected in keywords.items():
        parameters = set(inspect.signature(getattr(importlib.import_module(module), name)).parameters)
        missing += [f"{name}({keyword}=)" for keyword in sorted(expected - parameters)]
    for (module, name), expected in fields.items():
        found = {f.name for f in dataclasses.fields(getattr(importlib.import_module(module), name))}
        missing += [f"{name}.{field}" for field in sorted(expected - found)]
    return missing


def test_the_entry_points_take_the_registries_and_the_types_have_the_fields_the_page_names():
    assert missing_keywords_and_fields(KEYWORDS, FIELDS) == []
    assert hasattr(__import__("spur_cad.cam.machine", fromlist=["Machine"]).Machine, "setup")


def test_a_dropped_keyword_or_field_is_found():
    assert missing_keywords_and_fields({("spur_cad.job", "parse_job"): {"registry"}},
                                       {("spur_cad.result", "JobResult"): {"set_up"}}) == [
        "parse_job(registry=)", "JobResult.set_up"]


def test_the_job_schema_example_is_the_machine_s_own_declaration():
    """The `clearance_mm` declaration docs/architecture.md shows is [machine] clearance_mm's, default and metadata."""
    from spur_cad.cam.machine import Machine

    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8").split("\n## The job schema", 1)[1]
    snippet = text.split("```python\n", 1)[1].split("```", 1)[0]
    namespace: dict = {}
    exec("from dataclasses import dataclass\nfrom spur_cad.keys import key\n@dataclass(frozen=True)\nclass Shown:\n"
         + "".join(f"    {line}\n" for line in snippet.splitlines()), namespace)
    shown = dataclasses.fields(namespace["Shown"])[0]
    real = next(f for f in dataclasses.fields(Machine) if f.name == shown.name)
    assert (shown.name, shown.default, dict(shown.metadata)) == (real.name, real.default, dict(real.metadata))
