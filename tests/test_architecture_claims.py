"""The claims of docs/architecture.md about the code, checked against the code (issue 45): every rotation is
written in spur_cad/geometry/frames.py, except the simulator's numba kernels named there; no module passes the
correction's facts by string key to the report; the paths, names, IR table and CamPlan block the page gives; which
modules write files and import what.

Claims checked elsewhere: the layers and the import loops (tests/test_imports.py), the module size limit
(tests/test_module_size.py), the flag reads of the gear kinds and set-ups (tests/test_kinds.py), the dialect table
(tests/test_dialect_table.py), the worked examples (tests/test_docs_examples.py), no scipy.optimize in a run
(tests/test_roots.py), `import spur_cad` without CadQuery (tests/test_cad.py), the CLI's process without OCP
(tests/test_cad_worker.py). Each test here reads the page or the sources themselves, so the page and the code
cannot drift apart unnoticed; each has a planted-fault twin showing that it can fail.
"""

from __future__ import annotations

import ast
import dataclasses
import re
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from tests.test_docs_claims import missing_paths

ROOT = Path(__file__).resolve().parents[1]
ROTATION = re.compile(  # c y - s z / y c + z s and their spelled-out cos/sin forms, the way R(angle) is written
    r"\b(c|cos\w*|np\.cos\([^)]*\)|math\.cos\([^)]*\))\s*\*\s*[\w\[\]:, .]+?\s*[-+]\s*"
    r"(s|sin\w*|np\.sin\([^)]*\)|math\.sin\([^)]*\))\s*\*"
    # c y - s z written out, or R as a matrix [[c, s], [-s, c]]
    r"|\*\s*(c|cos\w*)\s*[-+]\s*[\w\[\]:, .]+?\*\s*(s|sin\w*)\b"
    r"|\[\[\s*(c|cos\w*)\s*,\s*-?\s*(s|sin\w*)\s*\]\s*,\s*\[\s*-?\s*(s|sin\w*)\s*,\s*(c|cos\w*)\s*\]\]")
ROTATION_HOMES = {"spur_cad/geometry/frames.py",
                  "spur_cad/sim/kernel.py", "spur_cad/sim/engagement.py", "spur_cad/sim/section_engagement.py",
                  # the whole gear's outline turns space 0 by a matrix product, whose rounding (fused multiply-adds)
                  # the STEP, DXF/SVG and 3-axis outputs keep byte-identical; turn_points differs in the last bit
                  "spur_cad/geometry/sampling.py"}


