"""spur_cad: CAD/CAM for spur gears cut with end mills on a 4-axis machining centre.

The engine is layered (geometry -> cad -> cam -> post -> sim -> report/cli) and needs OCP, not a front-end.
Importing this package loads nothing heavy: the CAD entry points below import OCP (and CadQuery or build123d,
for their own functions) on first use.

    import spur_cad
    spec = spur_cad.GearSpec(teeth=23, module_mm=4.0, rack_tip_radius_mm=0.8, face_width_mm=20.0)
    shape = spur_cad.gear_shape(spec)                    # OCP TopoDS_Shape, machine frame (axis X)
    gear = spur_cad.make_gear(spec)                      # cadquery.Workplane (spur_cad[cadquery])
    stock = spur_cad.make_stock(spec)
    solid = spur_cad.to_build123d(spec, frame="part")    # build123d.Solid, axis Z, centre at the origin
"""

from spur_cad.errors import GearSpecError, JobFileError, SpurCadError, StockError
from spur_cad.version import __version__

_CAD_ENTRY_POINTS = {"gear_shape", "stock_shape", "make_gear", "make_stock", "to_build123d", "BlankFeatures",
                     "StockSpec"}

__all__ = ["GearSpec", "GearSpecError", "JobFileError", "SpurCadError", "StockError", "__version__",
           *sorted(_CAD_ENTRY_POINTS)]


def __getattr__(name: str):
    """Lazy access to GearSpec and the CAD entry points: `import spur_cad` loads neither numpy nor the
    CAD kernel (the command line installs its signal handling before anything heavy is imported)."""
    if name == "GearSpec":
        from spur_cad.geometry.spec import GearSpec

        return GearSpec
    if name in {"BlankFeatures", "StockSpec"}:
        from spur_cad.cad import specs

        return getattr(specs, name)
    if name in _CAD_ENTRY_POINTS:
        from spur_cad.cad import solid

        return getattr(solid, name)
    raise AttributeError(f"module 'spur_cad' has no attribute {name!r}")
