"""[mate] in the job file: the pair it makes and its one-line refusals at the key (file, line, key; exit 2,
nothing written)."""

from __future__ import annotations

import math

import pytest

from spur_cad.cli import main
from spur_cad.errors import JobFileError
from spur_cad.job import job_from_dict, parse_job
from spur_cad.mate_section import check_mate
from tests.textbook import inv, inv_inverse
from tests.workbench_helper import ROOT

GEAR = "[gear]\nteeth = 40\nmodule_mm = 1.0\nface_width_mm = 10.0\nrack_tip_radius_mm = 0.38\n"


def _pair(text: str):
    job = parse_job(text, "job.toml")
    return check_mate(job.gear, job.mate, {})


def test_a_z40_mate_at_the_standard_centre_distance():
    pair, facts = _pair(GEAR + "thickness_allowance_percent = 2.0\n[mate]\nteeth = 40\n")
    assert facts.centre_distance_mm == pytest.approx(40.0, rel=1e-12)
    assert round(facts.start_of_active_profile_diameter_mm, 3) == 38.564
    assert facts.circumferential_backlash_mm == pytest.approx(0.02 * math.pi / 2, rel=1e-9)
    assert pair.mate.form_diameter_mm is not None and pair.gear.form_diameter_mm is not None


def test_the_centre_distance_sets_the_mate_shift():
    """a = 40.5 mm for z 40/40 m 1: cos(alpha_w) = 40 cos(20 deg) / 40.5, x_1 + x_2 = 80 (inv(alpha_w) - inv(20 deg))
    / (2 tan(20 deg)); the gear's x 0.1 given, the mate's is the rest."""
    pair, facts = _pair(GEAR.replace("teeth = 40\n", "teeth = 40\nprofile_shift_coefficient = 0.1\n", 1)
                        + "[mate]\nteeth = 40\ncentre_distance_mm = 40.5\n")
    alpha = math.radians(20.0)
    total = 80 * (inv(math.acos(40 * math.cos(alpha) / 40.5)) - inv(alpha)) / (2 * math.tan(alpha))
    assert pair.mate.profile_shift_coefficient == pytest.approx(total - 0.1, rel=1e-9)
    assert facts.centre_distance_mm == pytest.approx(40.5, rel=1e-12)
    # Given both, consistently (the shifts' centre distance within 0.001 mm): accepted.
    x2 = round(total - 0.1, 6)
    aw = inv_inverse(inv(alpha) + 2 * math.tan(alpha) * (0.1 + x2) / 80)
    assert abs(40 * math.cos(alpha) / math.cos(aw) - 40.5) < 0.001
    _pair(GEAR.replace("teeth = 40\n", "teeth = 40\nprofile_shift_coefficient = 0.1\n", 1)
          + f"[mate]\nteeth = 40\nprofile_shift_coefficient = {x2}\ncentre_distance_mm = 40.5\n")


