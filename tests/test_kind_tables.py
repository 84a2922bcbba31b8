"""The CAM and simulation modules ask the gear kind through tables keyed by the kind objects (issue 45): dispatch
tables of the algorithms that differ per kind and sets of the kinds a step applies to. Every dispatch table names
every kind (a new kind fails here, naming the tables to fill, instead of a KeyError inside a run), and each set holds
exactly the kinds an independent geometric fact of their specs says it should."""

from __future__ import annotations

import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import spur_cad.cam
import spur_cad.sim
from spur_cad.cam import fillet_reach, plan_roughing, probing, roughing
from spur_cad.cam.fillet_reach import RELAXED_BY_A_MATE
from spur_cad.cam.plan_roughing import SUGGESTED_FOR
from spur_cad.cam.probing import PROBED_KINDS
from spur_cad.cam.roughing import TURNS_A_ALONG_X
from spur_cad.cam.three_axis_root import SPACES
from spur_cad.geometry.internal import InternalGearSpec
from spur_cad.geometry.kinds import KINDS, GearKind
from spur_cad.geometry.spec import GearSpec
from spur_cad.sim import flat
from spur_cad.sim.flat import BORED_DISC_BLANKS

SPECS = (GearSpec(teeth=23, module_mm=4.0, face_width_mm=20.0, rack_tip_radius_mm=1.52),
         GearSpec(teeth=23, module_mm=4.0, face_width_mm=20.0, rack_tip_radius_mm=1.52, helix_angle_deg=15.0),
         InternalGearSpec(teeth=60, module_mm=2.0, addendum_coefficient=0.9, rack_tip_radius_mm=0.4,
                          shaper_cutter_teeth=20, rim_outer_diameter_mm=140.0, face_width_mm=10.0))
"""One gear of each kind (the reference gear, it with a 15 deg helix, tests/test_internal_gear.py's ring)."""


def _kind_tables() -> dict[str, dict]:
    """Every module-level dict of spur_cad.cam and spur_cad.sim whose keys are gear kinds, by module.name."""
    tables = {}
    for package in (spur_cad.cam, spur_cad.sim):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            module = importlib.import_module(info.name)
            for name, value in vars(module).items():
                if isinstance(value, dict) and value and all(isinstance(k, GearKind) for k in value):
                    tables[f"{module.__name__}.{name}"] = value
    return tables


SETS = {module: name for module in (roughing, probing, plan_roughing, fillet_reach, flat)
        for name, value in vars(module).items() if isinstance(value, frozenset) and value
        and all(isinstance(k, GearKind) for k in value)}
"""The sets of kinds a step applies to, by module (each module's own)."""
ARCHITECTURE = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"


def test_one_spec_of_each_kind() -> None:
    assert {spec.kind for spec in SPECS} == set(KINDS.values())


def test_every_dispatch_table_names_every_kind() -> None:
    tables = _kind_tables()
    assert len({id(t) for t in tables.values()}) >= 10, sorted(tables)  # the tables of cam/ and sim/ are found
    missing = {name: sorted(k.name for k in set(KINDS.values()) - set(table)) for name, table in tables.items()}
    assert {name: kinds for name, kinds in missing.items() if kinds} == {}


@pytest.mark.parametrize("spec", SPECS, ids=lambda spec: spec.kind.name)
def test_the_kind_sets_follow_the_geometry_of_their_specs(spec) -> None:
    """A kind's section turns along X when the transverse section at X = 10 mm is turned (a helix): then its
    roughing passes turn A and it is not probed (its flank normals leave the transverse plane) nor roughing
    alternatives planned for it. Its spaces open toward the axis when its root circle lies outside its tip circle
    (a ring): then its flat blank has a bore and its outline is a hole, and a mate is no remedy for its root."""
    kind = spec.kind
    turns = kind.section_turn_rad(spec, 10.0) != 0.0
    inward = spec.root_radius_mm > spec.tip_radius_mm
    assert (kind in TURNS_A_ALONG_X) is turns
    assert (kind in PROBED_KINDS) is not turns
    assert (kind in SUGGESTED_FOR) is not turns
    assert (kind in BORED_DISC_BLANKS) is inward
    assert SPACES[kind].internal is inward and SPACES[kind].mate_remedy is not inward
    assert (kind in RELAXED_BY_A_MATE) is (not turns and not inward)



def test_the_architecture_page_names_every_table_and_set() -> None:
    """docs/architecture.md's "Tables keyed by the kind" names each table and set as `module.NAME` (or the
    module's next table as `NAME` after it)."""
    page = " ".join(ARCHITECTURE.read_text().split())
    start = page.index("**Tables keyed by the kind**")
    paragraph = page[start:page.index("- **", start)]
    named = set(re.findall(r"`(?:\w+\.)?([A-Z_]+)`", paragraph))
    found = {name.rsplit(".", 1)[1] for name in _kind_tables()} | set(SETS.values())
    assert len(SETS) == 5 and found == named, (found ^ named)
