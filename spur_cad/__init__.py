"""spur_cad: CAD/CAM for spur gears cut with end mills on a 4-axis machining centre.

The engine is layered (geometry -> cad -> cam -> post -> sim -> report/cli); importing this
package loads nothing heavy and has no side effects.
"""

from spur_cad.errors import GearSpecError, JobFileError, SpurCadError

__version__ = "0.1.0"

__all__ = ["GearSpecError", "JobFileError", "SpurCadError", "__version__"]
