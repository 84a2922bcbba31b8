"""The job report's figures (PNG bytes, matplotlib object API): roughing levels, finishing contacts and
cutter locations, the simulated deviation map, the roughing engagement, the flank modification chart."""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

import numpy as np

from spur_cad.geometry.frames import turn_points
from spur_cad.geometry.sampling import full_space_points, sample_profile
from spur_cad.geometry.spec import GearSpec
from spur_cad.report.plots import _png, figure, figure_for_extent, set_title

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    from spur_cad.cam.flank_roughing import FlankPlan
    from spur_cad.cam.tools import Tool
    from spur_cad.geometry.modifications import FlankModifications
    from spur_cad.grade.grading import Grading, Trace
    from spur_cad.sim.engagement import Engagement
    from spur_cad.sim.simulate import SimResult


def _space_outline(spec: GearSpec) -> np.ndarray:
    """Tooth space 0 from tooth centre to tooth centre (machine Y, Z at A = 0)."""
    return full_space_points(sample_profile(spec.tooth_space_profile(), 1e-3 * spec.module_mm))


def _space_axes(spec: GearSpec, blank_radius_mm: float) -> tuple[Figure, Axes]:
    """A roughing figure's axes with the design's tooth space and the blank's arc over it."""
    fig = figure(7.5, 6.0)
    ax = fig.add_subplot(1, 1, 1)
    outline = _space_outline(spec)
    ax.plot(outline[:, 0], outline[:, 1], "-", color="k", lw=1.5, label="design")
    span = np.linspace(-math.pi / spec.teeth, math.pi / spec.teeth, 200)
    ax.plot(blank_radius_mm * np.sin(span), blank_radius_mm * np.cos(span), ":", color="0.5", lw=1, label="blank")
    return fig, ax


def _space_png(fig: Figure, ax: Axes, spec: GearSpec, blank_radius_mm: float, title: str) -> bytes:
    """A roughing figure finished: equal scales from below the root to above the blank, labels, title, legend."""
    ax.set_aspect("equal")
    ax.set_xlabel("Y [mm] (space axis up)")
    ax.set_ylabel("Z [mm]")
    ax.set_ylim(spec.root_radius_mm - 0.5, blank_radius_mm + 1.0)
    set_title(ax, title, 9)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(True, lw=0.3)
    return _png(fig)


def roughing_levels_png(spec: GearSpec, heights_mm: np.ndarray, half_widths_mm: np.ndarray, tool: Tool,
                        blank_radius_mm: float) -> bytes:
    """The tooth space with each roughing level: the tool bottom's reach at that height, the tool drawn at
    both ends of the lowest level."""
    fig, ax = _space_axes(spec, blank_radius_mm)
    radius = tool.diameter_mm / 2.0
    gap = np.full(len(heights_mm), np.nan)  # one line broken between the levels, not a line per level
    ax.plot(np.column_stack([-half_widths_mm, half_widths_mm, gap]).ravel(),
            np.column_stack([heights_mm, heights_mm, gap]).ravel(), "-", color="tab:orange", lw=1.2,
            label="levels (tool edge reach)")
    h, w = heights_mm[-1], half_widths_mm[-1]
    for centre in (-(w - radius), w - radius):
        ax.add_patch(_rectangle(centre - radius, h, tool.diameter_mm, 2.5 * tool.diameter_mm))
    return _space_png(fig, ax, spec, blank_radius_mm,
                      f"roughing: {len(heights_mm)} levels, flat end mill D {tool.diameter_mm:g} mm")