def rotations_written_out() -> dict[str, list[str]]:
    """{file: lines} of the package's and the workbench's sources that write a rotation out."""
    found: dict[str, list[str]] = {}
    for folder in ("spur_cad", "workbench"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            lines = [line.strip() for line in path.read_text(encoding="utf-8").splitlines()
                     if ROTATION.search(line.split("#")[0])]
            if lines:
                found[path.relative_to(ROOT).as_posix()] = lines
    return found


def test_the_search_finds_the_rotations_it_looks_for():
    """The pattern recognises R(angle) as the homes write it (else the next test would pass by finding nothing)."""
    for line in ("return np.stack([c * y - s * z, s * y + c * z], axis=-1)",
                 "x, y = points[:, 1] * c - points[:, 2] * s, 0",
                 "u = np.cos(a) * y - np.sin(a) * z",
                 "return np.stack([x * c + y * s, -x * s + y * c], axis=-1)",
                 "chunks.append(space @ np.array([[c, s], [-s, c]]))"):
        assert ROTATION.search(line), line
    for line in ("d = c * y", "rb * (np.sin(t) - t * np.cos(t))", "area = a * b - c * d"):
        assert not ROTATION.search(line), line
    assert set(rotations_written_out()) == ROTATION_HOMES  # each home writes one


def test_no_module_but_frames_and_the_simulator_kernels_writes_a_rotation():
    outside = {name: lines for name, lines in rotations_written_out().items() if name not in ROTATION_HOMES}
    assert outside == {}, "write rotations with spur_cad.geometry.frames (docs/architecture.md, Frames)"



UNTYPED_ALLOWED = {  # the JobResult's fields that are dictionaries, each of one kind of value under a name of its own
    ("CadResult", "step_bytes"): "STEP file name -> its size",
    ("ErrorBudgetFacts", "inputs"): "the [error_budget] section's values, echoed into summary.json (read by no one)",
    ("ErrorBudgetFacts", "share_um"): "ISO 1328 deviation name -> its share, as Grading names them",
    ("ErrorBudgetFacts", "share_percent"): "ISO 1328 deviation name -> its share",
    ("JobResult", "timings_s"): "stage name -> seconds",
    ("JobResult", "files"): "output file name -> bytes",
}


def test_the_job_result_passes_its_facts_typed():
    """docs/architecture.md: no layer passes dictionaries of facts by string key. Every field of the JobResult and
    of its parts (spur_cad/result.py) is a typed value; the dictionaries left are name -> value tables, listed
    above (JobResult.correction, once correction.json's dict read by key in the report, is CorrectionFacts)."""
    import dataclasses

    import spur_cad.result as result

    found = []
    for name, cls in vars(result).items():
        if not (isinstance(cls, type) and dataclasses.is_dataclass(cls) and cls.__module__ == result.__name__):
            continue
        for field in dataclasses.fields(cls):
            annotation = str(field.type)
            if re.search(r"\b(dict|Any|object)\b", annotation) and (name, field.name) not in UNTYPED_ALLOWED:
                found.append(f"{name}.{field.name}: {annotation}")
    assert found == []

PAGE = ROOT / "docs" / "architecture.md"
SOURCES = [*sorted((ROOT / "spur_cad").rglob("*.py")), *sorted((ROOT / "workbench").rglob("*.py"))]


def _page() -> str:
    return PAGE.read_text(encoding="utf-8")


def _section(text: str, heading: str) -> str:
    """The text of one `## heading` section of the page."""
    return text.split(f"\n## {heading}", 1)[1].split("\n## ", 1)[0]


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


# --- every path the page names exists -----------------------------------------------------------------------


def test_every_path_the_page_names_exists():
    assert missing_paths(_page()) == []


def test_a_renamed_path_is_found():
    assert missing_paths("see `spur_cad/cam/planner.py` and `cam/plan.py`") == ["spur_cad/cam/planner.py"]
    assert missing_paths("see `cam/plans.py`, `strategies/bases.py` and `strategies/base.py`") == [
        "cam/plans.py", "strategies/bases.py"]


# --- the names the page gives to functions, types and fields -----------------------------------------------

NAMED = [
    # (module, dotted attribute the page names)
    ("spur_cad.outputs", "write_output_set"),
    ("spur_cad.inputs", None),
    ("spur_cad.job", "load_job"), ("spur_cad.job", "parse_job"),
    ("spur_cad.cam.plan", "plan_cam"), ("spur_cad.cam.plan", "CamInputs"),
    ("spur_cad.post", "post_program"),
    ("spur_cad.sim", "simulate"),
    ("spur_cad.summary", "build_result"), ("spur_cad.summary", "summary_json"),
    ("spur_cad.result", "JobResult"),
    ("spur_cad.pipeline", "run_job"),
    ("spur_cad.cad_worker", "CadWorker"),
    ("spur_cad.cam.ir", "Toolpath.start_poses"), ("spur_cad.cam.ir", "ToolpathBuilder.build"),
    ("spur_cad.geometry.frames", "part_to_machine"), ("spur_cad.geometry.frames", "machine_to_part"),
    ("spur_cad.geometry.frames", "gap_to_part"), ("spur_cad.geometry.frames", "space_angle_rad"),
    ("spur_cad.geometry.frames", "turn_points"),
    ("spur_cad.grade.grading", "Grading.to_json"), ("spur_cad.grade.simulated", "grade_simulation"),
    ("spur_cad.grade.measured", "grade_measured"),
    ("spur_cad.keys", "key"), ("spur_cad.keydocs", "job_file_reference_markdown"),
    ("spur_cad.cam.strategies", "REGISTRY"), ("spur_cad.cam.strategies", "finishing_section_type"),
    ("spur_cad.cam.strategies.base", "TargetScallopParams"), ("spur_cad.cam.strategies.base", "ScallopParams"),
    ("spur_cad.cam.strategies.base", "FinishingResult"), ("spur_cad.cam.strategies.base", "StationFacts"),
    ("spur_cad.cam.strategies.base", "estimate_by_generating"),
    ("spur_cad.cam.strategies.perimeter", "PerimeterStrategy.estimate"),
    ("spur_cad.dialects", "Dialect"), ("spur_cad.dialects", "DIALECTS"), ("spur_cad.dialects", "FoldStyle"),
    ("spur_cad.geometry.kinds", "KINDS"), ("spur_cad.geometry.kinds", "EXTERNAL_SPUR"),
    ("spur_cad.geometry.kinds", "EXTERNAL_HELICAL"), ("spur_cad.geometry.kinds", "INTERNAL_SPUR"),
    ("spur_cad.geometry.spec", "GearSpec.kind"), ("spur_cad.geometry.spec", "GearSpec.section_turn_rad"),
    ("spur_cad.geometry.spec", "GearSpec.lead_mm"), ("spur_cad.geometry.spec", "GearSpec.tooth_space_profile"),
    ("spur_cad.geometry.internal", "InternalGearSpec"),
    ("spur_cad.cam.setups", "ROTARY_TABLE"), ("spur_cad.cam.setups", "LYING_FLAT"),
    ("spur_cad.cam.setups", "MachineSetup.cuts"), ("spur_cad.cam.setups", "MachineSetup.accepts_tool_kind"),
    ("spur_cad.cam.setups", "MachineSetup.reads_section"),
]


def unknown_names(named: list[tuple[str, str | None]]) -> list[str]:
    import importlib

    unknown = []
    for module_name, dotted in named:
        try:
            found: object = importlib.import_module(module_name)
        except ImportError:
            unknown.append(module_name)
            continue
        for part in (dotted or "").split(".") if dotted else ():
            fields = {f.name for f in dataclasses.fields(found)} if dataclasses.is_dataclass(found) else set()
            if part in fields:
                break
            if not hasattr(found, part):
                unknown.append(f"{module_name}.{dotted}")
                break
            found = getattr(found, part)
    return unknown


def test_the_functions_and_types_the_page_names_exist_where_it_says():
    assert unknown_names(NAMED) == []


def test_a_renamed_function_is_found():
    assert unknown_names([("spur_cad.cam.plan", "plan_the_cam"), ("spur_cad.cam.ir", "Toolpath.end_poses"),
                          ("spur_cad.no_such_module", None)]) == [
        "spur_cad.cam.plan.plan_the_cam", "spur_cad.cam.ir.Toolpath.end_poses", "spur_cad.no_such_module"]


def test_the_user_errors_the_page_names_are_spur_cad_errors():
    from spur_cad.cam.machine import MachineError
    from spur_cad.cam.tools import ToolError
    from spur_cad.errors import GearSpecError, JobFileError, PostError, SpurCadError

    assert all(issubclass(error, SpurCadError) for error in (GearSpecError, JobFileError, ToolError, MachineError,
                                                             PostError))


def test_the_registries_are_read_only_and_hold_what_the_page_lists():
    from spur_cad.cam.strategies import REGISTRY
    from spur_cad.dialects import DIALECTS
    from spur_cad.geometry.kinds import EXTERNAL_HELICAL, EXTERNAL_SPUR, INTERNAL_SPUR, KINDS

    text = _section(_page(), "Finishing strategies are plug-ins")
    listed = re.search(r"The registry holds (.*?)\(\[cam\.md\]", text, re.S).group(1)
    assert set(re.findall(r"`(\w+)`", listed)) - {"generating_flat", "generating_geometry", "generating_helical",
                                                  "generating_modified", "generating_plan",
                                                  "generating_advice"} == set(REGISTRY)
    assert {f"generating_{part}" for part in ("flat", "geometry", "helical", "modified", "plan", "advice")} == {
        path.stem for path in (ROOT / "spur_cad" / "cam" / "strategies").glob("generating_*.py")}
    for registry in (REGISTRY, DIALECTS):
        assert isinstance(registry, types.MappingProxyType)
        with pytest.raises(TypeError):
            registry["new"] = None  # type: ignore[index]
    assert set(KINDS.values()) == {EXTERNAL_SPUR, EXTERNAL_HELICAL, INTERNAL_SPUR}


def test_the_table_that_turns_the_other_way_is_a_post_key():
    from spur_cad.post.settings import PostSettings

    assert "rotary_sign" in {f.name for f in dataclasses.fields(PostSettings)}


# --- the toolpath IR table and the CamPlan block --------------------------------------------------------------


def ir_table_arrays(text: str) -> tuple[list[str], list[str]]:
    """The arrays the IR table lists (in order) and the other fields its 'Also stored:' sentence names."""
    section = _section(text, "Toolpath IR")
    arrays = []
    for row in re.findall(r"^\| `([^|]+)` \|", section, re.M):
        arrays += [name.strip() for name in row.replace("`", "").split(",")]
    stored = re.search(r"Also stored: (.*?)\.", section, re.S).group(1)
    return arrays, re.findall(r"`(\w+)`", stored)


def toolpath_fields() -> tuple[list[str], list[str]]:
    from spur_cad.cam.ir import Toolpath

    fields = dataclasses.fields(Toolpath)
    arrays = [f.name for f in fields if "np.ndarray" in str(f.type)]
    return arrays, [f.name for f in fields if f.name not in arrays]


def test_the_ir_table_lists_every_array_and_field_of_the_toolpath():
    assert ir_table_arrays(_page()) == toolpath_fields()


def test_the_ir_table_names_every_move_kind_and_feature():
    from spur_cad.cam.ir import Feature, MoveKind

    rows = {row.split("|")[1].strip(): row.split("|")[2] for row in re.findall(r"^\|.*\|$", _section(
        _page(), "Toolpath IR"), re.M)}
    for enum, row in ((MoveKind, rows["`kind`"]), (Feature, rows["`feature`"])):
        named = [word for word in re.split(r"[:,()]", row.lower())]
        for member in enum:
            words = member.name.lower().replace("_", " ").replace("ccw", "counter-clockwise").replace(
                "cw", "clockwise")
            assert any(words in part for part in named), f"{enum.__name__}.{member.name} not in: {row}"


def test_a_missing_ir_field_is_found():
    text = _page().replace("| `station` |", "| `stations` |")
    assert ir_table_arrays(text) != toolpath_fields()


def cam_plan_block(text: str) -> list[str]:
    """The field names of the page's CamPlan block, in order."""
    block = _section(text, "The CAM plan").split("```\nCamPlan\n", 1)[1].split("```", 1)[0]
    return [line.split()[0] for line in block.splitlines() if re.match(r"  \w", line)]


def test_the_cam_plan_block_lists_the_fields_of_cam_plan_in_order():
    from spur_cad.cam.plan import CamPlan

    assert cam_plan_block(_page()) == [f.name for f in dataclasses.fields(CamPlan)]


def test_the_cam_plan_holds_typed_fields_only():
    """'no dictionaries of facts by string key' in the plan: no field of CamPlan or of its parts is a dict."""
    from spur_cad.cam.plan import CamPlan, FinishingPlan, RoughingPlan

    for cls in (CamPlan, RoughingPlan, FinishingPlan):
        assert not [f.name for f in dataclasses.fields(cls) if re.search(r"\bdict\b|Mapping|Any", str(f.type))]


def test_a_missing_cam_plan_field_is_found():
    text = _page().replace("\n  flank_suggested ", "\n  flank_suggestion ")
    assert cam_plan_block(text) != cam_plan_block(_page())


def test_the_kinds_and_setups_have_the_capabilities_the_page_names():
    from spur_cad.cam.setups import MachineSetup
    from spur_cad.geometry.kinds import GearKind
    from spur_cad.result import JobResult

    text = _section(_page(), "Gear kinds and machine set-ups are types")
    kinds_text, setups_text = text.split("- **Machine set-ups**", 1)
    for cls, part in ((GearKind, kinds_text), (MachineSetup, setups_text)):
        members = {f.name for f in dataclasses.fields(cls)} | set(dir(cls))
        named = {n for n in re.findall(r"`(\w+)(?:\(|`)", part) if n.islower() and "_" in n or n in members}
        named -= {"is_helical", "is_internal", "section_turn_rad", "lead_mm"} - members
        assert named - members - {"axes", "reads_section", "three_axis", "machine_setup"} == set(), cls
    assert {"setup", "kind"} <= {f.name for f in dataclasses.fields(JobResult)}


# --- source-level claims -------------------------------------------------------------------------------------

WRITERS = {
    "spur_cad/outputs.py": "the one writer of output sets (write_output_set, write_file_atomically)",
    "spur_cad/verify/rs274.py": "rs274's scratch files, in a temporary folder of its own",
    "spur_cad/freecad_install.py": "the workbench's link in FreeCAD's Mod folder (its record through outputs.py)",
    "spur_cad/cad_worker.py": "the worker's results, on its standard output",
}
"""The modules that write to the file system, and what. Everything else hands bytes up (docs/architecture.md:
'No layer writes files')."""

_WRITE_CALLS = {"write_text", "write_bytes", "symlink_to", "mkdir", "touch", "rename", "replace", "unlink",
                "rmtree", "savefig", "fdopen"}


def file_writes(path: Path) -> list[int]:
    """Lines of `path` that write to the file system: open(..., 'w'/'a'/'x'), os.open with O_WRONLY/O_CREAT,
    Path.write_text / write_bytes / mkdir / ..., os.replace / rename / unlink, shutil, savefig to a path."""
    lines = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""
        owner = func.value.id if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) else ""
        if name == "open" and owner in ("", "io"):
            mode = node.args[1] if len(node.args) > 1 else next((k.value for k in node.keywords if k.arg == "mode"),
                                                                None)
            if isinstance(mode, ast.Constant) and isinstance(mode.value, str) and set(mode.value) & set("wax+"):
                lines.append(node.lineno)
        elif name == "open" and owner == "os" and re.search(r"O_WRONLY|O_CREAT|O_RDWR", ast.unparse(node)):
            lines.append(node.lineno)
        elif name == "savefig" and node.args and not (isinstance(node.args[0], ast.Name) and
                                                      node.args[0].id in ("buffer", "buf", "stream")):
            lines.append(node.lineno)
        elif name == "fdopen" and re.search(r"['\"][wax+]", ast.unparse(node)):
            lines.append(node.lineno)
        elif name in _WRITE_CALLS - {"savefig", "replace", "fdopen"} or (name == "replace" and owner == "os") or \
                (owner == "shutil" and name in ("copy", "copy2", "copyfile", "copytree", "move", "rmtree")):
            lines.append(node.lineno)
    return lines


