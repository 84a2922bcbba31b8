"""README.md is the first screen: it opens with the two commands a new user runs, says where to look next, and
every relative link in it and in the user's guide (docs/) leads to a file that exists."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINK = re.compile(r"\]\(([^)\s#]+)(?:#[^)\s]*)?\)")


def test_the_readme_opens_with_make_demo_and_make_test():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    first_block = re.search(r"```sh\n(.*?)```", text, re.S)
    assert first_block is not None and text.split("\n\n")[1].startswith("```sh")  # right under the title
    commands = [line.split("#")[0].strip() for line in first_block.group(1).splitlines()]
    assert commands == ["make demo", "make test"]
    # the Makefile really has both targets, and demo writes the report the README points to
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert re.search(r"^demo:", makefile, re.M) and re.search(r"^test:", makefile, re.M)
    assert "--out out/" in makefile and "out/report.html" in text


def test_the_readme_first_screen_is_one_screen():
    """What spur_cad does, needs and where to go next fit before the first section heading (a 50-line screen)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    first_section = text.find("\n## ")
    assert first_section > 0 and text[:first_section].count("\n") <= 50


@pytest.mark.parametrize("document", ["README.md", *sorted(p.relative_to(ROOT).as_posix()
                                                           for p in (ROOT / "docs").glob("*.md"))])
def test_relative_links_lead_to_files_that_exist(document):
    path = ROOT / document
    missing = [target for target in LINK.findall(path.read_text(encoding="utf-8"))
               if not target.startswith(("http://", "https://", "mailto:"))
               and not (path.parent / target).exists()]
    assert missing == [], f"{document} links to missing files: {missing}"