def roughing_flank_png(spec: GearSpec, plan: FlankPlan, tool: Tool, blank_radius_mm: float) -> bytes:
    """The tooth space with the flank strategy's passes: each tool drawn over the depth it cuts, turned back from
    its run's A into the space's frame, a colour per run."""
    fig, ax = _space_axes(spec, blank_radius_mm)
    radius = tool.diameter_mm / 2.0
    colours = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive")
    gap = np.full((1, 2), np.nan)  # a line broken between tools: one line per run, not one per pass
    for run, passes in itertools.groupby(plan.passes, key=lambda p: p.run):
        drawn = []
        for p in passes:
            corners = np.array([[p.y_mm - radius, p.z_mm], [p.y_mm + radius, p.z_mm],
                                [p.y_mm + radius, p.z_mm + p.axial_depth_mm],
                                [p.y_mm - radius, p.z_mm + p.axial_depth_mm], [p.y_mm - radius, p.z_mm]])
            # the machine frame turned back into the space's: R(-turn)
            drawn += [turn_points(corners, -math.radians(p.turn_deg)), gap]
        joined = np.concatenate(drawn)
        ax.plot(joined[:, 0], joined[:, 1], "-", lw=0.7, color=colours[run % len(colours)])
    turns = ", ".join(f"{abs(s.turn_deg):.1f}" for s in plan.segments)
    return _space_png(fig, ax, spec, blank_radius_mm,
                      f"roughing by flanks: {len(plan.passes)} passes per space, A turned +-({turns}) deg, flat end "
                      f"mill D {tool.diameter_mm:g} mm")


def _rectangle(y0: float, z0: float, width: float, height: float) -> Rectangle:
    from matplotlib.patches import Rectangle

    return Rectangle((y0, z0), width, height, fill=False, edgecolor="tab:blue", lw=0.8)


