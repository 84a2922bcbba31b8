"""Issue 45 (3): inputs are validated once, when a typed input is made.

Every job-file section refuses a bad value in its own `__post_init__` (derived here from the key registry: for
each numeric key, a value above its declared `high`, and NaN), so an invalid section cannot exist; the checks
that need context (a tool's role, the gear a stock or [three_axis] is for) run only where the typed inputs are
put together, which the AST check below lists: nothing below them calls `.validate(` again.
"""

from __future__ import annotations

import ast
import dataclasses
import math
from pathlib import Path

import pytest

from spur_cad.cam.plan import check_cam_inputs
from spur_cad.cam.strategies import REGISTRY, FinishingParams
from spur_cad.cam.strategies.generating import GeneratingStrategy
from spur_cad.cam.tools import Tool, ToolError
from spur_cad.errors import SpurCadError
from spur_cad.geometry.spec import GearSpec
from spur_cad.job import load_job, parse_job
from spur_cad.job_sections import MODIFICATION_SECTIONS, SECTIONS
from spur_cad.keys import keys_of
from spur_cad.pipeline import cam_inputs

ROOT = Path(__file__).resolve().parents[1]

# A value for each required key, so that a section can be made with every other key at its default.
REQUIRED = {"teeth": 20, "module_mm": 2.0, "face_width_mm": 10.0, "diameter_mm": 3.0}

# The sections made from the job file, the flank modification tables and every strategy's parameters; Tool is
# checked with its role (below), not when made: suggestions and the plan make tools beyond the file's ranges.
SECTION_TYPES = sorted({cls for cls in (*SECTIONS.values(), *MODIFICATION_SECTIONS.values(),
                                        *(s.params_type for s in REGISTRY.values())) if cls is not Tool},
                       key=lambda cls: cls.__name__)


def _required(cls: type) -> dict[str, object]:
    return {k.name: REQUIRED[k.name] for k in keys_of(cls) if k.required}


def _above_high(cls: type) -> list[tuple[type, str, object]]:
    """(section, key, a value above the key's high bound) for every numeric key of `cls` with a range."""
    defaults = cls(**_required(cls))
    cases = []
    for k in keys_of(cls):
        if k.type not in (int, float) or k.high is None:
            continue
        high = getattr(defaults, k.high) if isinstance(k.high, str) else k.high
        cases.append((cls, k.name, high + 1 if k.type is int else high + max(1.0, abs(high))))
    return cases


ABOVE_HIGH = [case for cls in SECTION_TYPES for case in _above_high(cls)]
NAN = [(cls, k.name) for cls in SECTION_TYPES for k in keys_of(cls) if k.type is float]


def test_every_section_is_checked_and_its_defaults_make_it():
    assert len(SECTION_TYPES) >= 15 and len(ABOVE_HIGH) >= 120, (len(SECTION_TYPES), len(ABOVE_HIGH))
    for cls in SECTION_TYPES:
        cls(**_required(cls))  # the declared defaults pass the section's own checks


@pytest.mark.parametrize("cls, name, value", ABOVE_HIGH, ids=[f"{c.__name__}.{n}" for c, n, _ in ABOVE_HIGH])
def test_a_value_above_its_range_is_refused_when_the_section_is_made(cls, name, value):
    with pytest.raises(SpurCadError) as raised:
        cls(**{**_required(cls), name: value})
    assert raised.value.field == name and name in str(raised.value), str(raised.value)


@pytest.mark.parametrize("cls, name", NAN, ids=[f"{c.__name__}.{n}" for c, n in NAN])
def test_nan_is_refused_when_the_section_is_made(cls, name):
    with pytest.raises(SpurCadError, match=rf"{name} must be a finite number, got nan") as raised:
        cls(**{**_required(cls), name: math.nan})
    assert raised.value.field == name


SOME = ABOVE_HIGH[::17]


@pytest.mark.parametrize("cls, name, value", SOME, ids=[f"{c.__name__}.{n}" for c, n, _ in SOME])
def test_replace_with_a_bad_value_is_refused_too(cls, name, value):
    made = cls(**_required(cls))
    with pytest.raises(SpurCadError):
        dataclasses.replace(made, **{name: value})


