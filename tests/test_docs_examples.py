"""The Python examples of docs/usage.md and docs/cad.md that show the CAD front-ends run as written, each in a fresh
namespace, and what they print or build is checked against the same independent reference as tests/test_cad.py
(the exact outline's area times the face width)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def python_blocks(document: str, containing: str) -> list[str]:
    """The ```python blocks of `document` (relative to the checkout) whose text contains `containing`."""
    text = (ROOT / document).read_text(encoding="utf-8")
    return [block for block in BLOCK.findall(text) if containing in block]


def exact_volume_mm3(spec, bore_mm: float = 0.0) -> float:
    import math

    from spur_cad.geometry import gear_outline
    from spur_cad.geometry.sampling import polygon_area

    return (polygon_area(gear_outline(spec, 1e-6)) - math.pi * bore_mm**2 / 4.0) * spec.face_width_mm


def test_the_readme_build123d_example_builds_a_gear_with_its_bore(capsys):
    (block,) = python_blocks("docs/usage.md", "bd.BuildPart")
    namespace: dict = {}
    exec(compile(block, "docs/usage.md", "exec"), namespace)
    volume = float(capsys.readouterr().out.strip())
    # build123d's volume uses OCP's default integration, off by about 1e-4 relative on swept B-spline faces
    # (docs/cad.md); the bore is 12 % of the gear, so a bore left out is far outside
    assert volume == pytest.approx(exact_volume_mm3(namespace["spec"], 30.0), rel=1e-4)


@pytest.mark.cadquery
@pytest.mark.parametrize("document", ["docs/usage.md", "docs/cad.md"])
def test_the_solid_examples_run_and_agree_with_the_exact_outline(document):
    import build123d

    (block,) = python_blocks(document, 'frame="part"') if document == "docs/cad.md" else \
        python_blocks(document, "spur_cad.gear_shape(spec, frame=")
    namespace: dict = {}
    exec(compile(block, document, "exec"), namespace)
    spec = namespace["spec"]
    from spur_cad.cad.solid import solid_volume_mm3

    assert solid_volume_mm3(namespace["shape"]) == pytest.approx(
        exact_volume_mm3(spec, 30.0 if document == "docs/cad.md" else 0.0), rel=1e-6)
    solid = namespace["part"] if document == "docs/cad.md" else namespace["solid"]
    assert isinstance(solid, build123d.Solid)
    assert solid.bounding_box().min.Z == pytest.approx(-spec.face_width_mm / 2.0, abs=1e-6)


def test_the_how_to_add_a_dialect_example_of_docs_post_md_runs_as_written(capsys, monkeypatch):
    """docs/post.md's worked example: its table entry is the dialect tests/test_dialect_table.py defines, and the
    registry made from it takes a job file's `[post] dialect = "acme"`, writes `.acm` programs that start as the
    entry says, has them in the output vocabulary and reads them back: what each print's comment says it prints."""
    from spur_cad.dialects import DIALECTS
    from tests.test_dialect_table import ACME

    (entry,) = python_blocks("docs/post.md", "ACME = replace(")
    (run,) = python_blocks("docs/post.md", "dialects=WITH_ACME")
    monkeypatch.chdir(ROOT)  # the example names the reference job relative to the checkout
    namespace: dict = {}
    exec(compile(entry, "docs/post.md", "exec"), namespace)
    assert namespace["ACME"] == ACME and tuple(namespace["WITH_ACME"]) == (*DIALECTS, "acme")
    exec(compile(run, "docs/post.md", "exec"), namespace)
    printed = capsys.readouterr().out.splitlines()
    promised = [line.split("# ", 1)[1] for line in run.splitlines() if line.startswith("print(")]
    assert printed == promised
    assert "acme" not in DIALECTS  # nothing global changed


def test_the_architecture_strategy_example_registers_and_finishes_a_gear_tip_land_first():
    """docs/architecture.md's worked strategy example, run as written and passed as a registry of its own: the
    loader takes its strategy and key, and every tooth space is finished tip land first, the tip passes touching
    the tip circle (the bull-nose section's distance from the axis written out here: the flat's height over the
    axis within the flat, the corner's circle beside it)."""
    import numpy as np

    from spur_cad.cam.finishing import plan_finishing
    from spur_cad.cam.ir import Feature
    from spur_cad.cam.strategies import REGISTRY
    from spur_cad.job import parse_job
    from tests.workbench_helper import small_job_text

    def finish(job):
        return plan_finishing(job.gear, job.tools.finishing, job.machine, job.finishing,
                              job.stock.blank_radius_mm(job.gear), job.strategies)

    (block,) = python_blocks("docs/architecture.md", "class TipFirstStrategy")
    namespace: dict = {}
    exec(compile(block, "docs/architecture.md", "exec"), namespace)
    strategy = namespace["TipFirstStrategy"]()
    strategies = {**REGISTRY, strategy.name: strategy}
    text = small_job_text().replace("[finishing]\n", '[finishing]\nstrategy = "tip_first"\n')
    job = parse_job(text, "tip_first.toml", strategies=strategies)
    assert job.finishing.strategy == "tip_first" and job.finishing.tip_land_first is True
    path, result = finish(job)
    assert result.strategy == "tip_first" and result.facts.tip_land_first
    assert result.report_text() == f"Finishing: tip_first, {result.points_per_flank} contacts per flank, the tip " \
                                   "land, then the flanks."
    assert any(w.startswith("finishing strategy tip_first: ") for w in path.warnings)
    cutting = path.feature != Feature.NONE
    for k in range(job.gear.teeth):
        features = path.feature[cutting & (path.space == k)]
        runs = [int(f) for i, f in enumerate(features) if i == 0 or f != features[i - 1]]
        assert runs == [Feature.TIP, Feature.RIGHT_FLANK, Feature.LEFT_FLANK]  # (along_x: the root with the right)
    tool, r_a = job.tools.finishing, job.gear.tip_radius_mm
    tip = cutting & (path.feature == Feature.TIP)
    beside = np.maximum(np.abs(path.y[tip]) - tool.flat_width_mm / 2.0, 0.0)
    distance = np.hypot(beside, path.z[tip] + tool.corner_radius_mm) - tool.corner_radius_mm
    assert np.allclose(distance, r_a, atol=1e-6)
    last = parse_job(text.replace('strategy = "tip_first"\n', 'strategy = "tip_first"\ntip_land_first = false\n'),
                     "tip_first.toml", strategies=strategies)
    features = finish(last)[0].feature
    assert features[features != Feature.NONE][-1] == Feature.TIP  # its own key puts the land last
