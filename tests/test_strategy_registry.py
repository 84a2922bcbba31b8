"""A finishing strategy is one module: a strategy defined here, in the test, and handed to the loader as a
registry (`strategies=`), is found by the job loader, the generated key documentation, summary.json and
the report, without any other module knowing it. Nothing global is changed: the default registry stays
as it was (checked last)."""

from __future__ import annotations

import dataclasses
import json
import re
from dataclasses import dataclass

import pytest

from spur_cad.cam.strategies import REGISTRY, strategy_names
from spur_cad.cam.strategies.along_x import AlongXParams, AlongXStrategy
from spur_cad.cam.strategies.base import (
    ScallopParams,
    contact_bottom_allowance,
    contact_largest_tool,
    contact_suggested_tool,
)
from spur_cad.errors import JobFileError
from spur_cad.job import parse_job
from spur_cad.keydocs import job_file_reference_markdown
from spur_cad.keys import key
from tests.workbench_helper import small_job_text


@dataclass(frozen=True)
class RowsParams(ScallopParams):
    """[finishing] keys of the test's strategy: its own key besides the shared ones."""

    rows_per_flank: int = key(7, low=1, high=1000, label="RowsPerFlank", group="Finishing strategy",
                              meaning="rows (a strategy defined by a test): rows per flank")


@dataclass(frozen=True)
class RowsFacts:
    """The test strategy's own summary fields and report sentence."""

    rows_per_flank: int
    stations: int

    def report_text(self) -> str:
        return f"Finishing: rows, {self.rows_per_flank} rows per flank over {self.stations} stations."


@dataclass(frozen=True)
class RowsAdvice:
    """The test strategy's own tool advice."""

    rows_tool_max_diameter_mm: float


class RowsStrategy:
    """The along-X passes under another name, with their own parameter and facts."""

    name = "rows"
    description = "a test's strategy: along_x passes with its own key and facts"
    params_type = RowsParams
    simultaneous_rotary = AlongXStrategy.simultaneous_rotary
    helical = False
    follows_modifications = False  # its capabilities declared, as a new strategy's are (the Protocol)
    corrects_slopes = False
    lying_flat = False

    def largest_tool(self, recommendations) -> tuple[str, float]:
        return contact_largest_tool(recommendations)

    def suggested_tool(self, spec, recommendations, target_scallop_mm: float, blank_radius_mm: float):
        return contact_suggested_tool(recommendations)

    def bottom_allowance(self, tool, recommendations):
        return contact_bottom_allowance(tool, recommendations)  # along_x's passes plunge at the root

    def check_tool(self, spec, tool) -> None:
        AlongXStrategy().check_tool(spec, tool)

    def estimate_moves(self, spec, tool, params: RowsParams) -> int:
        return AlongXStrategy().estimate_moves(spec, tool, self._along_x(params))

    def generate(self, spec, tool, machine, params: RowsParams, blank_radius_mm: float):
        path, result = AlongXStrategy().generate(spec, tool, machine, self._along_x(params), blank_radius_mm)
        return path, dataclasses.replace(result, strategy=self.name,
                                         facts=RowsFacts(params.rows_per_flank, result.stations),
                                         tool_advice=RowsAdvice(2.0 * tool.diameter_mm))

    @staticmethod
    def _along_x(params: RowsParams) -> AlongXParams:
        return AlongXParams(target_scallop_mm=params.target_scallop_mm, step_over_mm=params.step_over_mm)


STRATEGIES = {**REGISTRY, RowsStrategy.name: RowsStrategy()}
JOB = small_job_text().replace("[finishing]\n", '[finishing]\nstrategy = "rows"\nrows_per_flank = 5\n') + \
    "\n[simulation]\nenabled = false\n"


def test_the_loader_takes_the_strategy_and_its_keys_from_the_registry_it_is_given():
    job = parse_job(JOB, "rows.toml", strategies=STRATEGIES)
    assert job.finishing.strategy == "rows" and job.finishing.rows_per_flank == 5
    with pytest.raises(JobFileError, match=r"^rows\.toml:\d+: unknown key 'rows_per_flank' in \[finishing\]"):
        parse_job(JOB, "rows.toml")  # the default registry knows neither the key nor the strategy
    line = JOB.splitlines().index("rows_per_flank = 5") + 1
    with pytest.raises(JobFileError) as caught:
        parse_job(JOB.replace("rows_per_flank = 5", "rows_per_flank = 0"), "rows.toml", strategies=STRATEGIES)
    assert str(caught.value) == f"rows.toml:{line}: [finishing] rows_per_flank must be in 1..1000, got 0"