def finishing_png(spec: GearSpec, tool: Tool, y: np.ndarray, z: np.ndarray, a_deg: np.ndarray,
                  every: int = 10) -> bytes:
    """Space 0 with the finishing contact points and the cutter locations (tool tip centres) in the part
    frame; every `every`-th tool is drawn turned with the part. Contacts are the design points nearest
    to each corner-circle centre."""
    from spur_cad.geometry.frames import machine_to_part

    outline = _space_outline(spec)
    r_t, half_flat = tool.effective_corner_radius_mm, tool.flat_width_mm / 2.0
    from spur_cad.sim.design import sample_space

    tips = machine_to_part(y, z, a_deg)
    dense = sample_space(spec.tooth_space_profile(), 0.005)[0]
    touching_sets = []
    for side in (1.0, -1.0):  # right and left corner-circle centres
        centres = machine_to_part(y + side * half_flat, z + r_t, a_deg)
        d = np.hypot(dense[None, :, 0] - centres[:, None, 0], dense[None, :, 1] - centres[:, None, 1])
        nearest = d.argmin(axis=1)
        touching = np.abs(d[np.arange(len(centres)), nearest] - r_t) < 0.01
        touching_sets.append(dense[nearest[touching]])
    contacts = np.concatenate(touching_sets)
    phi = np.linspace(0.0, math.pi / 2, 12)
    top = tool.diameter_mm  # the tool drawn one diameter up from its tip
    profile_y = np.concatenate([[-half_flat - r_t], -half_flat - r_t * np.sin(phi[::-1]),
                                half_flat + r_t * np.sin(phi), [half_flat + r_t]])
    profile_z = np.concatenate([[top], r_t - r_t * np.cos(phi[::-1]), r_t - r_t * np.cos(phi), [top]])
    shapes = [machine_to_part(y[i] + profile_y, z[i] + profile_z, np.full(len(profile_y), a_deg[i]))
              for i in range(0, len(y), every)]
    drawn = np.concatenate([outline, tips, *shapes]) if shapes else np.concatenate([outline, tips])
    y_low, y_high = spec.root_radius_mm - 1.0, max(spec.tip_radius_mm + 1.5, float(drawn[:, 1].max()) + 0.5)
    inside = drawn[(drawn[:, 1] >= y_low) & (drawn[:, 1] <= y_high)]
    x_low, x_high = float(inside[:, 0].min()) - 0.5, float(inside[:, 0].max()) + 0.5
    fig = figure_for_extent(7.5, x_high - x_low, y_high - y_low)  # the height follows the data
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(outline[:, 0], outline[:, 1], "-", color="k", lw=1.2, label="design")
    ax.plot(tips[:, 0], tips[:, 1], ".", ms=2, color="tab:blue", label="cutter locations (tip centre)")
    ax.plot(contacts[:, 0], contacts[:, 1], ".", ms=3, color="tab:red", label="contact points")
    if shapes:  # one line broken between the tools, not a line per tool
        joined = np.concatenate([part for shape in shapes for part in (shape, np.full((1, 2), np.nan))])
        ax.plot(joined[:, 0], joined[:, 1], "-", color="0.6", lw=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("part Y [mm] (space 0, A = 0)")
    ax.set_ylabel("part Z [mm]")
    ax.set_xlim(x_low, x_high)
    ax.set_ylim(y_low, y_high)
    set_title(ax, f"finishing: {len(y)} poses per space, {tool.kind} D {tool.diameter_mm:g} mm r {r_t:g} mm "
              f"(every {every}th tool drawn)", 9)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(True, lw=0.3)
    return _png(fig)


def row_axis_label(lying_flat: bool) -> tuple[str, str]:
    """(what a simulated row's position is, its axis label): X along the face width on the rotary table, the depth
    below the top face for a gear cut lying flat (3 axes)."""
    return ("depth", "depth below the top face [mm]") if lying_flat else ("X", "X (face width) [mm]")


def deviation_map_png(result: SimResult, lying_flat: bool = False) -> bytes:
    """Deviation over the space outline (arc length) x face width (depth when `lying_flat`) for the tooth space with
    the largest deviation, and per tooth space the largest gouge and leftover."""
    rows = result.gear_rows
    deviation = result.gear_deviation  # mm, a view (no copy of a big gear's millions of values)
    most, least = deviation.max(axis=(1, 2)) * 1000.0, deviation.min(axis=(1, 2)) * 1000.0  # um, per space
    x = result.grid.rows_x[rows]
    arc = result.grid.arc_mm
    worst = int(np.maximum(most, -least).argmax())
    worst_space = deviation[worst] * 1000.0  # um
    limit = max(float(np.abs(worst_space).max()), 1000.0 * result.settings.resolution_mm)
    fig = figure(9.0, 7.0, left=0.08, right=0.97, bottom=0.07, top=0.95)
    fig.subplots_adjust(hspace=0.3)
    ax, bars = fig.subplots(2, 1, height_ratios=[3, 1.4])
    image = ax.pcolormesh(arc, x, worst_space.T, cmap="RdBu_r", vmin=-limit, vmax=limit, shading="nearest")
    fig.colorbar(image, ax=ax, label="deviation [\u00b5m] (red: leftover, blue: gouge)", fraction=0.05, pad=0.02)
    names = result.grid.feature_names()
    starts = [0] + [j for j in range(1, len(names)) if names[j] != names[j - 1]]
    ends = starts[1:] + [len(names) - 1]
    room = 0.025 * (arc[-1] - arc[0])  # a name needs about this much of the axis beside the next one
    for j, end in zip(starts, ends):
        ax.axvline(arc[j], color="k", lw=0.4)
        if arc[end] - arc[j] >= room:  # features too short to carry their name (a tip land's corner) go unnamed
            ax.annotate(names[j], (arc[end], x[-1]), fontsize=7, rotation=90, va="top", ha="right",
                        xytext=(-2, -2), textcoords="offset points")
    ax.set_xlabel("position along the tooth space, right tooth centre -> root -> left tooth centre [mm]")
    ax.set_ylabel(row_axis_label(lying_flat)[1])
    set_title(ax, f"simulated deviation of tooth space {worst} (largest |deviation|); resolution "
              f"{1000 * result.settings.resolution_mm:g} \u00b5m", 9)
    spaces = np.arange(deviation.shape[0])
    _bars(bars, spaces - 0.4, np.maximum(most, 0.0), 0.4, "tab:red", "max leftover")
    _bars(bars, spaces, np.maximum(-least, 0.0), 0.4, "tab:blue", "max gouge")
    bars.set_xlabel("tooth space")
    bars.set_ylabel("[\u00b5m]")
    bars.legend(fontsize=8, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncols=2, frameon=False)  # above the bars
    bars.grid(True, lw=0.3, axis="y")
    return _png(fig)


def _bars(ax: Axes, left: np.ndarray, heights: np.ndarray, width: float, colour: str, label: str) -> None:
    """Bars from `left` (ascending, apart by more than `width`) up from 0 drawn as one filled step outline (zero
    between the bars): it looks as `ax.bar` does, without an artist per bar to make and draw."""
    edges = np.column_stack([left, left + width]).ravel()
    values = np.column_stack([heights, np.zeros_like(heights)]).ravel()[:-1]
    ax.stairs(values, edges, fill=True, color=colour, label=label)


def k_chart_png(spec: GearSpec, grading: Grading, lying_flat: bool = False) -> bytes:
    """`k_chart_figure` as PNG bytes."""
    return _png(k_chart_figure(spec, grading, lying_flat))


def k_chart_figure(spec: GearSpec, grading: Grading, lying_flat: bool = False) -> Figure:
    """A gear measuring machine's chart for the tooth space with the largest total profile deviation: its
    right and left profile traces (deviation against roll length, the three face positions) and helix traces,
    the evaluation ranges, the design (deviation 0; a modified flank's design trace, its profile or lead
    modification, with the traces drawn against the unmodified involute or helix) and the tolerance band of the
    gear's class around it (the total tolerance F_aT / F_bT, half each side, as measuring machines print it).
    The class counts a trace's own spread, not its offset: a flank standing off the design as a whole (tooth size,
    the finish's scallops on one side) pokes out of the band while its spread is in class."""
    from spur_cad.grade.iso1328 import tolerance_um

    traces = grading.traces
    profile = [t for t in traces if t.kind == "profile"]

    def spread_in_range(trace: Trace) -> float:
        inside = (trace.position_mm >= trace.evaluation[0]) & (trace.position_mm <= trace.evaluation[1])
        return float(np.ptp(trace.deviation_um[inside])) if inside.any() else 0.0

    worst = max(profile, key=spread_in_range).space
    grade = grading.overall_class or 11
    d, b, m = 2.0 * spec.reference_radius_mm, spec.face_width_mm, spec.module_mm
    profile_label = ("roll length [mm] (a ring's negative: root to tip)" if spec.kind.roll_sign < 0
                     else "roll length [mm]")
    row_name, row_label = row_axis_label(lying_flat)
    fig = figure(9.0, 6.5, left=0.08, right=0.98, bottom=0.08, top=0.95)
    fig.subplots_adjust(wspace=0.25, hspace=0.4)
    axes = fig.subplots(2, 2)
    for column, side in enumerate(("right", "left")):
        for row, kind in enumerate(("profile", "helix")):
            ax = axes[row][column]
            band = tolerance_um("F_aT" if kind == "profile" else "F_bT", grade, d, b, m)  # the gear's class
            chosen = [t for t in traces if t.kind == kind and t.side == side and t.space == worst]
            for trace, style in zip(chosen, ("-", "--", ":", "-.") * len(chosen)):  # coinciding traces stay visible
                label = f"{row_name} = {trace.x_mm:.2f} mm" if trace.x_mm is not None else "reference circle"
                design = 0.0 if trace.design_um is None else trace.design_um
                ax.plot(trace.position_mm, trace.deviation_um + design, style, lw=1.1, label=label)
                for edge in trace.evaluation:
                    ax.axvline(edge, color="k", lw=0.5, ls=":")
            if chosen and chosen[0].design_um is not None:  # a modified flank: the design trace, the band about it
                _design_trace(ax, chosen[0], band)
            elif chosen:
                ax.axhline(0.0, color="k", lw=0.8, gid="design")
                for edge in (-0.5 * band, 0.5 * band):
                    ax.axhline(edge, color="tab:red", lw=0.6, ls="--", gid="tolerance band")
            if chosen:
                _clip_outside_evaluation(ax, chosen, band)
            set_title(ax, f"space {worst}, {side} flank: {kind} (band: class {grade} "
                      f"{'F_aT' if kind == 'profile' else 'F_bT'} = {band:g} \u00b5m)", 8)
            ax.set_xlabel(profile_label if kind == "profile" else row_label, fontsize=8)
            ax.set_ylabel("deviation [\u00b5m] (+ material)", fontsize=8)
            ax.grid(True, lw=0.3)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6)
            else:
                ax.text(0.5, 0.5, "not measured", transform=ax.transAxes, ha="center", fontsize=8)
    return fig


