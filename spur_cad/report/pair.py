"""The report's "Gear pair" section: the gear and its [mate] as they mesh (spur_cad.geometry.mate), or, without a
[mate], the one sentence saying that the checks assume the basic rack."""

from __future__ import annotations

from spur_cad.report.sheet import Row, number
from spur_cad.result import JobResult

NO_MATE_NOTE = ("No [mate] given: the checks that depend on where the active profile starts (the flat end mill's "
                "root lying flat, the grade's profile evaluation range) assume the basic rack as the mate.")


def pair_rows(result: JobResult) -> tuple[Row, ...]:
    """Both gears, the centre distance, working pressure angle, contact ratios, backlash, each gear's start of
    active profile and the clearances; () without a [mate]."""
    pair, facts = result.pair, result.mate
    if pair is None or facts is None:
        return ()
    gear, mate = pair.gear, pair.mate

    def who(member) -> str:
        return f"{member.teeth} teeth, {'internal (ring)' if member.internal else 'external'}"

    rows = [
        Row("this gear", who(gear)), Row("mate", who(mate)),
        Row("mate's profile shift coefficient", number(mate.profile_shift_coefficient, 4)),
        Row("mate's addendum / dedendum coefficient",
            f"{number(mate.addendum_coefficient, 3)} / {number(mate.dedendum_coefficient, 3)}"),
        Row("centre distance (zero backlash at nominal thicknesses)", number(facts.centre_distance_mm, 4), "mm"),
        Row("reference centre distance", number(facts.reference_centre_distance_mm, 4), "mm"),
        Row("working (transverse) pressure angle", number(facts.working_pressure_angle_deg, 4), "°"),
        Row("operating pitch diameters (gear / mate)",
            f"{number(facts.operating_pitch_diameter_mm, 4)} / {number(facts.mate_operating_pitch_diameter_mm, 4)}",
            "mm"),
        Row("tip diameters (gear / mate)",
            f"{number(facts.tip_diameter_mm, 4)} / {number(facts.mate_tip_diameter_mm, 4)}", "mm"),
        Row("start of active profile, this gear", number(facts.start_of_active_profile_diameter_mm, 4), "mm"),
        Row("start of active profile, mate", number(facts.mate_start_of_active_profile_diameter_mm, 4), "mm"),
        Row("transverse contact ratio", number(facts.transverse_contact_ratio, 4)),
    ]
    if facts.overlap_ratio > 0.0:
        rows += [Row("overlap ratio", number(facts.overlap_ratio, 4)),
                 Row("total contact ratio", number(facts.total_contact_ratio, 4))]
    rows += [
        Row("circumferential backlash (operating pitch circle)", number(facts.circumferential_backlash_mm, 4), "mm"),
        Row("normal backlash", number(facts.normal_backlash_mm, 4), "mm"),
        Row("tip clearance (this gear's tip to the mate's root)", number(facts.tip_clearance_mm, 4), "mm"),
        Row("root clearance (the mate's tip to this gear's root)", number(facts.root_clearance_mm, 4), "mm"),
    ]
    return tuple(rows)
