"""spur_cad for build123d users, with no CadQuery in the process: the gear from a GearSpec, in the machine frame
and in the part's own frame (axis Z, centre at the origin), composing in a BuildPart as any build123d Solid does.

These tests import no CadQuery, so they run in both flavours: beside CadQuery 2.8 and build123d 0.12 (OCP 7.9),
and in the build123d 0.13 flavour (OCP 8.0) that CI installs on its own (.ci/run). The references are
independent of the code under test: the exact outline's area (spur_cad.geometry, numpy only) times the face
width, the conventions of docs/cad.md stated as points that must lie in a tooth or in a space, and build123d's
own placement and booleans."""

from __future__ import annotations

import math
import subprocess
import sys

import build123d
import pytest

import spur_cad
from spur_cad.geometry import gear_outline
from spur_cad.geometry.sampling import polygon_area
from tests.gears import spec_of


def _inside(solid, point) -> bool:
    return solid.is_inside(build123d.Vector(*point))


def test_the_gear_from_a_spec_is_a_valid_solid_of_the_exact_volume_without_cadquery():
    code = ("import sys, spur_cad; from tests.gears import spec_of; "
            "s = spur_cad.to_build123d(spec_of('shifted_z12'), frame='part'); "
            "print(s.is_valid, 'cadquery' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False)
    assert done.stdout.split() == ["True", "False"], done.stderr[-2000:]
    spec = spec_of("shifted_z12")
    solid = spur_cad.to_build123d(spec)
    exact_mm3 = polygon_area(gear_outline(spec, 1e-6)) * spec.face_width_mm
    assert solid.volume == pytest.approx(exact_mm3, rel=1e-5)


@pytest.mark.parametrize("name", ["reference_z23_m4", "undercut_z8"])
def test_the_part_frame_puts_the_axis_on_z_the_centre_at_the_origin_and_space_0_on_plus_y(name):
    spec = spec_of(name)
    part = spur_cad.to_build123d(spec, frame="part")
    machine = spur_cad.to_build123d(spec)
    box = part.bounding_box()
    half_face = spec.face_width_mm / 2.0
    assert box.min.Z == pytest.approx(-half_face, abs=1e-6) and box.max.Z == pytest.approx(half_face, abs=1e-6)
    tip = spec.tip_radius_mm
    for low, high in ((box.min.X, box.max.X), (box.min.Y, box.max.Y)):
        assert -tip - 1e-6 <= low < -0.9 * tip and 0.9 * tip < high <= tip + 1e-6
    assert part.volume == pytest.approx(machine.volume, rel=1e-9)
    # Tooth space 0 is symmetric about +Y (machine +Z): half-way up the tooth on +Y is air, half a pitch on
    # (a tooth's centre line) is metal; likewise along machine +Z at mid-face in the machine frame.
    middle = (spec.root_radius_mm + tip) / 2.0
    half_pitch = math.pi / spec.teeth
    assert not _inside(part, (0.0, middle, 0.0))
    assert _inside(part, (middle * math.sin(half_pitch), middle * math.cos(half_pitch), 0.0))
    assert not _inside(machine, (half_face, 0.0, middle))
    assert _inside(machine, (half_face, -middle * math.sin(half_pitch), middle * math.cos(half_pitch)))


def test_the_part_frame_is_the_machine_frame_turned_without_a_mirror():
    """A helical gear keeps its hand: the part-frame solid is the machine-frame one moved by build123d's own
    rotations (a proper motion, so the helix cannot flip), point for point."""
    spec = spur_cad.GearSpec(teeth=17, module_mm=2.0, rack_tip_radius_mm=0.38, face_width_mm=12.0,
                             helix_angle_deg=20.0, hand="right")
    part = spur_cad.to_build123d(spec, frame="part")
    machine = spur_cad.to_build123d(spec)
    # docs/cad.md: machine X, Y, Z become part Z, X, Y, the centre at the origin: a build123d Plane whose x
    # direction is part +Z and whose normal is part +Y (so its y direction is part +X)
    plane = build123d.Plane(origin=(0.0, 0.0, -spec.face_width_mm / 2.0), x_dir=(0, 0, 1), z_dir=(0, 1, 0))
    moved = build123d.Location(plane) * machine
    targets = [vertex.center() for vertex in moved.vertices()]
    points = [vertex.center() for vertex in part.vertices()]
    assert len(points) > 20
    for point in points:
        assert min((point - other).length for other in targets) < 1e-6
    # and the same points are metal in both: points round the pitch circle near both faces, a quarter pitch off
    # the tooth centre lines (metal at one end, air at the other as the helix turns)
    radius = spec.reference_radius_mm
    seen = set()
    for height in (-5.5, 5.5):
        for k in range(0, 17, 2):
            angle = 2.0 * math.pi * (k + 0.25) / 17
            point = (radius * math.cos(angle), radius * math.sin(angle), height)
            inside = _inside(part, point)
            assert inside == _inside(moved, point), point
            seen.add(inside)
    assert seen == {True, False}  # both metal and air were compared


def test_the_gear_composes_in_a_build_part():
    spec = spec_of("reference_z23_m4")
    bore_mm = 10.0
    gear = spur_cad.to_build123d(spec, frame="part")
    with build123d.BuildPart() as part:
        build123d.insert(gear)
        build123d.Cylinder(bore_mm, spec.face_width_mm, mode=build123d.Mode.SUBTRACT)
        with build123d.Locations((200.0, 0.0, 0.0)):
            build123d.insert(gear)
    bore_mm3 = math.pi * bore_mm**2 * spec.face_width_mm
    assert part.part.is_valid
    assert part.part.volume == pytest.approx(2.0 * gear.volume - bore_mm3, rel=1e-6)
    located = build123d.Pos(0.0, 0.0, 30.0) * gear
    assert located.bounding_box().min.Z == pytest.approx(30.0 - spec.face_width_mm / 2.0, abs=1e-6)
    assert gear.bounding_box().min.Z == pytest.approx(-spec.face_width_mm / 2.0, abs=1e-6)  # the original stays


def test_a_shape_is_wrapped_where_it_lies_and_a_frame_is_refused_for_it():
    spec = spec_of("shifted_z12")
    shape = spur_cad.gear_shape(spec, frame="part")
    solid = spur_cad.to_build123d(shape)
    assert solid.wrapped.IsSame(shape)
    with pytest.raises(spur_cad.SpurCadError, match="frame"):
        spur_cad.to_build123d(shape, frame="part")
    with pytest.raises(spur_cad.SpurCadError, match="source"):
        spur_cad.to_build123d("gear")