def writers(paths: list[Path]) -> dict[str, list[int]]:
    return {_relative(p) if p.is_relative_to(ROOT) else p.name: found for p in paths if (found := file_writes(p))}


def test_only_the_listed_modules_write_files():
    found = writers(SOURCES)
    assert set(found) - set(WRITERS) == set(), {k: v for k, v in found.items() if k not in WRITERS}
    assert set(WRITERS) <= set(found)  # the list has no stale entry


def test_a_planted_write_is_found(tmp_path):
    cases = {"a.py": "open(p, 'w').write(s)\n", "b.py": "from pathlib import Path\nPath(p).write_bytes(b)\n",
             "c.py": "import os\nos.replace(a, b)\n", "d.py": "fig.savefig('x.png')\n",
             "e.py": "import os\nfd = os.open(p, os.O_WRONLY | os.O_CREAT)\n", "g.py": "os.fdopen(fd, 'wb')\n",
             "f.py": "open(p).read()\nfig.savefig(buffer, format='png')\ntext.replace('a', 'b')\n"
                   "os.fdopen(fd, 'rb')\nshutil.get_terminal_size()\n"}
    for name, source in cases.items():
        (tmp_path / name).write_text(source)
    assert sorted(writers(sorted(tmp_path.iterdir()))) == ["a.py", "b.py", "c.py", "d.py", "e.py", "g.py"]


