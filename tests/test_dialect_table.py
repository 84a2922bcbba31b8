"""The dialect table (spur_cad.dialects) is the one place that knows controllers (issue 26, point 3).

The milling post, the lathe post, the program reader and the CLI read the table's attributes and never
compare a dialect's name (checked on their source); a dialect defined here, and nowhere else, is written
by both posts and read back by the reader; the table and the settings do not import each other."""

from __future__ import annotations

import ast
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from spur_cad import keys
from spur_cad.cam.finishing import finishing_toolpath
from spur_cad.cam.machine import Machine
from spur_cad.cam.strategies import FinishingParams
from spur_cad.cam.turning import LatheError, LatheSection, plan_lathe
from spur_cad.dialects import DIALECTS, FANUC, Dialect, Rotary, dialect, lathe_names
from spur_cad.job import load_job
from spur_cad.post import PostError, PostSettings, ProgramInfo, post_program
from spur_cad.post.lathe import lathe_dialect, lathe_extension, post_lathe
from spur_cad.verify.reader import ProgramReadError, read_program
from tests.gears import spec_of, tools_for
from tests.test_post import assert_same_moves

ROOT = Path(__file__).resolve().parent.parent
READERS_OF_THE_TABLE = ("spur_cad/post/program.py", "spur_cad/post/lathe.py", "spur_cad/verify/reader.py",
                        "spur_cad/verify/program_text.py", "spur_cad/verify/controller.py", "spur_cad/cli.py")
NAMES = frozenset(DIALECTS)
INFO = ProgramInfo("spur_cad test (new dialect)", ("gear: z = 12",))

# The worked example of docs/post.md ("Adding a dialect"), defined here and nowhere else: a Fanuc-compatible
# control without % delimiters and with the title as a comment line, blocks of at most 100 characters, and
# M15 / M16 rotary direction codes; it keeps Fanuc's lathe words.
ACME = replace(FANUC, name="acme", title="Acme", extension="acm", percent_delimited=False,
               program_start="O{number:04d}", max_line_length=100, rotary=Rotary(3, direction_codes=("M15", "M16")))


# --- the table is the one place ---------------------------------------------------------------------------


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the string constants that are docstrings or bare string statements (prose, not code)."""
    return {id(node.value) for node in ast.walk(tree) if isinstance(node, ast.Expr)
            and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)}


def name_comparisons(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, name) of every dialect name compared, tested for membership, matched or subscripted with."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            parts = [node]
        elif isinstance(node, ast.MatchValue):
            parts = [node.value]
        elif isinstance(node, ast.Subscript):
            parts = [node.slice]
        else:
            continue
        for part in parts:
            found += [(sub.lineno, sub.value) for sub in ast.walk(part)
                      if isinstance(sub, ast.Constant) and isinstance(sub.value, str) and sub.value in NAMES]
    return found


def name_literals(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, name) of every string literal in the code (docstrings aside) equal to a dialect's name."""
    prose = _docstrings(tree)
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in NAMES
            and id(node) not in prose]


def test_the_checker_finds_name_comparisons():
    source = ('if d == "fanuc": pass\nx = d in ("haas", "okuma")\ny = {"siemens": 1}["siemens"]\n'
              'match d:\n    case "linuxcnc": pass\n')
    assert {name for _, name in name_comparisons(ast.parse(source))} == set(NAMES)
    assert not name_comparisons(ast.parse('"""fanuc"""\nif d.subprograms.local_labels: pass\n'))


@pytest.mark.parametrize("path", READERS_OF_THE_TABLE)
def test_posts_reader_and_cli_name_no_dialect(path):
    """No dialect name as a literal in the code of the modules that read the table (prose aside)."""
    tree = ast.parse((ROOT / path).read_text(), path)
    assert name_literals(tree) == [], f"{path} names dialects: the table (spur_cad/dialects.py) should know"


def test_nothing_in_spur_cad_compares_a_dialect_name():
    """Anywhere in the package but the table, a dialect name is at most a default or a choice, never compared."""
    for path in sorted((ROOT / "spur_cad").rglob("*.py")):
        if path == ROOT / "spur_cad" / "dialects.py":
            continue
        found = name_comparisons(ast.parse(path.read_text(), str(path)))
        assert found == [], f"{path.relative_to(ROOT)} compares dialect names: {found}"