def _clip_outside_evaluation(ax: Axes, traces: list[Trace], band_um: float) -> None:
    """Keep a K-chart panel's scale on what is graded: when a trace beyond the evaluation range (a ring's root fillet,
    a tip corner) reaches more than twice as far as the traces inside it and the band, the panel is clipped to those
    (20 % margin) and says so."""
    inside, design = [], []
    for trace in traces:
        lo, hi = trace.evaluation
        shown = trace.deviation_um + (0.0 if trace.design_um is None else trace.design_um)
        within = (trace.position_mm >= lo) & (trace.position_mm <= hi)
        inside.append(shown[within])
        design.append(np.zeros(1) if trace.design_um is None else trace.design_um[within])
    values = np.concatenate(inside + [d + 0.5 * band_um for d in design] + [d - 0.5 * band_um for d in design])
    low, high = float(values.min()), float(values.max())
    pad = 0.2 * max(high - low, 1e-3)
    shown_low, shown_high = ax.get_ylim()
    if shown_high - shown_low > 2.0 * (high - low + 2.0 * pad):
        ax.set_ylim(low - pad, high + pad)
        ax.text(0.01, 0.02, "clipped: the trace beyond the evaluation range leaves the scale", fontsize=6,
                transform=ax.transAxes, color="0.3")