def test_a_tool_is_checked_with_its_role_where_the_inputs_meet():
    """A Tool is made unchecked (the suggestions' bisection probes reach beyond the file's ranges); the loader and
    CamInputs check each tool with its role, which the messages name."""
    for k in keys_of(Tool):
        if k.type in (int, float) and isinstance(k.high, (int, float)):
            value = k.high + 1 if k.type is int else k.high * 2.0 + 1.0
            tool = Tool(**{**_required(Tool), k.name: value})
            with pytest.raises(ToolError, match=rf"\[tools.finishing\] {k.name} must be in") as raised:
                tool.validate("finishing")
            assert raised.value.field == k.name


# --- where `.validate(` may be called ----------------------------------------------------------------------

# (module, the function the call is in): the places where typed inputs are put together with their context.
ALLOWED_VALIDATE_CALLS = {
    # the job loader: the features and the stock against the gear, [three_axis] against the face width, each tool
    # with its role
    ("spur_cad/job.py", "_job_from_data"),
    ("spur_cad/job.py", "_validate_sections"),
    # the plan's inputs made by a script: the same checks, once, in CamInputs.__post_init__
    ("spur_cad/cam/plan_types.py", "__post_init__"),
    # the CAD entry points for scripts: the features and the stock against the gear
    ("spur_cad/cad/solid.py", "gear_shape"),
    ("spur_cad/cad/solid.py", "stock_shape"),
}


def validate_calls(source: str) -> list[tuple[str, int]]:
    """(enclosing function, line) of every `<something>.validate(...)` call in `source`."""
    found = []

    def visit(node: ast.AST, function: str) -> None:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            function = node.name
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "validate":
            found.append((function, node.lineno))
        for child in ast.iter_child_nodes(node):
            visit(child, function)

    visit(ast.parse(source), "<module>")
    return found


def _sources() -> list[Path]:
    return [path for folder in ("spur_cad", "workbench") for path in sorted((ROOT / folder).rglob("*.py"))]


def test_validate_is_called_only_where_typed_inputs_are_put_together():
    calls = {(path.relative_to(ROOT).as_posix(), function, line) for path in _sources()
             for function, line in validate_calls(path.read_text())}
    stray = sorted(call for call in calls if call[:2] not in ALLOWED_VALIDATE_CALLS)
    assert not stray, f"inner layers re-validate typed inputs (check once, in __post_init__): {stray}"
    assert len(calls) >= 6  # the loader's, CamInputs' and the CAD entry points' calls are found


def test_a_section_s_own_checks_are_in_its_post_init():
    """Every `validate` method left takes the context it checks against (the gear, the face width, a role)."""
    own = []
    for path in _sources():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                for item in node.body:
                    if isinstance(item, ast.FunctionDef) and item.name == "validate" and len(item.args.args) < 2:
                        own.append(f"{path.relative_to(ROOT)}: {node.name}.validate")
    assert not own, own


@pytest.mark.parametrize("snippet, expected", [
    ("def f(s):\n    s.validate()\n", [("f", 2)]),
    ("class C:\n    def g(self):\n        x = lambda: self.a.validate(1)\n", [("g", 3)]),
    ("settings.validate()\n", [("<module>", 1)]),
    ("def f(s):\n    validate(s)\n", []),
])
def test_validate_calls_finds_each_form(snippet, expected):
    assert validate_calls(snippet) == expected


# --- a strategy's tool check: once per plan ----------------------------------------------------------------


class CountingGenerating(GeneratingStrategy):
    """The generating strategy, counting the calls of its tool check."""

    def __init__(self) -> None:
        self.checks = 0

    def check_tool(self, spec: GearSpec, tool: Tool) -> None:
        self.checks += 1
        super().check_tool(spec, tool)


@pytest.mark.parametrize("two_stage", [False, True], ids=["one stage", "two stages"])
def test_the_strategy_s_tool_check_runs_once_per_plan_s_checks(two_stage):
    """check_cam_inputs runs the finishing strategy's check_tool once, with the tool conflicts (one stage) or before
    the finishing work bound (two stages), not again in check_finishing_work."""
    from tests.test_two_stage import JOB

    job = parse_job(JOB, "two.toml") if two_stage else load_job(ROOT / "resources" / "examples" / "reference_gear.toml")
    counting = CountingGenerating()
    inputs = dataclasses.replace(cam_inputs(job), finishing=FinishingParams(strategy="generating"),
                                 strategies={**REGISTRY, "generating": counting})
    assert (inputs.bottom_tool is not None) == two_stage
    check_cam_inputs(inputs)
    assert counting.checks == 1