def _spur_cad_imports(path: Path) -> set[str]:
    """Every spur_cad module a file imports, at the top or inside a function."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
        elif isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
    return {name for name in names if name.split(".")[0] == "spur_cad"}


def test_the_table_and_the_settings_do_not_import_each_other():
    assert _spur_cad_imports(ROOT / "spur_cad/dialects.py") == {"spur_cad.errors"}
    assert _spur_cad_imports(ROOT / "spur_cad/errors.py") == set()
    settings = ast.parse((ROOT / "spur_cad/post/settings.py").read_text())
    assert any(isinstance(node, ast.ImportFrom) and node.module == "spur_cad.dialects" for node in settings.body)


def test_the_table_is_consistent():
    assert keys.key_of(LatheSection, "dialect").names == lathe_names() == ("linuxcnc", "fanuc", "siemens")
    for d in DIALECTS.values():
        assert d.comments.style in d.comments.reads and d.subprograms.structure in ("o_words", "labels", "numbered")
        assert (d.probing is not None) == (d.name in ("linuxcnc", "fanuc", "haas"))  # probe.<ext> (docs/probing.md)
        assert len(d.ignored_words) == len(set(d.ignored_words)) and d.ignored_words.isupper()
    assert [d.name for d in DIALECTS.values() if d.rs274_checkable] == ["linuxcnc"]
    assert dialect(ACME) is ACME and lathe_dialect(ACME) is ACME and lathe_extension(ACME) == "acm"


# --- a dialect defined only here, through both posts and the reader -----------------------------------------


@pytest.fixture(scope="module")
def finishing():
    spec = spec_of("shifted_z12")
    _, tool = tools_for("shifted_z12")
    return finishing_toolpath(spec, tool, Machine(), FinishingParams(strategy="perimeter", target_scallop_mm=0.005,
                                                                     step_over_mm=spec.face_width_mm / 2),
                              spec.tip_radius_mm + 0.5)


def _written(moves) -> list[tuple[bool, np.ndarray]]:
    """The reader's moves as (rapid, pose) for tests.test_post.assert_same_moves."""
    poses = np.column_stack([moves.x, moves.y, moves.z, moves.a])
    return list(zip(moves.rapid.tolist(), poses))


@pytest.mark.parametrize("folded", [True, False], ids=["folded", "flat"])
def test_a_new_dialect_is_written_and_read_back_from_its_table_entry_alone(finishing, folded):
    posted = post_program(finishing, PostSettings(folded=folded), INFO, dialect=ACME)
    lines = posted.text.splitlines()
    assert posted.extension == "acm" and lines[0] == "O1000" and lines[1] == "(SPUR_CAD TEST [NEW DIALECT])"
    assert "%" not in lines and max(map(len, lines)) <= 100
    assert (posted.subprograms > 0 and any(line.startswith("G65 P1001 ") for line in lines)) == folded
    assert_same_moves(_written(read_program(posted.text, ACME, "new.acm")), finishing, 3, 3)


def test_a_new_dialects_direction_codes_turn_a_wrapped_program(finishing):
    text = post_program(finishing, PostSettings(folded=False, rotary_mode="wrapped"), INFO, dialect=ACME).text
    assert " M15" in text and " M16" in text
    moves = read_program(text, ACME, "new.acm")  # the reader turns A the way the dialect's direction codes say
    assert moves.a.min() < 0.0 or moves.a.max() >= 360.0  # unwound, where the written A (in [0, 360)) cannot be
    assert_same_moves(_written(moves), finishing, 3, 3, wrapped=True)
    with pytest.raises(ProgramReadError, match="M1[56] is not supported by this reader"):
        read_program(text, FANUC, "fanuc.nc")  # Fanuc has no direction codes


def test_a_new_dialect_is_nowhere_registered(finishing):
    text = post_program(finishing, PostSettings(), INFO, dialect=ACME).text
    with pytest.raises(ProgramReadError, match="unknown dialect 'acme'"):
        read_program(text, "acme")
    with pytest.raises(PostError, match="dialect = 'acme' is not known"):
        post_program(finishing, PostSettings(dialect="acme"), INFO)
    with pytest.raises(LatheError, match=r"dialect = 'acme' is not known \(known: linuxcnc, fanuc, siemens\)"):
        lathe_extension("acme")
    assert "acme" not in DIALECTS and isinstance(ACME, Dialect)