def imported_roots(path: Path, inside_functions: bool | None = None) -> set[str]:
    """The top-level packages `path` imports (absolute imports); `inside_functions`: only those inside (True) or
    outside (False) a function body, None: all."""
    found = set()

    def visit(node: ast.AST, in_function: bool) -> None:
        if isinstance(node, (ast.Import, ast.ImportFrom)) and (inside_functions is None or
                                                               inside_functions == in_function):
            if isinstance(node, ast.Import):
                found.update(alias.name.split(".")[0] for alias in node.names)
            elif not node.level and node.module:
                found.add(node.module.split(".")[0])
        for child in ast.iter_child_nodes(node):
            visit(child, in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)))

    visit(ast.parse(path.read_text(encoding="utf-8")), False)
    return found


def test_spur_cad_never_imports_freecad():
    package = [p for p in SOURCES if _relative(p).startswith("spur_cad/")]
    assert not {_relative(p) for p in package if imported_roots(p) & {"FreeCAD", "FreeCADGui", "Part"}}


def third_party(roots: set[str]) -> set[str]:
    return roots - set(sys.stdlib_module_names) - {"spur_cad", "__future__"}


GEOMETRY_BEYOND_NUMPY = {"spur_cad/geometry/mate_mesh.py": {"shapely"}}
"""The geometry modules that import more than numpy (docs/architecture.md names them): the [mate] mesh's polygons."""