def _design_trace(ax: Axes, trace: Trace, band_um: float) -> None:
    """A modified flank's design trace on a K-chart panel and the tolerance band about it (half each side)."""
    if trace.design_um is None:  # never: the caller draws it for a modified flank's trace only
        raise ValueError("a trace without its design trace has no design to draw")
    order = np.argsort(trace.position_mm)
    position, design = trace.position_mm[order], trace.design_um[order]
    ax.plot(position, design, "-", color="k", lw=0.8, gid="design", label="design (modified)")
    for edge in (-0.5 * band_um, 0.5 * band_um):
        ax.plot(position, design + edge, "--", color="tab:red", lw=0.6, gid="tolerance band")


_PASS_COLOURS = {"flank": "tab:blue", "tip": "tab:green", "land": "tab:purple"}


def passes_png(spec: GearSpec, tool: Tool, passes: tuple, blank_radius_mm: float) -> bytes:
    """Space 0 (and the neighbouring space on its +Y side, whose tooth land space 0's passes finish) with
    every straight pass of a clamped-A strategy: the tool's section turned into the part frame, and the
    design point each pass touches (nearest to the section: a contact, not an assumption about it)."""
    from spur_cad.cam.contacts import tool_signed_distance
    from spur_cad.geometry.frames import machine_to_part, turn_points

    outline = _space_outline(spec)
    neighbour = turn_points(outline, -2.0 * math.pi / spec.teeth)
    span = np.linspace(-math.pi / spec.teeth, 3.0 * math.pi / spec.teeth, 300)
    design = np.concatenate([outline, neighbour])
    r_t, half_flat = tool.effective_corner_radius_mm, tool.flat_width_mm / 2.0
    phi = np.linspace(0.0, math.pi / 2, 12)
    top = tool.diameter_mm  # the tool drawn one diameter up from its tip: enough to see its shape and side
    profile_y = np.concatenate([[-half_flat - r_t], -half_flat - r_t * np.sin(phi[::-1]),
                                half_flat + r_t * np.sin(phi), [half_flat + r_t]])
    profile_z = np.concatenate([[top], r_t - r_t * np.cos(phi[::-1]), r_t - r_t * np.cos(phi), [top]])
    shapes, nearest_points = [], []
    for p in passes:
        shapes.append(machine_to_part(p.y_mm + profile_y, p.z_mm + profile_z, np.full(len(profile_y), p.a_deg)))
        distance = tool_signed_distance(turn_points(design, math.radians(p.a_deg)), p.y_mm, p.z_mm, tool)
        nearest_points.append(design[int(np.argmin(distance))])
    contacts = np.array(nearest_points)
    x_low, x_high = -0.75 * spec.pitch_mm, 1.25 * spec.pitch_mm
    highest = max([blank_radius_mm] + [float(shape[:, 1].max()) for shape in shapes])
    y_low, y_high = spec.root_radius_mm - 1.0, highest + 0.5  # every tool outline inside the plot
    fig = figure_for_extent(7.5, x_high - x_low, y_high - y_low)
    ax = fig.add_subplot(1, 1, 1)
    ax.plot(outline[:, 0], outline[:, 1], "-", color="k", lw=1.2, label="design")
    ax.plot(neighbour[:, 0], neighbour[:, 1], "-", color="0.4", lw=0.8)
    ax.plot(blank_radius_mm * np.sin(span), blank_radius_mm * np.cos(span), ":", color="0.5", lw=1, label="blank")
    gap = np.full((1, 2), np.nan)  # a line broken between tools: one line per run of passes of a kind, in order
    labelled = set()
    for mode, run in itertools.groupby(zip(passes, shapes), key=lambda pass_shape: pass_shape[0].mode):
        joined = np.concatenate([part for _, shape in run for part in (shape, gap)])
        label = None if mode in labelled else f"{mode} passes"
        labelled.add(mode)
        ax.plot(joined[:, 0], joined[:, 1], "-", color=_PASS_COLOURS.get(mode, "0.6"), lw=0.4, label=label)
    ax.plot(contacts[:, 0], contacts[:, 1], ".", ms=4, color="tab:red", label="contacts")
    ax.set_aspect("equal")
    ax.set_xlabel("part Y [mm] (space 0, A = 0)")
    ax.set_ylabel("part Z [mm]")
    ax.set_xlim(x_low, x_high)
    ax.set_ylim(y_low, y_high)
    counts = {mode: sum(1 for p in passes if p.mode == mode) for mode in _PASS_COLOURS}
    set_title(ax, f"finishing passes of one tooth space: {len(passes)} ({counts['flank']} flank, {counts['tip']} "
              f"fillet and root, {counts['land']} land), {tool.kind} D {tool.diameter_mm:g} mm r {r_t:g} mm", 9)
    ax.legend(fontsize=8, loc="best")
    ax.grid(True, lw=0.3)
    return _png(fig)


