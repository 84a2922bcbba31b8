"""docs/job-file.md, generated from the job-file keys' declarations (spur_cad.keys.key fields of the section
dataclasses of spur_cad.job, and of the finishing strategies' parameters): `python -m spur_cad.keydocs >
docs/job-file.md`. A test fails when the committed file differs from what the declarations generate."""

from __future__ import annotations

import re
import sys

from spur_cad.cam.strategies import REGISTRY, Strategies
from spur_cad.job import MODIFICATION_SECTIONS, job_sections
from spur_cad.keys import keys_of, toml_literal

_DOC_INTRO = """\
# Job file reference

<!-- Generated from the key declarations (spur_cad.keys.key fields of the section dataclasses) by
     `python -m spur_cad.keydocs > docs/job-file.md`; edit those, not this file. -->

A job file is TOML. Units are in key names. Unknown sections or keys, wrong types,
missing required keys and values outside the accepted range are errors naming the key and the
line. Without `[tools.*]` the job stops after the CAD stage (tool recommendations are still
reported, no G-code is written).

Every number must be finite (`nan` and `inf` are rejected) and inside its range: `[a, b]`
includes both ends, `(a, b]` excludes a; `a..b` is a range of whole numbers. An integer is
accepted where a number is expected; `true`/`false` only where a flag is. The last column names
the FreeCAD workbench's property holding the key (see [workbench.md](workbench.md)).

Side files: a file the job names (`[job] report_template`, `[machine] rotary_calibration_file`) is named
relative to the job file and must lie in the job file's folder or below it, or in a folder named with
`spur-cad run --side-files DIR` (also `verify`, `grade`, `correct`; DIR is searched after the job's folder). An
absolute name, or a `..` or a symbolic link that leads out of these folders, is refused with one line, whatever
the file holds. In the workbench the saved document's folder takes the job file's place. A report template
renders within bounds (time, size of the page and of its values, loops, recursion): [report.md](report.md).
"""

_DOC_NOTES = """\
Notes:

- `[gear] thickness_allowance_percent` thins the nominal tooth thickness on the reference
  circle by that percentage (the reference process's "profile clearance", 0-5 %);
  `thickness_allowance_mm` subtracts a further absolute amount (see [geometry.md](geometry.md)).
  The gear itself must be cuttable by rack generation: `rack_tip_radius_mm` at most 0.6 x module,
  `thickness_allowance_mm` at most 0.5 x module, a positive root radius, no pointed tooth.
- `[gear] bore_diameter_mm`, `keyway_width_mm`, `keyway_depth_mm` (0 = none): a through bore and
  a hub keyway on the bore's +Z side (under tooth space 0); depth is measured from the bore
  surface. At least one module of wall must remain under the root circle; a keyway needs a bore
  and both its width (below the bore diameter) and depth.
- `[stock]`: the blank is a cylinder of tip radius + `radial_allowance_mm` from
  X = -`front_margin_mm` to face width + `back_margin_mm`; a holding stub (`stub_diameter_mm`,
  `stub_length_mm`, both or neither, not wider than the blank) continues it toward the chuck (+X).
- `[tools.*]`: `flute_length_mm` / `stick_out_mm` of 0 mean "not given"; when given they are
  checked against what the job needs (summary `tools.required_flute_length_mm`,
  `tools.required_stick_out_mm`). See [cam.md](cam.md) for every limit.
- `[roughing] finish_stock_mm` must be below `flank_allowance_mm`.
- `[machine]` travel limits: each low limit must be below its high limit.
  `rotary_clamp_code` / `rotary_unclamp_code` are needed when `[roughing] clamp_rotary`
  is true; `rotary_continuous = false` makes finishing unwind A after every station.
- `[post] folded = true` needs `rotary_mode = "unwound"`.
- `[stock] blank_diameter_mm` (the blank as turned) replaces tip diameter + 2 x
  `radial_allowance_mm`; it may not be below the tip diameter, and the blank may stand at most
  0.5 x the finishing tool's diameter (a slot's depth) above the tip circle.
- `[machine]` physical limits (`max_part_diameter_mm`, `max_part_weight_kg`, `max_overhang_mm`,
  `spindle_nose_top_mm`; 0 = not checked) are errors naming the limit; tools below
  `smallest_end_mill_mm` are warnings (see [shop-floor.md](shop-floor.md)).
- `[tools.bottom]`: two-stage roughing, a flat end mill smaller than `[tools.roughing]` for the
  bottom of the spaces (T3 when it gives no number); the split is chosen for the shortest time
  unless `[roughing] bottom_tool_above_root_mm` sets it (by flanks: the larger tool takes all it
  reaches). Roughing uses the quicker of two-stage roughing and the smaller tool alone.
- `[tools.roughing_top]`: the same pair the other way round, a flat end mill larger than
  `[tools.roughing]` for the upper part of the spaces (T4 when it gives no number); not with
  `[tools.bottom]`. Where two-stage roughing cannot be planned with it, `[tools.roughing]` roughs
  alone (a warning says why).
- `[lathe]`: with the section the blank's lathe program `blank.<ext>` is written too (see
  [lathe.md](lathe.md)).
- `[export]`: `dxf = true` / `svg = true` write `gear.dxf` / `gear.svg`, the gear's transverse
  outline as closed loops of arcs and lines (root and tip arcs exact, fillet and involute by
  tangent-continuous biarcs within `[job] profile_tolerance_mm`): layer `OUTLINE`, and `BORE` (the
  bore with its keyway) when `[gear]` has a bore. `offset_mm` moves every loop away from the material
  (outside the gear, into the bore) exactly, arcs to concentric arcs, so a positive value is the wire
  or beam centre's path: wire radius plus spark gap for wire EDM, half the kerf for laser and waterjet;
  0 writes the part's outline for a machine that compensates itself. An offset at or above the root
  fillet's smallest curvature radius is refused (the cut would round the fillet off), as is one that
  breaks a loop. Helical gears are refused (a wire cuts straight teeth only). See
  [geometry.md](geometry.md).
"""