def test_geometry_runs_with_numpy_alone():
    """The geometry layer imports numpy and nothing else outside the standard library (no scipy, no kernel), but
    for the modules listed above."""
    found = {_relative(p): third_party(imported_roots(p)) - {"numpy"} - GEOMETRY_BEYOND_NUMPY.get(_relative(p), set())
             for p in sorted((ROOT / "spur_cad" / "geometry").glob("*.py"))}
    assert {k: v for k, v in found.items() if v} == {}


def test_cadquery_and_build123d_are_imported_only_inside_the_functions_that_use_them():
    """The engine needs OCP only: the front-ends a user brings are imported by their own functions, never at the
    top of a module (so `import spur_cad.cad` works without them)."""
    package = [p for p in SOURCES if _relative(p).startswith("spur_cad/")]
    assert not [_relative(p) for p in package if imported_roots(p, inside_functions=False) & {"cadquery",
                                                                                              "build123d"}]


def test_the_import_checks_find_planted_imports(tmp_path):
    (tmp_path / "m.py").write_text("import scipy.optimize\nimport numpy\ndef f():\n    import cadquery\n")
    assert third_party(imported_roots(tmp_path / "m.py")) == {"scipy", "numpy", "cadquery"}
    assert imported_roots(tmp_path / "m.py", inside_functions=False) == {"scipy", "numpy"}
    assert imported_roots(tmp_path / "m.py", inside_functions=True) == {"cadquery"}


