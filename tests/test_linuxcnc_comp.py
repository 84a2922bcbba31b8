"""`a_axis.comp`, the LinuxCNC joint compensation file `spur-cad correct` writes for the A joint (issue 46), read and
applied as LinuxCNC does (tests/linuxcnc_comp.py: usrmotLoadComp in src/emc/motion/usrmotintf.cc, EMCMOT_SET_JOINT_COMP
in src/emc/motion/command.c, compute_screw_comp and output_to_hal in src/emc/motion/control.c, LinuxCNC/linuxcnc):
with COMP_FILE_TYPE = 1 the table, whose error is the planted e(A) = 25 arcsec x sin(A + 40 deg) at the motor's
position, stands at the commanded A."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spur_cad.correct.apply import linuxcnc_compensation
from spur_cad.correct.table import Harmonic, TableError
from tests.linuxcnc_comp import EMCMOT_COMP_SIZE, CompError, load_comp, motor_command

A_RANGE_DEG = (-383.2, 36.6)  # the reference job's corrected programs command A over this range


def planted_arcsec(a_deg: np.ndarray) -> np.ndarray:
    """The planted table error: the table stands this much further than its motor is commanded."""
    return 25.0 * np.sin(np.radians(np.asarray(a_deg) + 40.0))


def identified(*extra: Harmonic) -> TableError:
    """The planted e(A) as `correct` identifies it: 25 sin(A + 40) = 25 sin 40 cos A + 25 cos 40 sin A."""
    first = Harmonic(1, 25.0 * math.sin(math.radians(40.0)), 25.0 * math.cos(math.radians(40.0)), 0.03, True)
    return TableError((first, *extra), (-20.0, 20.0), True)


def test_the_file_loads_whole_in_linuxcnc():
    """Every line is one entry LinuxCNC keeps (three numbers, nominal strictly increasing, at most 256), the nominals
    covering the A the programs command and the turn 0 to 360 (a WRAPPED_ROTARY machine), both columns alike."""
    text = linuxcnc_compensation(identified(), (1,), A_RANGE_DEG)
    entries = load_comp(text, comp_file_type=1)
    assert len(entries) == len(text.splitlines()) <= EMCMOT_COMP_SIZE
    nominal = np.array([entry.nominal for entry in entries])
    assert nominal[0] <= min(A_RANGE_DEG[0], 0.0) and nominal[-1] >= max(A_RANGE_DEG[1], 360.0)
    assert all(entry.fwd_trim == entry.rev_trim for entry in entries)


@pytest.mark.parametrize("moving_up", [True, False])
def test_with_the_file_loaded_the_table_stands_at_the_commanded_a(moving_up):
    """The original program's A, through LinuxCNC's compensation, to the motor; the planted table then stands within
    0.01 arcsec of the commanded A over the programs' range and the turn (25 arcsec without the file)."""
    entries = load_comp(linuxcnc_compensation(identified(), (1,), A_RANGE_DEG), comp_file_type=1)
    commanded = np.linspace(A_RANGE_DEG[0], 360.0, 20001)
    motor = motor_command(entries, commanded, moving_up)
    table = motor + planted_arcsec(motor) / 3600.0
    assert np.abs(table - commanded).max() * 3600.0 < 0.01
    assert np.abs(planted_arcsec(commanded)).max() > 24.9  # what the file takes away


def test_a_higher_order_is_interpolated_within_an_arcsec():
    """The entries are close enough for LinuxCNC's linear interpolation of a 15 arcsec order 11 term (the reference
    gear's highest order tested) besides the planted first order: within 1 arcsec (0.1 um at 20 mm), the chord's
    (h step)^2 / 8 of the amplitude at the 3 deg step 256 entries allow over -384 to 360 deg (0.62 arcsec)."""
    eleventh = Harmonic(11, 0.0, 15.0, 0.03, True)
    entries = load_comp(linuxcnc_compensation(identified(eleventh), (1, 11), A_RANGE_DEG), comp_file_type=1)
    commanded = np.linspace(A_RANGE_DEG[0], 360.0, 20001)
    motor = motor_command(entries, commanded, True)
    error = planted_arcsec(motor) + 15.0 * np.sin(np.radians(11.0 * motor))
    assert np.abs(motor + error / 3600.0 - commanded).max() * 3600.0 < 1.0


def test_read_as_linuxcncs_default_type_0_the_file_would_be_wrong():
    """COMP_FILE_TYPE must be 1: read as type 0 (LinuxCNC's default) the trims are taken for actual positions and the
    motor goes about the nominal away: why docs/correction.md says to set it."""
    entries = load_comp(linuxcnc_compensation(identified(), (1,), A_RANGE_DEG), comp_file_type=0)
    motor = motor_command(entries, np.array([10.0, 100.0]), True)
    assert np.all(np.abs(motor - np.array([10.0, 100.0])) > 5.0)


def test_the_loader_emulation_refuses_what_linuxcnc_refuses():
    """The emulation itself: descending nominals and a 257th entry are errors, a comment line ends the loading."""
    with pytest.raises(CompError, match="increase"):
        load_comp("1 0 0\n0 0 0\n", 1)
    with pytest.raises(CompError, match="too many"):
        load_comp("".join(f"{i} 0 0\n" for i in range(257)), 1)
    assert len(load_comp("0 0 0\n# a comment\n1 0 0\n", 1)) == 1