_TYPE_WORDS = {float: "number", int: "integer", bool: "boolean", str: "string"}


def _doc_text(text: str) -> str:
    """Docstring or meaning text for markdown: docs/<name>.md becomes a link."""
    return re.sub(r"docs/([\w-]+\.md)", r"[\1](\1)", text)


def _section_summary(cls: type) -> str:
    """The first paragraph of a section dataclass's docstring, without its '[section]: ' prefix."""
    first = " ".join(line.strip() for line in (cls.__doc__ or "").strip().split("\n\n")[0].splitlines())
    first = re.sub(r"^\[[^\]]+\](\s*/\s*\[[^\]]+\])*:\s*", "", first)
    return _doc_text(first[:1].upper() + first[1:])


def _accepted(k) -> str:
    if k.type is bool:
        return "`true`, `false`"
    if k.names:
        return ", ".join(f"`{n}`" for n in k.names)
    if k.low is not None:
        text = k.interval()
        return text.removesuffix(f" {k.unit}") if k.unit else text
    return "any"


def job_file_reference_markdown(strategies: Strategies = REGISTRY) -> str:
    """docs/job-file.md: the introduction, one table per section from its key declarations (the [finishing]
    keys from the strategies of `strategies`), the notes."""
    sections = {}
    for name, cls in job_sections(strategies).items():
        sections[name] = cls
        if name == "gear":  # the flank modification tables follow [gear]
            sections.update(MODIFICATION_SECTIONS)
    parts = [_DOC_INTRO]
    done: set[type] = set()
    for cls in sections.values():
        if cls in done:
            continue
        done.add(cls)
        names = [n for n, c in sections.items() if c is cls]
        parts.append(f"## {' / '.join(f'[{n}]' for n in names)}\n\n{_section_summary(cls)}\n")
        if len(names) > 1 and any("{Role}" in k.label for k in keys_of(cls)):
            roles = " or ".join(n.split(".")[-1].capitalize() for n in names)
            parts.append(f"In the workbench property names, `{{Role}}` is {roles}.\n")
        if cls in MODIFICATION_SECTIONS.values():
            parts.append("In the workbench these are the gear's properties: [gear.modifications] in the group Flank "
                         "modifications; a side's table is `LeftFlankOwnValues` / `RightFlankOwnValues` switched on "
                         "and the `Left...` / `Right...` properties (switched on, they start from the common values; "
                         "the side's table writes only the keys that differ from them and inherits the rest, key by "
                         "key as here; switched off: the common values).\n")
        rows = ["| key | type | unit | default | accepted | meaning | workbench property |",
                "| --- | --- | --- | --- | --- | --- | --- |"]
        for k in keys_of(cls):
            default = "**required**" if k.required else f"`{toml_literal(k.default)}`"
            holder = (f"`{k.label}`, `Left{k.label}`, `Right{k.label}`" if cls in MODIFICATION_SECTIONS.values()
                      else f"`{k.label}`")
            rows.append(f"| `{k.name}` | {_TYPE_WORDS[k.type]} | {k.unit or '-'} | {default} | {_accepted(k)} | "
                        f"{_doc_text(k.meaning)} | {holder} |")
        parts.append("\n".join(rows) + "\n")
    parts.append(_DOC_NOTES)
    return "\n".join(parts)


def main(argv: list[str] | None = None) -> int:
    """`python -m spur_cad.keydocs`: print docs/job-file.md."""
    argv = sys.argv[1:] if argv is None else argv
    if argv:
        print("usage: python -m spur_cad.keydocs > docs/job-file.md", file=sys.stderr)
        return 2
    sys.stdout.write(job_file_reference_markdown())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