def test_the_first_rows_pose_is_its_own_start():
    """'Toolpath.start_poses(): the previous row's, and for the first row its own.'"""
    from spur_cad.cam.ir import MoveKind, Operation, ToolpathBuilder

    builder = ToolpathBuilder(Operation.FINISHING, 1, 1000.0)
    for x_mm, a_deg in ((1.0, 0.0), (2.0, 5.0), (3.0, -7.5)):
        builder.move(MoveKind.LINEAR, x_mm, 0.5, 5.0, a_deg, feed=100.0)
    path = builder.build()
    starts = path.start_poses()
    assert starts.tolist() == [[1.0, 0.5, 5.0, 0.0], [1.0, 0.5, 5.0, 0.0], [2.0, 0.5, 5.0, 5.0]]


def ocp_imports(path: Path) -> set[str]:
    """The OCP names `path` imports, as 'module.name' (`from OCP.TColgp import TColgp_Array1OfVec`)."""
    return {f"{node.module}.{alias.name}" for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("OCP") for alias in node.names}


def test_what_differs_between_ocp_versions_is_imported_only_in_ocp_compat():
    compat = ROOT / "spur_cad" / "cad" / "ocp_compat.py"
    differing = ocp_imports(compat)
    assert len(differing) == 12  # six names, each from OCP 8.0 and from OCP 7.9
    elsewhere = {_relative(p): ocp_imports(p) & differing for p in SOURCES if p != compat}
    assert {k: v for k, v in elsewhere.items() if v} == {}