def test_the_key_documentation_lists_the_strategy_and_its_key():
    text = job_file_reference_markdown(STRATEGIES)
    assert "| `rows_per_flank` | integer | - | `7` | 1..1000 | rows (a strategy defined by a test): rows per flank" \
        in text
    assert "`perimeter`, `along_x`, `generating`, `rows`" in text
    assert "rows_per_flank" not in job_file_reference_markdown()


def test_the_summary_and_the_report_show_the_strategy_s_own_facts_and_advice():
    from spur_cad.pipeline import run_job

    result = run_job(parse_job(JOB, "rows.toml", strategies=STRATEGIES))
    finishing = json.loads(result.files["summary.json"])["finishing"]
    stations = result.finishing.strategy_facts.stations
    assert finishing["strategy"] == "rows" and finishing["rows_per_flank"] == 5 and finishing["stations"] == stations
    assert list(finishing)[:3] == ["strategy", "rows_per_flank", "stations"]  # its fields, in its order
    assert f"Finishing: rows, 5 rows per flank over {stations} stations." in result.files["report.html"].decode()
    assert "(strategy: rows, " in result.files["finishing.ngc"].decode()  # the program header names it
    advice = json.loads(result.files["summary.json"])["tools"]["rows_advice"]
    assert advice == {"rows_tool_max_diameter_mm": 2.0 * result.tools.finishing.diameter_mm}
    report = result.files["report.html"].decode()
    assert "Advice for finishing strategy rows" in report  # its advice, labelled from its field names
    assert re.search(rf"rows tool max diameter</th><td class=\"num\">{advice['rows_tool_max_diameter_mm']:.3f}</td>"
                     r"<td class=\"unit\">mm</td>", report)


def test_a_registry_s_default_strategy_applies_without_a_finishing_section():
    job = parse_job(small_job_text().replace("[finishing]\n", "[unused]\n").split("[unused]")[0],
                    "rows.toml", strategies={RowsStrategy.name: RowsStrategy()})
    assert job.finishing.strategy == "rows" and job.finishing.rows_per_flank == 7


def test_two_strategies_declaring_one_key_differently_are_refused():
    from spur_cad.cam.strategies import finishing_section_type

    @dataclass(frozen=True)
    class OtherRowsParams(ScallopParams):
        rows_per_flank: int = key(9, low=1, high=50, label="RowsPerFlank", group="Finishing strategy",
                                  meaning="another meaning")

    class OtherRows(RowsStrategy):
        name = "other_rows"
        params_type = OtherRowsParams

    with pytest.raises(TypeError, match="declare the key rows_per_flank differently"):
        finishing_section_type({"rows": RowsStrategy(), "other_rows": OtherRows()})


def test_the_default_registry_is_unchanged_and_read_only():
    assert strategy_names() == ("perimeter", "along_x", "generating")
    with pytest.raises(TypeError):
        REGISTRY["rows"] = RowsStrategy()  # type: ignore[index]


def test_the_default_section_class_is_the_section_the_registry_makes():
    """FinishingParams is written out as a dataclass (typed for callers and the type checker); it must hold what
    finishing_section_type makes from REGISTRY's strategies: the same keys, in order, with the same types,
    defaults and declarations (the strategy names from the registry)."""
    from spur_cad.cam.strategies import FinishingParams, finishing_section_type
    from spur_cad.keys import keys_of

    made = finishing_section_type(dict(REGISTRY) | {"rows": RowsStrategy()})  # a registry's own section ...
    assert [k.name for k in keys_of(made)][-1] == "rows_per_flank"
    made = finishing_section_type(dict(REGISTRY))  # ... and a copy of REGISTRY: the written class
    assert made is FinishingParams
    from spur_cad.cam.strategies import _section_type

    generated, written = keys_of(_section_type(tuple(REGISTRY.items()))), keys_of(FinishingParams)
    assert [k.name for k in written] == [k.name for k in generated]
    for w, g in zip(written, generated):
        assert (str(w.type), w.default, w.unit, w.low, w.high, w.choices, w.meaning, w.label, w.group) == \
            (str(g.type), g.default, g.unit, g.low, g.high, g.choices, g.meaning, g.label, g.group), w.name
        assert (w.names_from() if w.names_from else None) == (g.names_from() if g.names_from else None)
