"""The blank's lathe program (issue 18): neutral turning moves for the stock a job describes (docs/lathe.md).

The gear blank is turned from bar stock before milling. Lathe frame: Z0 is the blank's FRONT face (milling
X = -front_margin, the bar's free end), Z negative toward the lathe chuck: lathe Z = -(X_mill + front_margin).
X is a DIAMETER. The blank runs from Z = 0 to Z = -L (L = front margin + face width + back margin), the
optional holding stub from Z = -L to Z = -(L + stub length); the part ends (and is parted off) there.

Two tools, each programmed at one point, without tool nose radius compensation:

- the turning insert (a right-hand tool cutting toward the chuck, e.g. 95 deg / 80 deg): programmed at its
  theoretical tip (the intersection of the tangents to its nose along X and Z), so faces and cylinders come
  out exact and 45 deg chamfers short by the nose radius effect (r (1 - tan 22.5 deg) ~ 0.59 r along each
  axis). It faces the bar end, roughs and finishes the front chamfer and the blank diameter; every pass runs
  toward the chuck and ends at the blank's back face Z = -L.
- the parting blade (a grooving/parting insert of width w): programmed at its corner on the part's side
  (toward +Z: the blade covers Z in [z - w, z]). A right-hand insert cannot cut a face that looks toward the
  chuck, so the blade cuts everything behind the blank: the back edge chamfer (with that corner), the
  shoulder and the stub diameter (plunges, overlapping by a quarter of the blade width), then the part-off.

Pure: no file I/O, no CAD kernel. `plan_lathe(spec, stock, lathe)` checks everything first
(`check_lathe_blank`) and returns a `LathePlan`; spur_cad.post.lathe writes it for a control.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from spur_cad.cad.specs import StockSpec
from spur_cad.dialects import DIALECTS, WORK_OFFSETS, Dialects, dialects_meaning, lathe_names
from spur_cad.errors import SpurCadError, require_instance, shown
from spur_cad.geometry.spec import GearSpec
from spur_cad.keys import check_section, key, key_of, with_key

DEFAULT_LATHE_DIALECT = "siemens"
MAX_PASSES = 10_000
"""Largest number of passes and plunges one lathe program may have (far more than any blank needs)."""
BAR_STEP_MM = 5.0
BAR_CLEAN_UP_MM = 2.0
"""bar_diameter_mm = 0: the smallest whole multiple of BAR_STEP_MM at least the blank diameter + BAR_CLEAN_UP_MM
(1 mm of the bar's surface, scale and out-of-roundness, turned off radially)."""
GROOVE_STEP_FRACTION = 0.75
"""Plunges of the blade along the stub are at most this x its width apart (a quarter overlaps)."""
FACE_PAST_CENTRE_MM = 0.1
"""Facing ends this far (radially) beyond the nose radius past the centre: the nose leaves no pip."""
PART_OFF_PAST_CENTRE_MM = 0.5
"""The part-off plunge ends this far (radially) past the centre."""
RETRACT_FEED_MM_REV = 0.5
"""Feed of the moves out of the material (they do not cut; feed moves so no rapid crosses the bar)."""

_TOOLS = "Lathe tools"


class LatheError(SpurCadError, ValueError):
    """A [lathe] setting, or the stock with it, that the lathe program cannot turn; `field` names the key."""

    def __init__(self, message: str, field: str | None = None, section: str | None = "lathe"):
        super().__init__(message, field=field, section=section)


@dataclass(frozen=True)
class LatheSection:
    """[lathe]: the blank's lathe program from bar stock (docs/lathe.md); X as diameter, Z0 on the front face."""

    dialect: str = key(DEFAULT_LATHE_DIALECT, label="LatheDialect", group="Lathe", choices=lathe_names(),
                       meaning=f"the lathe's control: {dialects_meaning(lathe_names())}; see docs/lathe.md")
    bar_diameter_mm: float = key(0.0, unit="mm", low=0.0, high=2000.0, label="LatheBarDiameter", group="Lathe",
                                 meaning="diameter of the bar stock, 0: the blank diameter + 2 mm rounded up to "
                                         "a whole 5 mm")
    face_stock_mm: float = key(1.0, unit="mm", low=0.0, high=50.0, label="LatheFaceStock", group="Lathe",
                               meaning="material faced off the bar's end (the program's Z0 is the faced end)")
    part_off: bool = key(True, label="LathePartOff", group="Lathe",
                         meaning="part the blank off at the end of the stub (of the blank without a stub); "
                                 "false leaves it on the bar")
    chamfer_mm: float = key(0.5, unit="mm", low=0.0, high=20.0, label="LatheChamfer", group="Lathe",
                            meaning="45 deg edge breaks on the blank's front and back edges, 0: none")
    work_offset: str = key("G54", label="LatheWorkOffset", group="Lathe", choices=WORK_OFFSETS,
                           meaning="work offset holding Z0 on the faced end, X0 on the spindle axis")
    program_number: int = key(2000, low=1, high=9999, label="LatheProgramNumber", group="Lathe",
                              meaning="program number (Fanuc O word)")
    max_spindle_rpm: float = key(3000.0, unit="1/min", low=10.0, high=50000.0, label="LatheMaxSpindleRpm",
                                 group="Lathe", meaning="spindle speed limit under constant cutting speed "
                                                        "(LIMS, G50 S, G96 D)")
    spindle_direction: str = key("M3", label="LatheSpindleDirection", group="Lathe", choices=("M3", "M4"),
                                 meaning="spindle direction for the tools as mounted (M3 or M4)")
    clearance_mm: float = key(2.0, unit="mm", low=0.1, high=50.0, label="LatheClearance", group="Lathe",
                              meaning="clearance of rapid moves from the bar (radial, and beyond its end)")
    tool_change_x_mm: float = key(0.0, unit="mm", low=0.0, high=5000.0, label="LatheToolChangeX", group="Lathe",
                                  meaning="X (diameter) of the tool change point, 0: the bar diameter + 2 x "
                                          "clearance")
    tool_change_z_mm: float = key(100.0, unit="mm", low=0.0, high=5000.0, label="LatheToolChangeZ",
                                  group="Lathe",
                                  meaning="Z of the tool change point (the turret indexes there), beyond the "
                                          "bar's end by at least the face stock + clearance")
    turning_tool_number: int = key(1, low=1, high=99, label="LatheTurningToolNumber", group=_TOOLS,
                                   meaning="turret position of the turning insert (Fanuc T0101: tool and offset)")
    turning_nose_radius_mm: float = key(0.4, unit="mm", low=0.0, high=5.0, label="LatheNoseRadius", group=_TOOLS,
                                        meaning="nose radius of the turning insert (the program point is its "
                                                "theoretical tip)")
    turning_cutting_speed_m_min: float = key(200.0, unit="m/min", low=1.0, high=3000.0,
                                             label="LatheTurningCuttingSpeed", group=_TOOLS,
                                             meaning="cutting speed V_c of the turning insert (G96)")
    roughing_feed_mm_rev: float = key(0.2, unit="mm/rev", low=0.001, high=2.0, label="LatheRoughingFeed",
                                      group=_TOOLS, meaning="feed of the insert's facing and roughing passes")
    finishing_feed_mm_rev: float = key(0.1, unit="mm/rev", low=0.001, high=2.0, label="LatheFinishingFeed",
                                       group=_TOOLS, meaning="feed of the insert's last facing and finishing passes")
    depth_of_cut_mm: float = key(1.5, unit="mm", low=0.01, high=20.0, label="LatheDepthOfCut", group=_TOOLS,
                                 meaning="largest depth of cut of the insert (radial; axial when facing)")
    finish_allowance_mm: float = key(0.2, unit="mm", low=0.0, high="depth_of_cut_mm", label="LatheFinishAllowance",
                                     group=_TOOLS, meaning="radial stock roughing leaves for the finishing pass")
    parting_tool_number: int = key(2, low=1, high=99, label="LathePartingToolNumber", group=_TOOLS,
                                   meaning="turret position of the parting blade (not the turning insert's)")
    parting_blade_width_mm: float = key(3.0, unit="mm", low=0.5, high=20.0, label="LatheBladeWidth", group=_TOOLS,
                                        meaning="width of the parting blade (programmed at its corner toward the "
                                                "part)")
    parting_cutting_speed_m_min: float = key(100.0, unit="m/min", low=1.0, high=3000.0,
                                             label="LathePartingCuttingSpeed", group=_TOOLS,
                                             meaning="cutting speed V_c of the parting blade (G96)")
    parting_feed_mm_rev: float = key(0.05, unit="mm/rev", low=0.001, high=1.0, label="LathePartingFeed",
                                     group=_TOOLS, meaning="feed of the blade's plunges, chamfer and part-off")
    parting_max_depth_mm: float = key(0.0, unit="mm", low=0.0, high=1000.0, label="LatheBladeReach", group=_TOOLS,
                                      meaning="deepest plunge the blade reaches from the bar's surface (radial), "
                                              "0: not checked")

    def __post_init__(self) -> None:
        """Raise LatheError for a key outside its range or choices, or keys that contradict each other, once, when
        the section is made (the stock and bar against the gear: check_lathe_blank)."""
        check_section(self, "lathe", LatheError)
        names = key_of(type(self), "dialect").names  # the registry's this section was made for
        if self.dialect not in names:  # a registry without lathe words gives no choices to check
            raise LatheError(f"[lathe] dialect = {shown(self.dialect)} is not known (known: "
                             f"{', '.join(names) or 'no dialect with lathe words'})", field="dialect")
        if self.parting_tool_number == self.turning_tool_number:
            raise LatheError(f"[lathe] parting_tool_number = {self.parting_tool_number} is the turning insert's "
                             "number too; the blade needs a turret position of its own", field="parting_tool_number")


def lathe_section_type(dialects: Dialects = DIALECTS) -> type[LatheSection]:
    """The [lathe] section for a registry of dialects: LatheSection for the default registry, else a subclass
    whose `dialect` key takes the registry's dialects with lathe words (its default siemens when among them,
    else the first)."""
    names = lathe_names(dialects)
    return _lathe_section_type(names, f"the lathe's control: {dialects_meaning(names, dialects)}; see docs/lathe.md")


@functools.cache
def _lathe_section_type(names: tuple[str, ...], meaning: str) -> type[LatheSection]:
    declared = key_of(LatheSection, "dialect")
    if names == declared.names and meaning == declared.meaning:
        return LatheSection
    default = DEFAULT_LATHE_DIALECT if DEFAULT_LATHE_DIALECT in names or not names else names[0]
    return with_key(LatheSection, "dialect", key(default, label=declared.label, group=declared.group,
                                                 meaning=meaning, choices=names))


@dataclass(frozen=True)
class LatheGeometry:
    """The turned part in the lathe frame (mm; diameters)."""

    blank_diameter: float
    blank_length: float  # L: the blank from Z = 0 to Z = -L
    stub_diameter: float  # 0: no stub
    stub_length: float
    bar_diameter: float
    safe_x: float  # bar diameter + 2 x clearance: rapids along Z run here
    tool_change_x: float
    tool_change_z: float

    @property
    def end_z(self) -> float:
        """Z of the part's far end (the stub's end, or the blank's back face): the part-off cut."""
        return -(self.blank_length + self.stub_length)

    @property
    def has_stub(self) -> bool:
        return self.stub_length > 0.0

    @property
    def shoulder(self) -> bool:
        """A step from the blank down to a thinner stub (the blank's back face shows)."""
        return self.has_stub and self.stub_diameter < self.blank_diameter - 1e-9


@dataclass(frozen=True)
class TurningMove:
    """One neutral lathe move to (x, z): x a DIAMETER, feed mm/rev (NaN for rapids), `tool` the turret
    position, `operation` what it belongs to ("facing", "roughing", "finishing", "stub roughing", ...)."""

    rapid: bool
    x: float
    z: float
    feed: float
    tool: int
    operation: str


@dataclass(frozen=True)
class LathePlan:
    """The lathe program in neutral moves, with the geometry it turns."""

    geometry: LatheGeometry
    moves: tuple[TurningMove, ...]
    face_stock_mm: float
    part_off: bool
    chamfer_mm: float

    def __len__(self) -> int:
        return len(self.moves)

    def columns(self) -> dict[str, np.ndarray]:
        """The moves as numpy columns: rapid, x (diameter), z, feed (mm/rev, NaN for rapids), tool."""
        return {"rapid": np.array([m.rapid for m in self.moves], bool),
                "x": np.array([m.x for m in self.moves], float), "z": np.array([m.z for m in self.moves], float),
                "feed": np.array([m.feed for m in self.moves], float),
                "tool": np.array([m.tool for m in self.moves], int)}


def bar_diameter_mm(spec: GearSpec, stock: StockSpec, lathe: LatheSection) -> float:
    """The bar's diameter: [lathe] bar_diameter_mm, or (0) the blank diameter + BAR_CLEAN_UP_MM rounded up to a
    whole multiple of BAR_STEP_MM."""
    if lathe.bar_diameter_mm > 0.0:
        return lathe.bar_diameter_mm
    blank = 2.0 * stock.blank_radius_mm(spec)
    return BAR_STEP_MM * math.ceil((blank + BAR_CLEAN_UP_MM) / BAR_STEP_MM - 1e-9)


def lathe_geometry(spec: GearSpec, stock: StockSpec, lathe: LatheSection) -> LatheGeometry:
    """The blank, stub and bar in the lathe frame (not checked: see check_lathe_blank)."""
    bar = bar_diameter_mm(spec, stock, lathe)
    safe = bar + 2.0 * lathe.clearance_mm
    x_front, x_back = stock.blank_x_range_mm(spec)
    return LatheGeometry(
        blank_diameter=2.0 * stock.blank_radius_mm(spec),
        blank_length=x_back - x_front,
        stub_diameter=stock.stub_diameter_mm if stock.stub_length_mm > 0.0 else 0.0,
        stub_length=stock.stub_length_mm if stock.stub_diameter_mm > 0.0 else 0.0,
        bar_diameter=bar, safe_x=safe,
        tool_change_x=lathe.tool_change_x_mm if lathe.tool_change_x_mm > 0.0 else safe,
        tool_change_z=lathe.tool_change_z_mm)


def _back_chamfer(g: LatheGeometry, lathe: LatheSection) -> bool:
    """The blank's back edge gets a chamfer (it has one: a shoulder, or the part-off end without a stub)."""
    return lathe.chamfer_mm > 0.0 and (g.shoulder or not g.has_stub)


def _pass_counts(g: LatheGeometry, lathe: LatheSection) -> dict[str, int]:
    """Facing and roughing passes of the insert, plunges of the blade along the stub."""
    doc = lathe.depth_of_cut_mm
    radial = (g.bar_diameter - g.blank_diameter) / 2.0 - lathe.finish_allowance_mm
    facing = max(1, math.ceil(lathe.face_stock_mm / doc - 1e-9))
    roughing = max(0, math.ceil(radial / doc - 1e-9)) if radial > 1e-9 else 0
    plunges = 0
    if g.has_stub:
        plunges = 2 * len(_plunge_positions(-g.blank_length, g.end_z + lathe.parting_blade_width_mm,
                                            lathe.parting_blade_width_mm, limit=MAX_PASSES))
    return {"facing": facing, "roughing": roughing, "plunges": plunges}


def check_lathe_blank(spec: GearSpec, stock: StockSpec, lathe: LatheSection) -> LatheGeometry:
    """Raise LatheError (field = the key to blame) unless the bar can be turned into the stock; the geometry.

    Refused: a bar thinner than the blank, a tool change point inside the bar, chamfers that overlap, eat
    the shoulder or need a finishing cut deeper than depth_of_cut_mm, a blade that cannot reach the stub's
    groove or the centre, more than MAX_PASSES passes. The sections are valid as made (their __post_init__); the
    stock against the gear is the job loader's check (StockSpec.validate), made before this one.
    """
    require_instance(spec, GearSpec, "spec")
    require_instance(stock, StockSpec, "stock")
    require_instance(lathe, LatheSection, "lathe")
    g = lathe_geometry(spec, stock, lathe)
    if g.bar_diameter < g.blank_diameter - 1e-9:
        raise LatheError(f"[lathe] bar_diameter_mm = {g.bar_diameter:g} is smaller than the blank "
                         f"({g.blank_diameter:.3f} mm: tip diameter + 2 x [stock] radial_allowance_mm)",
                         field="bar_diameter_mm")
    if lathe.tool_change_x_mm > 0.0 and lathe.tool_change_x_mm < g.safe_x - 1e-9:
        raise LatheError(f"[lathe] tool_change_x_mm = {lathe.tool_change_x_mm:g} is inside the bar's clearance "
                         f"(at least {g.safe_x:g}: bar diameter + 2 x clearance)", field="tool_change_x_mm")
    if lathe.tool_change_z_mm < lathe.face_stock_mm + lathe.clearance_mm - 1e-9:
        raise LatheError(f"[lathe] tool_change_z_mm = {lathe.tool_change_z_mm:g} is not clear of the bar's end "
                         f"(at least face_stock_mm + clearance_mm = "
                         f"{lathe.face_stock_mm + lathe.clearance_mm:g})", field="tool_change_z_mm")
    _check_chamfer(g, lathe)
    _check_blade_reach(g, lathe)
    counts = _pass_counts(g, lathe)
    for name, field in (("facing", "depth_of_cut_mm"), ("roughing", "depth_of_cut_mm"),
                        ("plunges", "parting_blade_width_mm")):
        if counts[name] > MAX_PASSES:
            raise LatheError(f"[lathe] {counts[name]:,} {name} passes exceed the limit of {MAX_PASSES:,}; "
                             f"raise {field}", field=field)
    if sum(counts.values()) > MAX_PASSES:
        raise LatheError(f"[lathe] {sum(counts.values()):,} passes exceed the limit of {MAX_PASSES:,}; raise "
                         "depth_of_cut_mm", field="depth_of_cut_mm")
    return g


def _check_chamfer(g: LatheGeometry, lathe: LatheSection) -> None:
    c = lathe.chamfer_mm
    if c <= 0.0:
        return
    ends = 2 if _back_chamfer(g, lathe) else 1
    if ends * c >= g.blank_length - 1e-9:
        raise LatheError(f"[lathe] chamfer_mm = {c:g}: {ends} chamfers of {c:g} mm do not fit on the blank's length "
                         f"{g.blank_length:g} mm", field="chamfer_mm")
    if 2.0 * c >= g.blank_diameter - 1e-9:
        raise LatheError(f"[lathe] chamfer_mm = {c:g} is larger than the blank's radius", field="chamfer_mm")
    height = (g.blank_diameter - g.stub_diameter) / 2.0
    if g.shoulder and c > height + 1e-9:
        raise LatheError(f"[lathe] chamfer_mm = {c:g} is larger than the shoulder from the blank to the stub "
                         f"({height:.3f} mm)", field="chamfer_mm")
    deepest = (c + lathe.finish_allowance_mm) / math.sqrt(2.0)
    if deepest > lathe.depth_of_cut_mm + 1e-9:
        raise LatheError(f"[lathe] chamfer_mm = {c:g}: the finishing pass would cut {deepest:.3f} mm deep at the "
                         f"front chamfer, more than depth_of_cut_mm = {lathe.depth_of_cut_mm:g} (at most "
                         f"{lathe.depth_of_cut_mm * math.sqrt(2.0) - lathe.finish_allowance_mm:.3f})",
                         field="chamfer_mm")


def _check_blade_reach(g: LatheGeometry, lathe: LatheSection) -> None:
    reach = lathe.parting_max_depth_mm
    if reach <= 0.0:
        return
    needs = []
    if g.has_stub:
        needs.append(((g.bar_diameter - g.stub_diameter) / 2.0, "the stub's groove"))
    elif _back_chamfer(g, lathe):
        needs.append(((g.bar_diameter - g.blank_diameter) / 2.0 + lathe.chamfer_mm, "the back chamfer"))
    if lathe.part_off:
        needs.append((g.bar_diameter / 2.0 + PART_OFF_PAST_CENTRE_MM, "the part-off"))
    for depth, what in needs:
        if depth > reach + 1e-9:
            raise LatheError(f"[lathe] {what} needs the blade {depth:.3f} mm deep into the bar, more than "
                             f"parting_max_depth_mm = {reach:g}", field="parting_max_depth_mm")


def _plunge_positions(first: float, last: float, width: float, limit: int = MAX_PASSES) -> list[float]:
    """Z of the blade's part-side corner for plunges from `first` toward the chuck to `last` (first >= last),
    at most GROOVE_STEP_FRACTION x width apart; one plunge at `first` when last >= first."""
    span = first - last
    if span <= 1e-9:
        return [first]
    count = math.ceil(span / (GROOVE_STEP_FRACTION * width) - 1e-9) + 1
    if count > limit:
        return [first] * (limit + 1)  # only counted: check_lathe_blank refuses it
    return [float(z) for z in np.linspace(first, last, count)]


class _Builder:
    """Collects moves; only axes that change, never a zero-length move."""

    def __init__(self, g: LatheGeometry):
        self.g = g
        self.moves: list[TurningMove] = []
        self.x, self.z = g.tool_change_x, g.tool_change_z
        self.tool = 0
        self.operation = ""

    def _add(self, rapid: bool, x: float | None, z: float | None, feed: float) -> None:
        x = self.x if x is None else x
        z = self.z if z is None else z
        if abs(x - self.x) < 1e-12 and abs(z - self.z) < 1e-12:
            return  # the post writes a tool change before the first move that carries the new tool
        self.moves.append(TurningMove(rapid, x, z, math.nan if rapid else feed, self.tool, self.operation))
        self.x, self.z = x, z

    def rapid(self, x: float | None = None, z: float | None = None) -> None:
        self._add(True, x, z, math.nan)

    def feed(self, x: float | None, z: float | None, feed: float) -> None:
        self._add(False, x, z, feed)

    def approach(self, x: float, z: float) -> None:
        """Rapid to (x, z) from the safe diameter: out to safe X, along Z, then in at that Z (the caller makes
        sure (x, z) is reachable in air: Z beyond the bar's end, or X on the safe diameter)."""
        if self.x < self.g.safe_x - 1e-9:
            raise RuntimeError("lathe plan: an approach from inside the bar")  # the builder's own invariant
        self.rapid(x=max(self.x, self.g.safe_x))
        self.rapid(z=z)
        self.rapid(x=x)

    def tool_change(self, tool: int) -> None:
        """To the tool change point with the old tool; then (tool > 0) the new one's first move goes there
        too (written with both axes: from wherever the turret is, with the new tool's offsets)."""
        self.operation = "tool change"
        if self.tool:
            self.rapid(x=max(self.x, self.g.tool_change_x))
            self.rapid(self.g.tool_change_x, self.g.tool_change_z)
        self.tool = tool
        if tool:
            self.moves.append(TurningMove(True, self.g.tool_change_x, self.g.tool_change_z, math.nan, tool,
                                          self.operation))
            self.x, self.z = self.g.tool_change_x, self.g.tool_change_z


def plan_lathe(spec: GearSpec, stock: StockSpec, lathe: LatheSection) -> LathePlan:
    """The lathe program for the job's stock as neutral moves (checks first: check_lathe_blank)."""
    g = check_lathe_blank(spec, stock, lathe)
    b = _Builder(g)
    b.tool_change(lathe.turning_tool_number)
    _facing(b, g, lathe)
    _roughing(b, g, lathe)
    _finishing(b, g, lathe)
    if g.has_stub or lathe.part_off or _back_chamfer(g, lathe):
        b.tool_change(lathe.parting_tool_number)
        if g.has_stub:
            _stub(b, g, lathe)
        _back_end(b, g, lathe)
    b.tool_change(0)
    moves = tuple(b.moves)
    return LathePlan(geometry=g, moves=moves, face_stock_mm=lathe.face_stock_mm, part_off=lathe.part_off,
                     chamfer_mm=lathe.chamfer_mm)


def _facing(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """Passes of at most depth_of_cut from Z = face_stock to Z = 0, from above the bar to past the centre."""
    b.operation = "facing"
    count = _pass_counts(g, lathe)["facing"]
    cl = lathe.clearance_mm
    x_end = -2.0 * (lathe.turning_nose_radius_mm + FACE_PAST_CENTRE_MM)
    for k in range(1, count + 1):
        z = lathe.face_stock_mm * (1.0 - k / count)
        b.rapid(x=g.safe_x)
        b.rapid(z=z)
        b.feed(x_end, z, lathe.finishing_feed_mm_rev if k == count else lathe.roughing_feed_mm_rev)
        b.feed(x_end, z + cl, RETRACT_FEED_MM_REV)
    b.rapid(x=g.safe_x)


def _roughing(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """Passes along the blank from Z = +clearance to its back face, down to its diameter + 2 x allowance."""
    b.operation = "roughing"
    count = _pass_counts(g, lathe)["roughing"]
    cl, length = lathe.clearance_mm, g.blank_length
    target = g.blank_diameter + 2.0 * lathe.finish_allowance_mm
    for k in range(1, count + 1):
        x = g.bar_diameter + (target - g.bar_diameter) * k / count
        b.rapid(z=cl)
        b.rapid(x=x)
        b.feed(x, -length, lathe.roughing_feed_mm_rev)
        b.feed(g.safe_x, -length + cl, RETRACT_FEED_MM_REV)


def _finishing(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """The front chamfer (entered on its 45 deg line from beyond the face) and the blank diameter."""
    b.operation = "finishing"
    cl, c, d = lathe.clearance_mm, lathe.chamfer_mm, g.blank_diameter
    f = lathe.finishing_feed_mm_rev
    b.rapid(z=cl)
    if c > 0.0:
        b.rapid(x=d - 2.0 * c - 2.0 * cl)
        b.feed(d, -c, f)
    else:
        b.rapid(x=d)
    b.feed(d, -g.blank_length, f)
    b.feed(g.safe_x, -g.blank_length + cl, RETRACT_FEED_MM_REV)


def _plunge(b: _Builder, g: LatheGeometry, z: float, x: float, feed: float) -> None:
    b.approach(g.safe_x, z)
    b.feed(x, z, feed)
    b.feed(g.safe_x, z, RETRACT_FEED_MM_REV)


def _stub(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """Rough plunges to the stub's diameter + 2 x allowance (the shoulder keeps the allowance too), then the
    back chamfer, the shoulder and finishing plunges to the stub's diameter."""
    w, a, f = lathe.parting_blade_width_mm, lathe.finish_allowance_mm, lathe.parting_feed_mm_rev
    length, last = g.blank_length, g.end_z + w
    b.operation = "stub roughing"
    for z in _plunge_positions(-length - a, last, w):
        _plunge(b, g, z, g.stub_diameter + 2.0 * a, f)
    b.operation = "stub finishing"
    if _back_chamfer(g, lathe):
        _chamfer_back(b, g, lathe)
        b.operation = "stub finishing"
        b.feed(g.stub_diameter, -length, f)
        b.feed(g.safe_x, -length, RETRACT_FEED_MM_REV)
    else:
        _plunge(b, g, -length, g.stub_diameter, f)
    for z in _plunge_positions(-length, last, w)[1:]:
        _plunge(b, g, z, g.stub_diameter, f)


def _chamfer_back(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """The blank's back edge with the blade's part-side corner, entered on the 45 deg line from above."""
    c, e, d, f = lathe.chamfer_mm, lathe.clearance_mm, g.blank_diameter, lathe.parting_feed_mm_rev
    z0 = -g.blank_length + c + e
    b.operation = "back chamfer"
    b.approach(g.safe_x, z0)
    b.feed(d + 2.0 * e, z0, f)
    b.feed(d - 2.0 * c, -g.blank_length, f)


def _back_end(b: _Builder, g: LatheGeometry, lathe: LatheSection) -> None:
    """Without a stub: the back chamfer; then the part-off at the part's end."""
    x_off = -2.0 * PART_OFF_PAST_CENTRE_MM
    f = lathe.parting_feed_mm_rev
    if not g.has_stub and _back_chamfer(g, lathe):
        _chamfer_back(b, g, lathe)
        if lathe.part_off:
            b.operation = "part-off"
            b.feed(x_off, g.end_z, f)
        b.feed(g.safe_x, g.end_z, RETRACT_FEED_MM_REV)
        return
    if lathe.part_off:
        b.operation = "part-off"
        _plunge(b, g, g.end_z, x_off, f)