def test_a_planted_ocp_import_is_found(tmp_path):
    (tmp_path / "m.py").write_text("from OCP.TColgp import TColgp_HArray1OfPnt, TColgp_Array1OfPnt\n")
    differing = ocp_imports(ROOT / "spur_cad" / "cad" / "ocp_compat.py")
    assert ocp_imports(tmp_path / "m.py") & differing == {"OCP.TColgp.TColgp_HArray1OfPnt"}


# --- frames, imports inside a layer, the kernel on first use -------------------------------------------------


@pytest.mark.parametrize("a_deg", [0.0, 30.0, -117.5, 250.0])
def test_a_turns_the_part_as_the_page_writes_it(a_deg):
    """'(y cos A - z sin A, y sin A + z cos A) when A is commanded', written out here."""
    from spur_cad.geometry.frames import machine_to_part, part_to_machine

    y, z = 3.0, 11.0
    a = a_deg * np.pi / 180.0
    expected = [y * np.cos(a) - z * np.sin(a), y * np.sin(a) + z * np.cos(a)]
    assert part_to_machine(np.array([[y, z]]), a_deg)[0] == pytest.approx(expected, abs=1e-12)
    assert machine_to_part(np.array([expected[0]]), np.array([expected[1]]), np.array([a_deg]))[0] == pytest.approx(
        [y, z], abs=1e-12)


@pytest.mark.parametrize("space, psi_deg", [(0, 0.0), (1, 7.0), (5, -12.5), (16, 3.0)])
def test_a_contact_of_space_k_is_brought_up_by_psi_minus_k_pitches(space, psi_deg):
    """'space k is brought up under the tool by A = -k * 360/z'; a contact at gap polar angle psi (from +y toward
    +x) 'is brought onto the vertical through the axis by A = psi - k * 360/z'."""
    from spur_cad.geometry.frames import gap_to_part, part_to_machine

    teeth, radius_mm = 17, 20.0
    psi = psi_deg * np.pi / 180.0
    contact = np.array([[radius_mm * np.sin(psi), radius_mm * np.cos(psi)]])  # in space k's gap frame
    machine = part_to_machine(gap_to_part(contact, space, teeth), psi_deg - space * 360.0 / teeth)[0]
    assert machine == pytest.approx([0.0, radius_mm], abs=1e-9)


