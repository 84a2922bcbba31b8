"""STEP export of the gear, the stock and the job assembly (named, coloured parts), in millimetres.

Written with OCP's STEP writers as CadQuery's exporters write them (the same settings: pcurves, precision
mode 0, millimetres), into a private temporary folder that is removed afterwards; the caller decides
where the files go. What OCCT would take from outside the part is set here, so that the same job gives the
same bytes (docs/cad.md): a lone shape's PRODUCT is named after the part (OCCT would name it
'Open CASCADE STEP translator 7.9 <n>', n counting the shapes the process wrote before), the assembly's
NEXT_ASSEMBLY_USAGE_OCCURRENCE ids count from 1 in the file (OCCT counts them per process), and the
header's time is `timestamp` when given (spur_cad.pipeline takes it from SOURCE_DATE_EPOCH).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import cadquery as cq

GEAR_COLOUR = (0.55, 0.62, 0.72, 1.0)  # steel blue-grey
STOCK_COLOUR = (0.85, 0.75, 0.45, 0.35)  # translucent brass


def _settings() -> None:
    """The writer settings CadQuery's STEP exporters use (OCCT keeps them process-wide)."""
    from OCP.Interface import Interface_Static

    Interface_Static.SetIVal_s("write.surfacecurve.mode", 1)
    Interface_Static.SetIVal_s("write.precision.mode", 0)
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    Interface_Static.SetCVal_s("write.step.unit", "MM")


def _own_model(model, product_name: str | None, timestamp: str | None) -> None:
    """Set in the model what OCCT takes from the process: product names (lone shapes), assembly usage ids,
    and the header's time when `timestamp` is given."""
    from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
    from OCP.StepBasic import StepBasic_Product
    from OCP.StepRepr import StepRepr_NextAssemblyUsageOccurrence
    from OCP.TCollection import TCollection_HAsciiString

    usages = 0
    for index in range(1, model.NbEntities() + 1):
        entity = model.Value(index)
        if product_name is not None and isinstance(entity, StepBasic_Product):
            entity.SetId(TCollection_HAsciiString(product_name))
            entity.SetName(TCollection_HAsciiString(product_name))
        elif isinstance(entity, StepRepr_NextAssemblyUsageOccurrence):
            usages += 1
            entity.SetId(TCollection_HAsciiString(str(usages)))
    if timestamp is not None:
        APIHeaderSection_MakeHeader(model).SetTimeStamp(TCollection_HAsciiString(timestamp))


def _export_shape(workplane: cq.Workplane, name: str, folder: Path, timestamp: str | None) -> bytes:
    """One solid as a STEP file whose PRODUCT is called `name`."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    path = folder / f"{name}.step"
    writer = STEPControl_Writer()
    _settings()
    writer.Transfer(workplane.val().wrapped, STEPControl_AsIs)
    _own_model(writer.Model(), name, timestamp)
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCP could not write {name}.step")
    return path.read_bytes()


def job_assembly(gear: cq.Workplane, stock: cq.Workplane, name: str = "job") -> cq.Assembly:
    """Assembly with parts named `gear` and `stock`, both already in the machine frame."""
    assembly = cq.Assembly(name=name)
    assembly.add(gear, name="gear", color=cq.Color(*GEAR_COLOUR))
    assembly.add(stock, name="stock", color=cq.Color(*STOCK_COLOUR))
    return assembly


def _export_assembly(assembly: cq.Assembly, folder: Path, timestamp: str | None) -> bytes:
    """The assembly as CadQuery's default STEP export writes it (colours, layers, names)."""
    from cadquery.occ_impl.assembly import toCAF
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType
    from OCP.XSControl import XSControl_WorkSession

    _, document = toCAF(assembly, True)
    writer = STEPCAFControl_Writer(XSControl_WorkSession(), False)
    writer.SetColorMode(True)
    writer.SetLayerMode(True)
    writer.SetNameMode(True)
    _settings()
    Interface_Static.SetIVal_s("write.stepcaf.subshapes.name", 1)
    writer.Transfer(document, STEPControl_StepModelType.STEPControl_AsIs)
    _own_model(writer.ChangeWriter().Model(), None, timestamp)
    path = folder / "job.step"
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError("OCP could not write job.step")
    return path.read_bytes()


def step_files(gear: cq.Workplane, stock: cq.Workplane, timestamp: str | None = None) -> dict[str, bytes]:
    """{'gear.step', 'stock.step', 'job.step'} as bytes; `timestamp` ('YYYY-MM-DDTHH:MM:SS', UTC) is the
    headers' time, OCCT's clock when None."""
    with tempfile.TemporaryDirectory(prefix="spur_cad_step_") as tmp:
        folder = Path(tmp)
        return {"gear.step": _export_shape(gear, "gear", folder, timestamp),
                "stock.step": _export_shape(stock, "stock", folder, timestamp),
                "job.step": _export_assembly(job_assembly(gear, stock), folder, timestamp)}
