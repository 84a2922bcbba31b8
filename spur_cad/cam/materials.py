"""The job's material ([job] material): its specific cutting force by Kienzle, k_c = k_c1.1 * h^-m_c (N/mm^2,
h the chip thickness in mm), which the error budget's tool deflection needs (spur_cad.sim.budget).

The figures are the usual handbook values for milling with carbide (Kienzle-Victor tables as the machining
handbooks print them, e.g. Tabellenbuch Metall); plastics vary widely and are a rough figure. A shop with its
own measured k_c1.1 and m_c for a material should prefer them.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """A material's Kienzle constants: k_c1.1 (N/mm^2, the specific cutting force at h = 1 mm, b = 1 mm) and m_c."""

    name: str
    description: str
    kc11_n_mm2: float
    mc: float

    def cutting_force_n(self, chip_thickness_mm: float, chip_width_mm: float) -> float:
        """Kienzle's cutting force F = k_c1.1 * h^(1 - m_c) * b (N)."""
        return self.kc11_n_mm2 * chip_thickness_mm ** (1.0 - self.mc) * chip_width_mm


MATERIALS: dict[str, Material] = {m.name: m for m in (
    Material("steel_s235", "structural steel S235JR (St 37)", 1780.0, 0.17),
    Material("steel_c45", "carbon steel C45 (1.0503), the common gear steel", 2220.0, 0.14),
    Material("steel_16mncr5", "case-hardening steel 16MnCr5 (1.7131), soft", 2100.0, 0.26),
    Material("steel_42crmo4", "quenched and tempered steel 42CrMo4 (1.7225)", 2500.0, 0.26),
    Material("cast_iron_gjl250", "grey cast iron EN-GJL-250 (GG 25)", 1160.0, 0.26),
    Material("brass_cuzn39pb3", "free-cutting brass CuZn39Pb3", 780.0, 0.18),
    Material("aluminium_almgsi", "wrought aluminium alloy AlMgSi (6082)", 830.0, 0.23),
    Material("plastic_pom", "acetal POM (rough figure: plastics vary widely)", 150.0, 0.25),
)}
DEFAULT_MATERIAL = "steel_c45"
