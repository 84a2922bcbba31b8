"""2-D export for wire EDM, laser and waterjet: the gear's outline as DXF and SVG bytes (docs/geometry.md).

Loops are `Outline2D`s (spur_cad.geometry.outline2d) on named layers: OUTLINE (the gear's toothed outline)
and BORE (the bore, with its keyway), each offset by the job's `offset_mm` away from the material (the
wire's, or the kerf's, centre path). The writers know nothing of gears: any closed loops plug in (an
internal gear's ring is its rim circle and its toothed inner loop).

DXF: one closed LWPOLYLINE with arc bulges per loop, R2000, units mm ($INSUNITS = 4); the bytes are
deterministic (the header's times and GUIDs and ezdxf's own time stamps are fixed after writing).
SVG: one path of M/A/L commands per loop, written with the standard library, in mm.
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass
from xml.sax.saxutils import escape, quoteattr

from spur_cad.errors import SpurCadError
from spur_cad.geometry.outline2d import (
    Arc2D,
    Line2D,
    Outline2D,
    Segment2D,
    gear_outline_arcs,
    internal_gear_outline_arcs,
    offset_outline,
)
from spur_cad.geometry.spec import GearSpec

OUTLINE_LAYER = "OUTLINE"
BORE_LAYER = "BORE"
DXF_VERSION = "R2000"  # LWPOLYLINE's first version; its CLASSES section has a fixed order (R2004+ follow a set's)
_FIXED_DATE_JULIAN = "2451544.5"  # 2000-01-01 00:00
_FIXED_GUID = "{00000000-0000-0000-0000-000000000000}"
_TIME_VARIABLES = {"$TDCREATE", "$TDUCREATE", "$TDUPDATE", "$TDUUPDATE"}
_GUID_VARIABLES = {"$FINGERPRINTGUID", "$VERSIONGUID"}
_EZDXF_STAMP = re.compile(r"\d+\.\d+\.\d+(\S*)? @ \d{4}-\d\d-\d\dT[0-9:.]+(\+00:00)?")  # ezdxf's "version @ time"


class ExportError(SpurCadError, ValueError):
    """The outline cannot be exported as asked (an offset that breaks it, a helical gear); names the key."""


@dataclass(frozen=True)
class Layer:
    """Closed loops drawn on one named layer."""

    name: str
    loops: tuple[Outline2D, ...]


def bore_loop(bore_diameter_mm: float, keyway_width_mm: float = 0.0, keyway_depth_mm: float = 0.0) -> Outline2D:
    """The bore as a clockwise loop (material on its left), with the hub keyway on the +z side (under tooth space 0,
    as in spur_cad/cad/solid.py): its sides at y = +-width/2, its top at bore radius + depth."""
    r = bore_diameter_mm / 2.0
    if keyway_width_mm <= 0.0:
        return Outline2D((Arc2D((0.0, r), (0.0, r), (0.0, 0.0), False),))
    half = keyway_width_mm / 2.0
    foot = math.sqrt(r * r - half * half)
    top = r + keyway_depth_mm
    right, left = (half, foot), (-half, foot)
    return Outline2D((Arc2D(right, left, (0.0, 0.0), False), Line2D(left, (-half, top)),
                      Line2D((-half, top), (half, top)), Line2D((half, top), right)))


def gear_layers(spec: GearSpec, tolerance_mm: float, offset_mm: float, bore_diameter_mm: float = 0.0,
                keyway_width_mm: float = 0.0, keyway_depth_mm: float = 0.0) -> tuple[Layer, ...]:
    """A spur gear's layers: OUTLINE (an internal gear's: the rim and the toothed inner loop), and BORE when it has
    a bore, offset by offset_mm away from the
    material (ExportError at offset_mm where the offset breaks a loop)."""
    loops: dict[str, tuple[Outline2D, ...]]
    if spec.kind.has_rim:  # the rim circle and the toothed inner outline, both on OUTLINE
        loops = {OUTLINE_LAYER: internal_gear_outline_arcs(spec, tolerance_mm)}
    else:
        loops = {OUTLINE_LAYER: (gear_outline_arcs(spec, tolerance_mm),)}
    if bore_diameter_mm > 0.0:
        loops[BORE_LAYER] = (bore_loop(bore_diameter_mm, keyway_width_mm, keyway_depth_mm),)
    layers = []
    for name, group in loops.items():
        try:
            layers.append(Layer(name, tuple(offset_outline(loop, offset_mm) for loop in group)))
        except ValueError as exc:
            what = "the gear's outline" if name == OUTLINE_LAYER else "the bore"
            raise ExportError(f"[export] offset_mm = {offset_mm:g}: {what}: {exc}", field="offset_mm",
                              section="export") from None
    return tuple(layers)


# --- DXF -----------------------------------------------------------------------------------------

def _pieces(segment: Segment2D) -> list[tuple[tuple[float, float], float]]:
    """(start, bulge) of a segment, an arc of more than half a turn split in two (a full circle needs that)."""
    if isinstance(segment, Line2D):
        return [(segment.start_xy, 0.0)]
    sweep = segment.sweep_rad
    if abs(sweep) <= math.pi:
        return [(segment.start_xy, math.tan(sweep / 4.0))]
    return [(segment.start_xy, math.tan(sweep / 8.0)), (segment.point_at(0.5), math.tan(sweep / 8.0))]


def loop_vertices(loop: Outline2D) -> list[tuple[float, float, float]]:
    """(x, y, bulge) of a loop's closed LWPOLYLINE: bulge = tan(sweep / 4), positive counter-clockwise."""
    return [(p[0], p[1], bulge) for segment in loop.segments for p, bulge in _pieces(segment)]