def engagement_png(engagement: Engagement, step_over_fraction: float, max_depth_fraction: float,
                   slot_depth_fraction: float | None = None) -> bytes:
    """Histograms of the roughing moves that removed material: radial engagement a_e / D and axial depth
    a_p / D, per operation, with the job's step-over and depth limits (flank roughing: its radial engagement and
    axial depth limits, and `slot_depth_fraction`, the depth above which a_e must keep the radial limit)."""
    fig = figure(7.5, 2.6, left=0.08, right=0.98, bottom=0.19, top=0.86)
    cutting = engagement.cutting & engagement.measured
    names = list(dict.fromkeys(np.array(engagement.operation)[cutting]))
    operation = np.array(engagement.operation)
    values = (engagement.radial_fraction, engagement.axial_depth_mm / engagement.diameter_mm)
    for col, (value, limit, label) in enumerate(zip(values, (step_over_fraction, max_depth_fraction),
                                                    ("radial engagement a_e / D", "axial depth a_p / D"))):
        ax = fig.add_subplot(1, 2, col + 1)
        top = max(1.0, float(value[cutting].max(initial=0.0)), limit)
        bins = (np.arange(math.ceil(top / 0.025) + 2) - 0.5) * 0.025  # bins centred on 0, 0.025, ..., 1 D
        stacked = np.zeros(len(bins) - 1)
        for name, colour in zip(names, ("tab:blue", "tab:orange")):  # one filled outline per operation, stacked
            counts = np.histogram(value[cutting & (operation == name)], bins)[0]
            ax.stairs(stacked + counts, bins, baseline=stacked, fill=True, color=colour, label=name)
            stacked = stacked + counts
        ax.axvline(limit, color="tab:red", lw=1.0, ls="--", label="limit")
        if col == 1 and slot_depth_fraction is not None:
            ax.axvline(slot_depth_fraction, color="0.4", lw=1.0, ls=":", label="wider only up to here")
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel("moves", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, lw=0.3)
        if col == 1:  # beyond the depth limit: empty unless a move overloads
            ax.legend(fontsize=7, loc="upper right")
    n = int(cutting.sum())
    fig.suptitle(f"roughing engagement measured on the simulated stock ({n} moves removing material)", fontsize=9)
    return _png(fig)


MODIFICATION_SIDE_STYLES = {"right": ("tab:blue", "-"), "left": ("tab:orange", "--")}


