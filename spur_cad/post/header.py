"""The start every program shares, whatever writes it (the milling post, the lathe post, the probing post):
the file frame, the title and the comments (`program_head`), and the setup with the work offset
(`setup_blocks`). One place, so a dialect's frame and its work-offset word are written the same way in every
program (issue 45). User text only ever appears inside one inert comment of bounded length.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from spur_cad.dialects import WORK_OFFSETS, Dialect
from spur_cad.errors import PostError, shown

_ACTIVE_COMMENT = re.compile(r"(msg|debug|print|log\w*|probe\w*|abort|py\w*)\s*,|(probeopen|probeclose|logclose)\b",
                             re.IGNORECASE)
"""Comment words a LinuxCNC interpreter acts on (messages, log files, probe files, aborts, Python); PROBEOPEN takes
its file name after a space, PROBECLOSE and LOGCLOSE take nothing."""

_COMMENT_TRANSLATION = str.maketrans({"(": "[", ")": "]", ";": ",", "%": "?"})


def inert_comment_text(text: str, max_length: int) -> str:
    """User text made safe inside one comment of any dialect: printable ASCII only (white space and line
    breaks become one space, anything else non-printable or non-ASCII becomes '?'), no comment delimiter,
    no '%' (the end of a Fanuc tape), never a comment the control acts on (LinuxCNC's MSG, LOGOPEN,
    ABORT, PY, ...: an '_' goes in front), at most `max_length` characters ('...' marks a cut)."""
    text = re.sub(r"\s+", " ", text)
    text = "".join(c if " " <= c <= "~" else "?" for c in text).translate(_COMMENT_TRANSLATION).strip()
    if _ACTIVE_COMMENT.match(text):  # LinuxCNC acts on (MSG,...), (LOGOPEN,...), (ABORT,...), (PY,...), ...
        text = "_" + text
    return text if len(text) <= max_length else text[:max_length - 3] + "..."


def comment_line(d: Dialect, text: str) -> str:
    """User text as one inert comment line of dialect `d` (its syntax and case, cut to its line limit)."""
    text = inert_comment_text(text, d.max_line_length - 4)
    if d.comments.uppercase:
        text = text.upper()
    return f"({text})" if d.comments.style == "paren" else f"; {text}"


def program_title(d: Dialect, title: str) -> str:
    """The title inside dialect `d`'s program-start block (room left for the O number and the parentheses)."""
    text = inert_comment_text(title, d.max_line_length - 16)
    return text.upper() if d.comments.uppercase else text


def program_head(d: Dialect, number: int, title: str, comments: Sequence[str]) -> list[str]:
    """The program's first lines in dialect `d`: '%' where the dialect delimits its files, the program start
    (program `number`, with the title inside it where its template has one), else the title as the first
    comment, then one inert comment line per item of `comments`."""
    lines = ["%"] if d.percent_delimited else []
    if d.program_start:
        lines.append(d.program_start.format(number=number, title=program_title(d, title)))
    if "{title}" not in d.program_start:
        lines.append(comment_line(d, title))
    return lines + [comment_line(d, text) for text in comments]


def work_offset_word(d: Dialect, work_offset: str) -> str:
    """The block selecting `work_offset` (G54..G59) in dialect `d`: the code itself, or the dialect's form with
    the offset's number 1..6 (Okuma OSP: G15 H1..H6)."""
    if work_offset not in WORK_OFFSETS:
        raise PostError(f"work offset {shown(work_offset)} is not one of {', '.join(WORK_OFFSETS)}",
                        field="work_offset")
    return d.work_offsets.word.format(code=work_offset, number=WORK_OFFSETS.index(work_offset) + 1)


def setup_blocks(d: Dialect, setup: Sequence[str], work_offset: str, workpiece: str = "") -> list[str]:
    """What every program commands before its first tool: the blank for the control's own simulation (when
    `workpiece` is not empty), the `setup` blocks (the milling or the lathe setup of `d`), and the selection of
    `work_offset`."""
    return [*([workpiece] if workpiece else []), *setup, work_offset_word(d, work_offset)]