def test_the_three_posts_share_the_one_header_writer_and_the_table_lies_lowest():
    """'one header writer, post/header.py, for the milling, lathe and probing programs'; 'The table lies in the
    lowest layer'."""
    from tests.test_imports import documented_layers, import_graph, layer_of

    graph = {module: {i.target for i in found} for module, found in import_graph().items()}
    posts = ("spur_cad.post.program", "spur_cad.post.lathe", "spur_cad.post.probe")
    assert [m for m in posts if "spur_cad.post.header" not in graph[m]] == []
    layers = documented_layers(_page())
    assert layer_of("spur_cad.dialects", layers) == len(layers) - 1


def test_inside_cam_the_layers_order_holds():
    """'in cam/: machine and tools below the strategies, the strategies below finishing and plan'; and 'the
    simulation and report stages never import the job loader or the pipeline'."""
    from tests.test_imports import import_graph

    graph = {module: {i.target for i in found} for module, found in import_graph().items()}
    strategies = {m for m in graph if m.startswith("spur_cad.cam.strategies")}
    assert not {m for m in ("spur_cad.cam.machine", "spur_cad.cam.tools") if graph[m] & strategies}
    assert not {m for m in strategies if graph[m] & {"spur_cad.cam.finishing", "spur_cad.cam.plan"}}
    stages = [m for m in graph if m.startswith(("spur_cad.sim", "spur_cad.report"))]
    assert not {m for m in stages if graph[m] & {"spur_cad.job", "spur_cad.pipeline"}}


def test_import_spur_cad_loads_no_cad_kernel():
    """'`import spur_cad` loads no CAD kernel' (nor does a GearSpec): neither OCP nor a front-end."""
    code = ("import json, sys, spur_cad; spur_cad.GearSpec(teeth=20, module_mm=2); "
            "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules} & {'OCP', 'cadquery', 'build123d'})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False,
                         cwd=ROOT)
    assert out.stdout.strip() == "[]", out.stderr


NAMED_STRATEGY_ALLOWED = {
    ("spur_cad/summary.py", "perimeter"): "summary.json's perimeter_* keys (the comparison with perimeter finishing)",
}
"""Where a strategy's name may be written outside spur_cad/cam/strategies/ (docs/architecture.md: 'no module keeps
a list of strategy names ... none of them names one, but for the comparison with the perimeter strategy')."""


def strategy_names_written(paths: list[Path], names: set[str]) -> set[tuple[str, str]]:
    """(file, name) for every string constant of `paths` that is exactly a strategy's name."""
    return {(_relative(p) if p.is_relative_to(ROOT) else p.name, node.value)
            for p in paths for node in ast.walk(ast.parse(p.read_text(encoding="utf-8")))
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in names}


def test_no_module_outside_the_strategies_names_a_strategy():
    from spur_cad.cam.strategies import REGISTRY

    outside = [p for p in SOURCES if not _relative(p).startswith("spur_cad/cam/strategies/")]
    assert strategy_names_written(outside, set(REGISTRY)) == set(NAMED_STRATEGY_ALLOWED)


def test_a_planted_strategy_name_is_found(tmp_path):
    (tmp_path / "m.py").write_text('"""Uses along_x."""\nif strategy.name == "along_x":\n    pass\n')
    assert strategy_names_written([tmp_path / "m.py"], {"along_x", "perimeter"}) == {("m.py", "along_x")}


def protocol_members() -> set[str]:
    from spur_cad.cam.strategies.base import FinishingStrategy

    members = set(FinishingStrategy.__annotations__) | {
        name for name, value in vars(FinishingStrategy).items() if not name.startswith("_") and
        (callable(value) or isinstance(value, property))}
    return members


def test_the_page_names_every_member_of_the_strategy_protocol():
    """'Everything about a strategy is declared in its module:' the list that follows names every member of
    strategies/base.py's FinishingStrategy protocol."""
    listed = set(re.findall(r"`(\w+)", _section(_page(), "Finishing strategies are plug-ins")))
    assert protocol_members() - listed == set()
    assert {"generate", "check_tool", "bottom_allowance", "lying_flat"} <= protocol_members()  # the walk finds them