def modification_chart_figure(mods: FlankModifications, base_radius_mm: float, width_in: float = 9.0,
                              stacked: bool = False) -> Figure:
    """The design flank modifications as a gear measuring machine charts them (+ material, so reliefs and crowning
    droop below the unmodified design at 0): the profile against roll length L (diameter on the top axis), from
    the form to the tip circle, and the lead against the face position X, both flanks (right solid, left
    dashed). `stacked`: profile above lead (a narrow task panel), else side by side."""
    from matplotlib.ticker import MaxNLocator

    right = mods.side("right")
    rolls = np.linspace(right.form_roll_mm, right.tip_roll_mm, 400)
    faces = np.linspace(0.0, right.face_width_mm, 400)
    # a breakpoint at every kink (the reliefs' starts), so a linear relief's corner is drawn sharp
    for side in ("right", "left"):
        flank = mods.side(side)
        rolls = np.union1d(rolls, flank.profile_kinks_roll_mm())
        faces = np.union1d(faces, flank.lead_kinks_mm())
    if stacked:  # inches: left, right, top (the diameter axis), bottom margins, axes height, gap between the axes
        left, right_in, top_in, bottom, axes_h, gap = 0.62, 0.08, 0.42, 0.42, 1.35, 0.78
        height_in = top_in + 2.0 * axes_h + gap + bottom
    else:
        left, right_in, top_in, bottom, axes_h, gap = 0.85, 0.15, 0.55, 0.5, 2.4, 0.0
        height_in = top_in + axes_h + bottom
    fig = figure(width_in, height_in, left=left / width_in, right=1.0 - right_in / width_in, bottom=bottom / height_in,
                 top=1.0 - top_in / height_in)
    fig.subplots_adjust(hspace=gap / axes_h, wspace=0.3)
    profile_ax, lead_ax = fig.subplots(2, 1) if stacked else fig.subplots(1, 2)
    size = 7 if stacked else 8
    for side, (colour, style) in MODIFICATION_SIDE_STYLES.items():
        flank = mods.side(side)
        profile_ax.plot(rolls, -1000.0 * flank.profile_offset_mm(rolls), style, color=colour, lw=1.4,
                        label=f"{side} flank")
        lead_ax.plot(faces, -1000.0 * flank.lead_offset_mm(faces), style, color=colour, lw=1.4,
                     label=f"{side} flank")

    def diameter(roll: np.ndarray) -> np.ndarray:
        return 2.0 * np.sqrt(np.asarray(roll, dtype=float) ** 2 + base_radius_mm ** 2)

    def roll(diam: np.ndarray) -> np.ndarray:
        return np.sqrt(np.maximum((np.asarray(diam, dtype=float) / 2.0) ** 2 - base_radius_mm ** 2, 0.0))

    top = profile_ax.secondary_xaxis("top", functions=(diameter, roll))
    top.xaxis.set_major_locator(MaxNLocator(4 if stacked else 8))  # a narrow chart's diameters never overlap
    top.set_xlabel("diameter [mm]", fontsize=size)
    top.tick_params(labelsize=size)
    profile_ax.set_xlabel("roll length L [mm]" if stacked else "roll length L [mm] (form to tip)", fontsize=size)
    lead_ax.set_xlabel("face position X [mm]" if stacked else "face position X [mm] (front to back)", fontsize=size)
    for ax, name in ((profile_ax, "profile"), (lead_ax, "lead")):
        ax.axhline(0.0, color="k", lw=0.8, gid="design")
        ax.set_ylabel(f"{name} [\u00b5m]\n(+ material)", fontsize=size)
        ax.tick_params(labelsize=size)
        ax.grid(True, lw=0.3)
        low = min(ax.get_ylim()[0], -1.0)
        ax.set_ylim(low, max(ax.get_ylim()[1], 0.1 * -low))
        if not any(getattr(mods.side(side), f"has_{name}") for side in MODIFICATION_SIDE_STYLES):
            ax.text(0.5, 0.35, f"no {name} modification", transform=ax.transAxes, ha="center", fontsize=size)
    lead_ax.legend(fontsize=size - 1, loc="lower center")
    return fig


def modification_chart_png(mods: FlankModifications, base_radius_mm: float, width_in: float = 9.0,
                           stacked: bool = False) -> bytes:
    """`modification_chart_figure` as PNG bytes."""
    return _png(modification_chart_figure(mods, base_radius_mm, width_in, stacked))
