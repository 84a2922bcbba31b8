"""Verification by simulated cutting: material removal by every IR move, deviation from the design.

`simulate` (fast, numpy + numba, point-vector blades along the design normals) and
`spur_cad.sim.occ_check` (the same removal with OCP booleans on a subset of moves, to cross-check
it). See docs/simulation.md.
"""

from spur_cad.sim.simulate import (
    Cut,
    SimResult,
    SimSettings,
    SimulationError,
    StockCylinder,
    decompose,
    finishing_stations,
    shifted,
    simulate,
    simulate_grid,
    subset,
)

__all__ = ["Cut", "SimResult", "SimSettings", "SimulationError", "StockCylinder", "decompose", "finishing_stations",
           "shifted",
           "simulate", "simulate_grid", "subset"]
