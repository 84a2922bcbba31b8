"""The import graph of spur_cad/, workbench/ and benchmarks/: no loops, and no import up the layers that
docs/architecture.md lists (read from its `layers` block, so the page and the code cannot drift apart).

Every import counts, at the top of a file, inside a function (a lazy import is still a dependency) or under
`if TYPE_CHECKING:` (an annotation names the module all the same: two modules that name each other are one
module in two files, however the import is hidden).
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {"spur_cad": ROOT / "spur_cad", "spur_cad_workbench": ROOT / "workbench" / "spur_cad_workbench",
            "benchmarks": ROOT / "benchmarks"}
LAYER_ROOTS = {"spur_cad/": "spur_cad", "workbench/": "spur_cad_workbench"}


@dataclass(frozen=True)
class Import:
    """One import statement's target module, where it is, and whether it only serves annotations."""

    target: str
    line: int
    annotations_only: bool


def module_files() -> dict[str, Path]:
    """{dotted module name: file} of every Python file of the three packages."""
    found = {}
    for package, folder in PACKAGES.items():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            parts = parts[:-1] if parts[-1] == "__init__" else parts
            found[".".join((package, *parts))] = path
    return found


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imports_of(module: str, path: Path, modules: set[str]) -> list[Import]:
    """The modules of the packages that `module` imports (`from package import submodule` names the
    submodule), anywhere in its file."""
    is_package = path.name == "__init__.py"
    found: list[Import] = []

    def visit(node: ast.AST, annotations_only: bool) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node):
            for child in node.body:
                visit(child, True)
            for child in node.orelse:
                visit(child, annotations_only)
            return
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")[: len(module.split(".")) - (0 if is_package else 1)]
                base = base[: len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            targets = [source] + [f"{source}.{alias.name}" for alias in node.names]
        for target in targets:
            while target and target not in modules and "." in target:  # a name inside a module
                target = target.rsplit(".", 1)[0]
            if target in modules and target != module:
                found.append(Import(target, node.lineno, annotations_only))
        for child in ast.iter_child_nodes(node):
            visit(child, annotations_only)

    visit(ast.parse(path.read_text(encoding="utf-8")), False)
    return found


def import_graph() -> dict[str, list[Import]]:
    files = module_files()
    return {module: imports_of(module, path, set(files)) for module, path in files.items()}


def loops(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    counter = 0
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def documented_layers(text: str) -> list[tuple[str, ...]]:
    """The layers of docs/architecture.md's `layers` block, top first: each a tuple of module prefixes
    (dotted; a folder ends with '.')."""
    block = text.split("<!-- layers:", 1)[1].split("```", 2)[1]
    layers = []
    for line in block.strip("\n").splitlines():
        paths = []
        for token in line.split():
            if not (token.endswith("/") or token.endswith(".py")):
                break
            for folder, package in LAYER_ROOTS.items():
                if token.startswith(folder):
                    parts = [p for p in token.removeprefix(folder).removesuffix(".py").split("/") if p]
                    dotted = ".".join([package, *(p for p in parts if p != "__init__")])
                    paths.append(dotted + "." if token.endswith("/") else dotted)
        layers.append(tuple(paths))
    return layers


def layer_of(module: str, layers: list[tuple[str, ...]]) -> int | None:
    """The index (0: top) of the layer holding `module`; None when no layer lists it."""
    for number, prefixes in enumerate(layers):
        for prefix in prefixes:
            if module == prefix.rstrip(".") or (prefix.endswith(".") and module.startswith(prefix)):
                return number
    return None


def upward_imports(graph: dict[str, list[Import]], layers: list[tuple[str, ...]]) -> list[str]:
    problems = []
    for module, found in graph.items():
        own = layer_of(module, layers)
        for imported in found:
            theirs = layer_of(imported.target, layers)
            if own is not None and theirs is not None and theirs < own:
                problems.append(f"{module} (line {imported.line}) imports {imported.target}, a layer above it")
    return problems


def dependency_graph(graph: dict[str, list[Import]]) -> dict[str, set[str]]:
    """{module: the modules it imports}, every kind of import counted."""
    return {module: {i.target for i in found} for module, found in graph.items()}


# --- the tests --------------------------------------------------------------------------------------------


def test_the_import_graph_has_no_loop():
    assert loops(dependency_graph(import_graph())) == []


def test_no_import_runs_up_the_documented_layers():
    layers = documented_layers((ROOT / "docs" / "architecture.md").read_text(encoding="utf-8"))
    graph = import_graph()
    unlisted = [m for m in graph if not m.startswith("benchmarks") and layer_of(m, layers) is None]
    assert unlisted == [], f"modules in no layer of docs/architecture.md: {unlisted}"
    assert upward_imports(graph, layers) == []


def test_the_walk_finds_a_planted_loop_a_lazy_import_and_an_upward_import(tmp_path):
    """The checks above can fail: a loop made only by an import inside a function, one made only by an
    annotation-only import, and an import from the geometry layer up into the CAM layer, are found."""
    files = {"low": "import pkg.high\n", "high": "def f():\n    from pkg import low\n",
             "typed": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import named\n",
             "named": "from pkg.typed import f\n", "alone": "import pkg.low\n"}
    modules = {f"pkg.{name}" for name in files}
    graph = {}
    for name, text in files.items():
        (tmp_path / f"{name}.py").write_text(text)
        graph[f"pkg.{name}"] = imports_of(f"pkg.{name}", tmp_path / f"{name}.py", modules)
    assert sorted(loops(dependency_graph(graph))) == [["pkg.high", "pkg.low"], ["pkg.named", "pkg.typed"]]
    assert graph["pkg.typed"][0].annotations_only
    layers = documented_layers("<!-- layers: x -->\n```\nspur_cad/cam/  cam\nspur_cad/geometry/  geometry\n```\n")
    planted = {"spur_cad.geometry.spec": [Import("spur_cad.cam.plan", 3, False)],
               "spur_cad.cam.plan": [Import("spur_cad.geometry.spec", 1, False)]}
    assert upward_imports(planted, layers) == [
        "spur_cad.geometry.spec (line 3) imports spur_cad.cam.plan, a layer above it"]


def test_the_documented_layers_are_read_as_written():
    layers = documented_layers((ROOT / "docs" / "architecture.md").read_text(encoding="utf-8"))
    assert layers[0] == ("spur_cad",) and layers[-1][0] == "spur_cad.errors"
    assert layer_of("spur_cad.cam.strategies.generating", layers) < layer_of("spur_cad.geometry.spec", layers)
    assert all(re.fullmatch(r"[a-z_.]+", prefix) for layer in layers for prefix in layer)