def dxf_bytes(layers: tuple[Layer, ...]) -> bytes:
    """The layers as a DXF drawing (see the module doc); the same layers give the same bytes."""
    import ezdxf  # loaded only when a DXF is written

    doc = ezdxf.new(DXF_VERSION, setup=False)
    doc.units = ezdxf.units.MM
    doc.header["$INSUNITS"] = ezdxf.units.MM
    doc.header["$MEASUREMENT"] = 1  # metric
    msp = doc.modelspace()
    for color, layer in enumerate(layers, start=1):
        doc.layers.add(layer.name, color=color)
        for loop in layer.loops:
            points = [(x, y, 0.0, 0.0, bulge) for x, y, bulge in loop_vertices(loop)]
            msp.add_lwpolyline(points, format="xyseb", close=True, dxfattribs={"layer": layer.name})
    stream = io.StringIO()
    doc.write(stream)
    return _fixed_metadata(stream.getvalue()).encode("ascii")


def _fixed_metadata(text: str) -> str:
    """The DXF text with the times, GUIDs and ezdxf stamps that change from run to run replaced by constants
    (tag pairs: a group code line, then its value line)."""
    lines = text.split("\n")
    for i in range(0, len(lines) - 3, 2):
        if lines[i].strip() != "9":
            continue
        name = lines[i + 1]
        if name in _TIME_VARIABLES:
            lines[i + 3] = _FIXED_DATE_JULIAN
        elif name in _GUID_VARIABLES:
            lines[i + 3] = _FIXED_GUID
    return "\n".join(_EZDXF_STAMP.sub("spur_cad", line) if "@" in line else line for line in lines)


# --- SVG -----------------------------------------------------------------------------------------

def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _svg_point(p: tuple[float, float]) -> str:
    """Part (y, z) to SVG (x, y): SVG's y axis points down."""
    return f"{_number(p[0])} {_number(-p[1])}"


def svg_path(loop: Outline2D) -> str:
    """A loop as SVG path data: M, then L for lines and A for arcs (at most half a turn each), Z."""
    parts = [f"M {_svg_point(loop.segments[0].start_xy)}"]
    for segment in loop.segments:
        if isinstance(segment, Line2D):
            parts.append(f"L {_svg_point(segment.end_xy)}")
            continue
        r = _number(segment.radius_mm)
        # SVG's sweep flag 1 runs its angle up in its own (y down) axes: clockwise in ours, whose y points up
        sweep_flag = 0 if segment.counterclockwise else 1
        ends = [segment.end_xy] if abs(segment.sweep_rad) <= math.pi else [segment.point_at(0.5), segment.end_xy]
        parts.extend(f"A {r} {r} 0 0 {sweep_flag} {_svg_point(end)}" for end in ends)
    parts.append("Z")
    return " ".join(parts)


def svg_bytes(layers: tuple[Layer, ...], title: str, margin_mm: float = 1.0) -> bytes:
    """The layers as an SVG drawing in mm (one <g> per layer, one <path> per loop); `title` is escaped."""
    xs, ys = [], []
    for layer in layers:
        for loop in layer.loops:
            for segment in loop.segments:
                for t in (0.0, 0.25, 0.5, 0.75):
                    x, y = segment.point_at(t)
                    xs.append(x)
                    ys.append(-y)
    left, top = min(xs) - margin_mm, min(ys) - margin_mm
    width, height = max(xs) - min(xs) + 2 * margin_mm, max(ys) - min(ys) + 2 * margin_mm
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{_number(width)}mm" height="{_number(height)}mm" '
           f'viewBox="{_number(left)} {_number(top)} {_number(width)} {_number(height)}">',
           f"<title>{escape(title)}</title>"]
    for layer in layers:
        out.append(f'<g id={quoteattr(layer.name)} fill="none" stroke="black" stroke-width="0.02">')
        out.extend(f'<path d="{svg_path(loop)}"/>' for loop in layer.loops)
        out.append("</g>")
    out.append("</svg>")
    return ("\n".join(out) + "\n").encode("utf-8")
