"""How the program reader (spur_cad.verify.reader) takes a program's text apart: a line cleaned of comments and
block number, the dialect's syntax in flat fields, lines read by byte offset, and the one pass over the file
that checks every line and finds where the main program ends and where every subprogram, loop and label is."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import BinaryIO

from spur_cad.dialects import Dialect
from spur_cad.errors import SpurCadError, shown
from spur_cad.verify.limits import MAX_LINE_CHARS, MAX_LINES, MAX_SUBPROGRAMS


class ProgramReadError(SpurCadError):
    """A program this reader cannot execute: the message names the file, the line and what is wrong."""


@dataclass
class Line:
    number: int  # 1-based line in the file
    text: str  # without comments and block number
    offset: int = 0  # byte offset of the line in the file


Position = tuple[int, int]  # (byte offset of a line's start, number of lines before it)
OpenSubprogram = tuple[re.Match, Position, int]  # a subprogram's head, its body's start and its line number

_ENDS = re.compile(r"(^|\s)M0*(30|2)(\s|$)")  # M30 or M2, anywhere in a block
_COMMENT = re.compile(r"\([^)]*\)")
_BLOCK_NUMBER = re.compile(r"^N\d+\s*")
_HAAS_LOCAL = re.compile(r"N\d+")
_CANDIDATE = re.compile(rb"[OoMm:]")  # what a line needs to hold to end the program or open a structure
LINUXCNC_SUB = re.compile(r"O(\d+)\s*SUB")
_LINUXCNC_ENDSUB = re.compile(r"O(\d+)\s*ENDSUB")
LINUXCNC_REPEAT = re.compile(r"O(\d+)\s*REPEAT\s*\[([^\]]*)\]")
_LINUXCNC_ENDREPEAT = re.compile(r"O(\d+)\s*ENDREPEAT")
LABEL = re.compile(r"[A-Z_][A-Z0-9_]*:")
_SUB_HEAD = re.compile(r"O(\d+)|N(\d+)")


@dataclass(frozen=True, slots=True)
class Syntax:
    """What reading every line needs from the dialect table (spur_cad.dialects), in flat fields."""

    paren: bool  # ( ... ) is a comment
    semicolon: bool  # ; starts a comment to the end of the line
    local_labels: bool  # a line N<n> heads a local subprogram (Haas), not a block number
    structure: str  # "o_words", "labels" or "numbered" (Subprograms.structure)
    closing: re.Pattern  # "numbered": the block closing a subprogram

    @classmethod
    def of(cls, d: Dialect) -> "Syntax":
        subs = d.subprograms
        return cls("paren" in d.comments.reads, "semicolon" in d.comments.reads, subs.local_labels,
                   subs.structure, re.compile(subs.closing))


def clean_line(raw: bytes, syntax: Syntax) -> str:
    """A line without comments, block number and surrounding blanks; upper case (LinuxCNC's o-words too);
    '' for a line with nothing to execute ('%' delimits Fanuc and Haas programs)."""
    line = raw.decode("utf-8")  # checked while indexing
    if syntax.paren and "(" in line:
        line = _COMMENT.sub("", line)
    if syntax.semicolon:
        line = line.split(";", 1)[0]
    line = line.strip().upper()
    if line[:1] == "N" and (not syntax.local_labels or not _HAAS_LOCAL.fullmatch(line)):  # N<n> heads a local sub
        line = _BLOCK_NUMBER.sub("", line, count=1)
    return "" if line == "%" else line


class LineSource:
    """The program's lines read by byte offset from a seekable binary file: nothing but the current line and the
    file's buffer is held, however long the program."""

    def __init__(self, handle: BinaryIO) -> None:
        self.handle = handle
        self.at = 0

    def line(self, offset: int) -> tuple[bytes, int]:
        """The raw line starting at `offset` and the offset of the next line."""
        if offset != self.at:
            self.handle.seek(offset)
        raw = self.handle.readline()
        self.at = offset + len(raw)
        return raw, self.at


@dataclass
class Structure:
    """Where the main program ends and where every subprogram, loop and label is (byte offsets and positions)."""

    end: int = -1  # offset just after the main program's last line (its M30 or M2)
    # O<n> (and LinuxCNC o<n> sub): n -> (body start Position, offset of the closing line)
    subs: dict[int, tuple[Position, int]] = field(default_factory=dict)
    local_subs: dict[int, tuple[Position, int]] = field(default_factory=dict)  # Haas N<n> (M97), alike
    skips: dict[int, Position] = field(default_factory=dict)  # LinuxCNC: 'o<n> sub' line's offset -> after 'endsub'
    # LinuxCNC: offset of an 'o<n> repeat' line -> (offset of its 'endrepeat', Position after)
    repeats: dict[int, tuple[int, Position]] = field(default_factory=dict)
    labels: dict[str, tuple[Position, int]] = field(default_factory=dict)  # Siemens: label -> (after, line offset)

    opened: int = 0  # subprograms, loops and labels met (closed or not): bounds what the index holds


def index_program(handle: BinaryIO, syntax: Syntax, source: str) -> Structure:
    """One pass over the file: check every line (UTF-8, no NUL, length, count) and find the structure; linear in
    the file's length (a line that cannot end or open a structure is not even decoded)."""
    found = Structure()
    open_subs: list[tuple[int, Position, int]] = []  # LinuxCNC: (number, body start, line offset)
    open_repeats: dict[int, list[int]] = {}  # LinuxCNC: number -> offsets of its open repeats
    fanuc_family = syntax.structure == "numbered"
    o_words, labels = syntax.structure == "o_words", syntax.structure == "labels"
    closing = syntax.closing
    current_sub: OpenSubprogram | None = None  # Fanuc family after the end: the open subprogram
    offset, number = 0, 0
    for raw in iter(lambda: handle.readline(MAX_LINE_CHARS + 3), b""):  # a line read is bounded too
        number += 1
        here, offset = offset, offset + len(raw)
        _check_raw_line(raw, number, source)
        after_end = found.end >= 0
        if not (after_end and fanuc_family) and not _CANDIDATE.search(raw):
            continue
        text = clean_line(raw, syntax)
        if not text:
            continue
        line = Line(number, text, here)
        if not after_end and _ENDS.search(text):
            found.end = offset
            continue
        if o_words:
            _index_o_words(found, line, (offset, number), open_subs, open_repeats)
        elif labels and LABEL.fullmatch(text):
            found.labels[text[:-1]] = ((offset, number), here)
            found.opened += 1
        elif fanuc_family and after_end:
            current_sub = _index_subprogram(found, line, (offset, number), current_sub, closing, source)
        if found.opened > MAX_SUBPROGRAMS:
            raise line_error(source, line, f"more than {MAX_SUBPROGRAMS:,} subprograms, loops and labels")
    if found.end < 0:
        raise ProgramReadError(f"{source}: no end of program (M30 or M2)")
    if current_sub is not None:
        head, _, first = current_sub
        raise ProgramReadError(f"{source}:{first}: nothing closes this subprogram ({closing.pattern}) "
                               f"(in {shown(head.group(0))})")
    if open_subs:
        sub_number, _, _ = open_subs[-1]
        raise ProgramReadError(f"{source}: nothing closes subprogram o{sub_number} (o{sub_number} endsub)")
    return found


def _check_raw_line(raw: bytes, number: int, source: str) -> None:
    """A line of a text program: bounded length and count, UTF-8, no NUL byte."""
    if len(raw) > MAX_LINE_CHARS + 2:
        raise ProgramReadError(f"{source}:{number}: a line of more than {MAX_LINE_CHARS:,} characters; a "
                               "controller's block is a few hundred at most")
    if number > MAX_LINES:
        raise ProgramReadError(f"{source}: more than {MAX_LINES:,} lines; verify reads at most {MAX_LINES:,}")
    if not raw.isascii():
        try:
            raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ProgramReadError(f"{source}:{number}: not a text file (byte {exc.start + 1} of the line is "
                                   "not UTF-8)") from None
    if b"\x00" in raw:
        raise ProgramReadError(f"{source}:{number}: not a text file (a NUL byte)")


def _index_subprogram(found: Structure, line: Line, after: Position, current_sub: OpenSubprogram | None,
                      closing: re.Pattern, source: str) -> OpenSubprogram | None:
    """Fanuc family after the end of the program: subprograms O<n> (Haas N<n>) ... M99 (Okuma RTS) and nothing
    else; returns the subprogram still open (its head, body start, line number) or None."""
    if current_sub is None:
        head = _SUB_HEAD.fullmatch(line.text)
        if head is None:
            raise line_error(source, line, "a block after the end of the program that is not a subprogram")
        found.opened += 1
        return (head, after, line.number)
    if closing.fullmatch(line.text):
        head, start, _ = current_sub
        target = found.subs if head.group(1) else found.local_subs
        target[int(head.group(1) or head.group(2))] = (start, line.offset)
        return None
    return current_sub


def _index_o_words(found: Structure, line: Line, after: Position, open_subs: list, open_repeats: dict) -> None:
    """LinuxCNC o-word structure, paired with stacks (each opening is closed by the nearest closing of its number)."""
    text = line.text
    if text[:1] != "O":
        return
    if (head := LINUXCNC_SUB.fullmatch(text)) is not None:
        open_subs.append((int(head.group(1)), after, line.offset))
        found.opened += 1
    elif (head := _LINUXCNC_ENDSUB.fullmatch(text)) is not None:
        sub_number = int(head.group(1))
        for i in range(len(open_subs) - 1, -1, -1):
            if open_subs[i][0] == sub_number:
                _, start, opening = open_subs.pop(i)
                found.subs[sub_number] = (start, line.offset)
                found.skips[opening] = after
                break
    elif (head := LINUXCNC_REPEAT.fullmatch(text)) is not None:
        open_repeats.setdefault(int(head.group(1)), []).append(line.offset)
        found.opened += 1
    elif (head := _LINUXCNC_ENDREPEAT.fullmatch(text)) is not None and open_repeats.get(int(head.group(1))):
        found.repeats[open_repeats[int(head.group(1))].pop()] = (line.offset, after)


def line_error(source: str, line: Line, message: str) -> ProgramReadError:
    return ProgramReadError(f"{source}:{line.number}: {message} (in {shown(line.text)})")

