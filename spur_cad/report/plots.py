"""Static figures rendered to PNG bytes with matplotlib's object API (no global pyplot state)."""

from __future__ import annotations

import io

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from spur_cad.geometry.profile import SEGMENT_LABELS
from spur_cad.geometry.sampling import ProfileSamples
from spur_cad.geometry.spec import GearSpec

SEGMENT_COLOURS = {"root": "#1f77b4", "fillet": "#d62728", "involute": "#2ca02c", "tip": "#9467bd"}


PNG_DPI = 120
"""The report figures' resolution: they are made at it, so drawing them for the PNG changes no size."""


def figure(width_in: float, height_in: float, left: float = 0.1, right: float = 0.97, bottom: float = 0.09,
           top: float = 0.94) -> Figure:
    """A figure with fixed margins (fractions of its size): matplotlib's constrained layout measured every
    label of every figure again and cost about half a second per report."""
    fig = Figure(figsize=(width_in, height_in), dpi=PNG_DPI)
    fig.subplots_adjust(left=left, right=right, bottom=bottom, top=top)
    return fig


def figure_for_extent(width_in: float, x_range: float, y_range: float,
                      margins_in: tuple[float, float, float, float] = (0.75, 0.15, 0.6, 0.4),
                      largest_height_in: float = 9.0) -> Figure:
    """A figure for one equal-aspect plot of data `x_range` wide and `y_range` tall: the height follows the
    data (no band of empty space above and below), margins (left, right, bottom, top) fixed in inches."""
    left, right, bottom, top = margins_in
    axes_height_in = (width_in - left - right) * y_range / max(x_range, 1e-9)
    height_in = min(axes_height_in + bottom + top, largest_height_in)
    return figure(width_in, height_in, left=left / width_in, right=1.0 - right / width_in, bottom=bottom / height_in,
                  top=1.0 - top / height_in)


def set_title(ax: Axes, text: str, fontsize: float) -> None:
    """The axes' title at matplotlib's default place above the plot, fixed there: left automatic, every draw
    measures the y axis's tick labels again to dodge a top axis or offset text that these plots do not have."""
    ax.set_title(text, fontsize=fontsize, y=1.0)


def _png(fig: Figure) -> bytes:
    """The figure drawn at PNG_DPI as PNG bytes."""
    if fig.dpi != PNG_DPI:
        fig.set_dpi(PNG_DPI)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return png_bytes(np.asarray(canvas.buffer_rgba())[..., :3], PNG_DPI)


def png_bytes(rgb: np.ndarray, dpi: float) -> bytes:
    """An opaque image (height x width x 3, uint8) as PNG by Pillow at zlib level 1: three channels, not
    savefig's four (a plot has no transparency), which Pillow filters and compresses in 35 ms instead of 42 for a
    large figure."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8)).save(buffer, "PNG", compress_level=1, dpi=(dpi, dpi))
    return buffer.getvalue()


MODIFIED_COLOUR = "#ff7f0e"
MODIFIED_SHARE_OF_DEPTH = 0.04
"""A modified gear's plotted removal is magnified so that its largest amount shows as about this share of the
tooth depth (micrometres would not show on a millimetre plot)."""


def removal_magnification(spec: GearSpec, largest_removal_mm: float) -> float:
    """A round factor (1, 2 or 5 x 10^n) showing `largest_removal_mm` as about 4 % of the tooth depth."""
    wanted = MODIFIED_SHARE_OF_DEPTH * (spec.tip_radius_mm - spec.root_radius_mm) / max(largest_removal_mm, 1e-9)
    decade = 10.0 ** np.floor(np.log10(wanted))
    return float(max(step * decade for step in (1.0, 2.0, 5.0) if step * decade <= wanted))


def _plot_modified_flanks(ax: Axes, spec: GearSpec, flanks: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
    """The modified flanks (`flanks`: side -> (modified points, unmodified points), right-half gap frame) with their
    removal magnified; the left side drawn mirrored."""
    largest = max(float(np.linalg.norm(modified - design, axis=1).max()) for modified, design in flanks.values())
    factor = removal_magnification(spec, largest)
    for side, (modified, design) in flanks.items():
        shown = design + factor * (modified - design)
        mirror = -1.0 if side == "left" else 1.0
        ax.plot(mirror * shown[:, 0], shown[:, 1], "--", color=MODIFIED_COLOUR, lw=1.4, zorder=3,
                label=f"modified at mid-face (removal x {factor:g})" if side == "right" else None)


def tooth_space_png(spec: GearSpec, samples: ProfileSamples, modified_flanks: dict | None = None) -> bytes:
    """The tooth space (right half as sampled, left half mirrored), segments coloured, key circles dashed; with
    `modified_flanks` (side -> (modified points, unmodified points)) a modified gear's flanks over it, their
    removal magnified."""
    fig = figure(8.0, 5.5, left=0.08, right=0.86, bottom=0.09, top=0.94)  # room for the circles' names
    ax = fig.add_subplot(1, 1, 1)
    if modified_flanks:
        _plot_modified_flanks(ax, spec, modified_flanks)
    for index, label in enumerate(SEGMENT_LABELS):
        mask = samples.labels == index
        if not mask.any():
            continue
        # Include the previous point so segments join up on the plot.
        idx = np.nonzero(mask)[0]
        idx = np.concatenate([[max(idx[0] - 1, 0)], idx])
        pts = samples.points[idx]
        colour = SEGMENT_COLOURS[label]
        ax.plot(pts[:, 0], pts[:, 1], "-", color=colour, lw=2.0, label=label)
        ax.plot(-pts[:, 0], pts[:, 1], "-", color=colour, lw=2.0)
    half_angle = np.pi / spec.teeth
    span = np.linspace(-1.3 * half_angle, 1.3 * half_angle, 200)
    profile = spec.tooth_space_profile()
    circles = sorted((("tip", spec.tip_radius_mm), ("reference", spec.reference_radius_mm),
                      ("base", spec.base_radius_mm), ("form", profile.form_radius_mm),
                      ("root", spec.root_radius_mm))
                     + ((("SAP (mate)", spec.active_profile_start_diameter_mm / 2.0),)
                        if spec.active_profile_start_diameter_mm > 0.0 else ()), key=lambda item: -item[1])
    label_gap = 0.045 * (spec.tip_radius_mm - spec.root_radius_mm + 1.0)  # labels of close circles kept apart
    label_y = np.inf
    for name, radius in circles:  # top down, each label at least label_gap below the one above it
        ax.plot(radius * np.sin(span), radius * np.cos(span), ":", color="0.6", lw=0.8)
        end_y = radius * np.cos(span[-1])
        label_y = min(end_y, label_y - label_gap)
        ax.annotate(f"{name} r = {radius:.3f} mm", (radius * np.sin(span[-1]), end_y), xytext=(
            radius * np.sin(span[-1]), label_y), fontsize=7, color="0.4", va="center")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm] (space axis)")
    title = (f"z={spec.teeth}  m={spec.module_mm:g}  alpha={spec.pressure_angle_deg:g} deg  "
             f"x={spec.profile_shift_coefficient:g}"
             f"  rho={spec.rack_tip_radius_mm:g} mm" + ("  UNDERCUT" if profile.undercut else ""))
    set_title(ax, title, 9)
    ax.legend(loc="lower center", fontsize=8, ncols=4)  # below the root: the tip circle stays visible
    ax.grid(True, lw=0.3)
    return _png(fig)