REFUSED = {
    "inconsistent": ("[mate]\nteeth = 40\nprofile_shift_coefficient = 0.3\ncentre_distance_mm = 40.0\n",
                     "job.toml:9: [mate] centre_distance_mm = 40 mm disagrees with profile_shift_coefficient = 0.3, "
                     "whose working centre distance is 40.2921 mm; give one of them"),
    "below the base circles": ("[mate]\nteeth = 40\ncentre_distance_mm = 36.0\n",
                               "job.toml:8: [mate] centre_distance_mm = 36 mm cannot be reached: the base circles "
                               "leave no working pressure angle below 37.5877 mm"),
    "beyond the shifts": ("[mate]\nteeth = 40\ncentre_distance_mm = 50.0\n",
                          "job.toml:8: [mate] centre_distance_mm = 50 mm cannot be reached: it needs a mate shift of "),
    "involute interference": ("[mate]\nteeth = 8\n",
                              "job.toml:7: [mate] involute interference: this gear's tips reach the mate's flank past "
                              "its base circle's tangent point"),
    "root interference": ("[mate]\nteeth = 40\naddendum_coefficient = 1.2\n",
                          "job.toml:8: [mate] root interference: the mate's tips reach this gear's fillet"),
    "contact ratio": ("[mate]\nteeth = 40\naddendum_coefficient = 0.5\n",
                      "job.toml:9: [mate] the transverse contact ratio "),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_refusals_at_the_key(case):
    section, expected = REFUSED[case]
    gear = GEAR.replace("rack_tip_radius_mm = 0.38\n", "rack_tip_radius_mm = 0.38\naddendum_coefficient = 0.5\n") \
        if case == "contact ratio" else GEAR
    with pytest.raises(JobFileError) as caught:
        parse_job(gear + section, "job.toml")
    assert str(caught.value).startswith(expected), str(caught.value)
    assert caught.value.section == "mate"


def test_the_contact_ratio_refusal_states_the_textbook_ratio():
    rb, ra = 20.0 * math.cos(math.radians(20.0)), 20.5
    ratio = (2 * math.sqrt(ra**2 - rb**2) - 40 * math.sin(math.radians(20.0))) / (math.pi * math.cos(math.radians(20)))
    text = GEAR.replace("rack_tip_radius_mm = 0.38\n", "rack_tip_radius_mm = 0.38\naddendum_coefficient = 0.5\n")
    with pytest.raises(JobFileError, match=f"contact ratio {ratio:.4f} is below 1"):
        parse_job(text + "[mate]\nteeth = 40\naddendum_coefficient = 0.5\n", "job.toml")


RING = ("[gear]\nteeth = 60\nmodule_mm = 2.0\nface_width_mm = 10.0\nrack_tip_radius_mm = 0.4\ninternal = true\n"
        "shaper_cutter_teeth = 20\nrim_outer_diameter_mm = 140.0\naddendum_coefficient = 0.9\n")


def test_a_ring_gear_with_a_pinion_mate():
    """The ring (this gear) and a 40-tooth pinion: the ring's SAP (its largest active diameter) by KHK's internal
    formula, the pinion's tip roll plus a sin(alpha_w), at a = (z_2 - z_1) m / 2 (no shifts)."""
    _, facts = _pair(RING + "[mate]\nteeth = 40\n")
    alpha = math.radians(20.0)
    rb2, rb1, ra1 = 60 * math.cos(alpha), 40 * math.cos(alpha), 42.0
    sap = 2 * math.hypot(rb2, math.sqrt(ra1**2 - rb1**2) + 20.0 * math.sin(alpha))
    assert facts.centre_distance_mm == pytest.approx(20.0, rel=1e-12)
    assert facts.start_of_active_profile_diameter_mm == pytest.approx(sap, rel=1e-9)
    with pytest.raises(JobFileError, match=r"job.toml:12: \[mate\] two internal gears cannot mesh"):
        parse_job(RING + "[mate]\nteeth = 40\ninternal = true\n", "job.toml")


def test_a_refused_mate_exits_2_and_writes_nothing(tmp_path, capsys):
    job = tmp_path / "bad.toml"
    job.write_text(GEAR + "[mate]\nteeth = 8\n")
    out = tmp_path / "out"
    assert main(["run", str(job), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spur-cad: error: ") and len(err.strip().splitlines()) == 1
    assert f"{job}:7: [mate] involute interference" in err
    assert not out.exists()


def test_a_workbench_document_writes_mate_only_when_asked_and_lets_a_centre_distance_set_the_shift(monkeypatch):
    """The document holds [mate] behind its UseMate switch (group Mate); a document always holds a shift, so a 0
    shift beside a centre distance is left out of the job it writes (the centre distance sets it)."""
    monkeypatch.syspath_prepend(str(ROOT / "workbench"))
    from spur_cad_workbench import schema  # noqa: PLC0415 (importable once workbench/ is on the path)

    job = parse_job(GEAR + "[mate]\nteeth = 40\ncentre_distance_mm = 40.5\n", "job.toml")
    values = schema.values_from_job(job)
    assert values["job"]["UseMate"] is True and schema.field_by_prop("MateTeeth").group == "Mate"
    data = schema.job_data(values)
    assert "profile_shift_coefficient" not in data["mate"] and data["mate"]["centre_distance_mm"] == 40.5
    again = job_from_dict(data, "document")
    assert again.pair.mate.profile_shift_coefficient == pytest.approx(job.pair.mate.profile_shift_coefficient,
                                                                      rel=1e-12)
    values["job"]["UseMate"] = False
    assert "mate" not in schema.job_data(values)
    assert "mate" not in schema.job_data(schema.values_from_job(parse_job(GEAR, "job.toml")))