def test_a_new_dialects_lathe_words_write_and_read_the_blank_program():
    job = load_job(ROOT / "resources/examples/reference_gear.toml")
    lathe = LatheSection(dialect="fanuc")
    plan = plan_lathe(job.gear, job.stock, lathe)
    text = post_lathe(plan, lathe, job.job.name, ("blank",), dialect=ACME)
    lines = text.splitlines()
    assert lines[0] == "O2000" and lines[1].startswith("(") and "%" not in lines and "T0101" in lines
    blocks = [line for line in lines[1:] if not line.startswith("(")]
    fanuc = post_lathe(plan, lathe, job.job.name, ("blank",)).splitlines()
    assert blocks == [line for line in fanuc[2:-1] if not line.startswith("(")]  # Fanuc's blocks, in Acme's frame
    moves = read_program(text, ACME, "blank.acm", lathe=True)
    want = [(m.rapid, m.x, m.z) for m in plan.moves]
    assert len(moves) == len(want)
    assert np.allclose(np.column_stack([moves.x, moves.z]), np.array([w[1:] for w in want]), atol=1.5e-3, rtol=0)
    assert np.array_equal(moves.rapid, [w[0] for w in want])
    without = replace(ACME, name="acme_mill", lathe=None)
    with pytest.raises(ProgramReadError, match=r"no lathe dialect 'acme_mill' \(known: linuxcnc, fanuc, siemens\)"):
        read_program(text, without, lathe=True)
    with pytest.raises(LatheError, match="dialect = 'acme_mill' is not known"):
        post_lathe(plan, lathe, job.job.name, dialect=without)



# --- the documents that list the controllers follow the registry ----------------------------------------------


def _table_rows(document: str, first_row: str) -> list[list[str]]:
    """The cells of the markdown table of `document` whose first line starts with `first_row`."""
    lines = (ROOT / document).read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(first_row))
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip().strip("|").split("|")])
    return rows


def test_the_documents_name_every_dialect_of_the_registry():
    """docs/post.md's table has one column per dialect, in the registry's order, titled and filed as the table
    says; docs/verification.md's reader table a row per dialect; docs/lathe.md a column per lathe dialect; the
    README and docs/usage.md name every controller. A dialect added to the registry fails here until they do."""
    post = _table_rows("docs/post.md", "| | LinuxCNC |")
    assert post[0][1:] == [d.title for d in DIALECTS.values()]
    files = next(row for row in post if row[0] == "file")[1:]
    assert [cell.split(",")[0] for cell in files] == [f"`.{d.extension}`" for d in DIALECTS.values()]
    assert [("%" in cell) for cell in files] == [d.percent_delimited for d in DIALECTS.values()]
    reader = _table_rows("docs/verification.md", "| dialect | subprograms")
    assert [row[0] for row in reader[2:]] == [f"`{name}`" for name in DIALECTS]
    lathe = _table_rows("docs/lathe.md", "| | Siemens 840D")
    lathe_titles = lathe[0][1:]
    assert len(lathe_titles) == len(lathe_names()) and all(
        any(title.startswith(DIALECTS[name].title) for title in lathe_titles) for name in lathe_names())
    for document in ("README.md", "docs/usage.md"):
        text = " ".join((ROOT / document).read_text(encoding="utf-8").split())
        assert all(d.title.split()[0] in text for d in DIALECTS.values()), document


def test_every_dialect_has_its_hand_written_golden_program_and_decimals():
    """The test tables written from the manuals (independent of the table, so never derived from it) cover the
    registry: a golden program per dialect (tests/test_post_golden.py) and its decimals (tests/test_post.py)."""
    from tests.test_post import DECIMALS
    from tests.test_post_golden import GOLDEN

    assert set(GOLDEN) == set(DIALECTS) == set(DECIMALS)
    assert all(DECIMALS[d.name] == (d.linear_decimals, d.rotary.decimals) for d in DIALECTS.values())
