"""STEP export of the gear, the stock and the job assembly (named, coloured parts), in millimetres.

Written with OCP's STEP writers as CadQuery's exporters write them (the same settings: pcurves, precision
mode 0, millimetres; the assembly as CadQuery's Assembly makes it), without importing CadQuery (its import
costs more than the export), into a private temporary folder that is removed afterwards; the caller
decides where the files go. What OCCT would take from outside the part is set here, so that the same job gives the
same bytes (docs/cad.md): a lone shape's PRODUCT is named after the part (OCCT would name it
'Open CASCADE STEP translator 7.9 <n>', n counting the shapes the process wrote before), the assembly's
NEXT_ASSEMBLY_USAGE_OCCURRENCE ids count from 1 in the file (OCCT counts them per process), and the
header's time is `timestamp` when given (spur_cad.pipeline takes it from SOURCE_DATE_EPOCH).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # annotations only
    from OCP.TopoDS import TopoDS_Shape

GEAR_COLOUR = (0.55, 0.62, 0.72, 1.0)  # steel blue-grey
STOCK_COLOUR = (0.85, 0.75, 0.45, 0.35)  # translucent brass


def _settings() -> None:
    """The writer settings CadQuery's STEP exporters use (OCCT keeps them process-wide), and OCCT's messages
    kept to failures, as CadQuery keeps them on import: else the writer prints its transfer statistics on
    standard output (the CLI's, the workbench's console)."""
    from OCP.Interface import Interface_Static
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)

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

    if product_name is not None:
        for product in _entities_of_type(model, StepBasic_Product):
            product.SetId(TCollection_HAsciiString(product_name))
            product.SetName(TCollection_HAsciiString(product_name))
    for usages, usage in enumerate(_entities_of_type(model, StepRepr_NextAssemblyUsageOccurrence), start=1):
        usage.SetId(TCollection_HAsciiString(str(usages)))
    if timestamp is not None:
        APIHeaderSection_MakeHeader(model).SetTimeStamp(TCollection_HAsciiString(timestamp))


def _entities_of_type(model, kind) -> list:
    """The model's entities of the STEP type `kind` (an OCP class), in the model's order: selected by OCCT, not
    by wrapping each of the model's tens of thousands of entities in Python (0.06 s a run)."""
    entities = model.Entities()
    entities.SelectType(kind.get_type_descriptor_s(), True)
    found = []
    entities.Start()
    while entities.More():
        found.append(entities.Value())
        entities.Next()
    return found


def _export_shape(shape: TopoDS_Shape, name: str, folder: Path, timestamp: str | None) -> bytes:
    """One solid as a STEP file whose PRODUCT is called `name`."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    path = folder / f"{name}.step"
    writer = STEPControl_Writer()
    _settings()
    writer.Transfer(shape, STEPControl_AsIs)
    _own_model(writer.Model(), name, timestamp)
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError(f"OCP could not write {name}.step")
    return path.read_bytes()


def job_document(gear: TopoDS_Shape, stock: TopoDS_Shape, name: str = "job"):
    """An XCAF document holding the assembly `name` with the parts `gear` and `stock`, coloured, both already
    in the machine frame: as CadQuery's Assembly makes it for a coloured STEP export (each part a compound
    of its solid, named, with a surface colour, placed once in the assembly at the identity)."""
    return coloured_assembly(name, (("gear", gear, GEAR_COLOUR), ("stock", stock, STOCK_COLOUR)),
                             as_cadquery_does=True)


def coloured_assembly(name: str, parts: tuple[tuple[str, TopoDS_Shape, tuple[float, float, float, float]], ...],
                      as_cadquery_does: bool):
    """An XCAF document holding the assembly `name` of `parts` ((part name, shape, sRGBA colour) each: a named,
    surface-coloured compound of its solid, placed at the identity; the shapes carry their own placement).
    `as_cadquery_does`: also the layer and material tools and the assembly's own located top label, as
    CadQuery's Assembly export makes them (the job's STEP, compared with CadQuery's); without them, the pair's."""
    from OCP.BinXCAFDrivers import BinXCAFDrivers
    from OCP.Quantity import Quantity_Color, Quantity_ColorRGBA, Quantity_TOC_sRGB
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_Label
    from OCP.TDocStd import TDocStd_Document
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS_Builder, TopoDS_Compound
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

    def named(label, text: str):
        TDataStd_Name.Set_s(label, TCollection_ExtendedString(text))
        return label

    application = XCAFApp_Application.GetApplication_s()
    BinXCAFDrivers.DefineFormat_s(application)
    document = TDocStd_Document(TCollection_ExtendedString("BinXCAF"))
    application.InitDocument(document)
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(document.Main())
    shapes.SetAutoNaming_s(False)
    colours = XCAFDoc_DocumentTool.ColorTool_s(document.Main())
    if as_cadquery_does:
        XCAFDoc_DocumentTool.LayerTool_s(document.Main())
        XCAFDoc_DocumentTool.MaterialTool_s(document.Main())
    assembly = named(shapes.NewShape(), name)
    for part_name, shape, (r, g, b, a) in parts:
        compound = TopoDS_Compound()
        builder = TopoDS_Builder()
        builder.MakeCompound(compound)
        builder.Add(compound, shape)
        part = named(shapes.NewShape(), part_name)
        shapes.SetShape(part, compound)
        colours.SetColor(part, Quantity_ColorRGBA(Quantity_Color(r, g, b, Quantity_TOC_sRGB), a),
                         XCAFDoc_ColorType.XCAFDoc_ColorSurf)
        named(shapes.AddComponent(assembly, part, TopLoc_Location()), part_name)
    if as_cadquery_does:
        top = TDF_Label()
        shapes.SetLocation(assembly, TopLoc_Location(), top)
        named(top, name)
    shapes.UpdateAssemblies()
    return document


def style_blocks(model) -> list[tuple[int, int, int]]:
    """The parts' colour styles in a STEP model, as OCCT adds them last: (part, first entity, entities) for each,
    in the model's order; part 0 is the gear, 1 the stock (recognised by the COLOUR_RGB, the parts' colours are
    ours), 2 a colour of neither. A style is the block of entities from its
    MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION to the next one or the model's end."""
    from OCP.StepVisual import StepVisual_ColourRgb
    from OCP.StepVisual import StepVisual_MechanicalDesignGeometricPresentationRepresentation as Presentation

    count = len(_entities_of_type(model, Presentation))
    last = model.NbEntities()
    starts: list[int] = []
    index = last
    while len(starts) < count and index > 0:  # the styles are the model's last entities: a short walk back
        if isinstance(model.Value(index), Presentation):
            starts.append(index)
        index -= 1
    starts.sort()
    part_of_colour: dict[tuple[float, ...] | None, int] = {
        colour[:3]: part for part, colour in enumerate((GEAR_COLOUR, STOCK_COLOUR))}
    blocks = []
    for start, end in zip(starts, [*(start - 1 for start in starts[1:]), last]):
        entities = [model.Value(i) for i in range(start, end + 1)]
        colour = next((entity for entity in entities if isinstance(entity, StepVisual_ColourRgb)), None)
        rgb = None if colour is None else tuple(round(value, 6) for value in (colour.Red(), colour.Green(),
                                                                              colour.Blue()))
        blocks.append((part_of_colour.get(rgb, len(part_of_colour)), start, end - start + 1))
    return blocks


def swap_style_blocks(model, first: tuple[int, int, int], second: tuple[int, int, int]) -> None:
    """Move the `second` of two adjacent style blocks (style_blocks' (part, first entity, entities)) before the
    `first`, one entity at a time: OCCT's ChangeOrder moves a block forward only over at least as many entities
    as it holds, and the two blocks differ in size (the stock's translucency adds two entities)."""
    _, first_start, _ = first
    _, second_start, second_size = second
    for k in range(second_size):
        model.ChangeOrder(second_start + k, first_start + k, 1)


def _styles_in_part_order(model) -> None:
    """Put the parts' two colour styles in the parts' order, gear then stock: OCCT adds them in an order that
    changes from run to run (its map of styles is keyed by the shapes' addresses), and two runs must write the
    same bytes. Styles not recognised as the two parts' are left as OCCT wrote them."""
    blocks = style_blocks(model)
    if [part for part, _, _ in blocks] == [1, 0]:
        swap_style_blocks(model, *blocks)


def _assembly_writer(gear: TopoDS_Shape, stock: TopoDS_Shape, timestamp: str | None):
    """A STEP writer holding the assembly as CadQuery's default STEP export writes it (colours, layers, names),
    transferred, its model owned (_own_model) and not yet written."""
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Writer
    from OCP.STEPControl import STEPControl_StepModelType
    from OCP.XSControl import XSControl_WorkSession

    document = job_document(gear, stock)
    writer = STEPCAFControl_Writer(XSControl_WorkSession(), False)
    writer.SetColorMode(True)
    writer.SetLayerMode(True)
    writer.SetNameMode(True)
    _settings()
    Interface_Static.SetIVal_s("write.stepcaf.subshapes.name", 1)
    writer.Transfer(document, STEPControl_StepModelType.STEPControl_AsIs)
    _own_model(writer.ChangeWriter().Model(), None, timestamp)
    return writer


def _export_assembly(gear: TopoDS_Shape, stock: TopoDS_Shape, folder: Path, timestamp: str | None) -> bytes:
    """job.step: the assembly with its colour styles in the parts' order."""
    from OCP.IFSelect import IFSelect_RetDone

    writer = _assembly_writer(gear, stock, timestamp)
    _styles_in_part_order(writer.ChangeWriter().Model())
    path = folder / "job.step"
    if writer.Write(str(path)) != IFSelect_RetDone:
        raise RuntimeError("OCP could not write job.step")
    return path.read_bytes()


def step_files(gear: TopoDS_Shape, stock: TopoDS_Shape, timestamp: str | None = None) -> dict[str, bytes]:
    """{'gear.step', 'stock.step', 'job.step'} as bytes from the two solids (machine frame); `timestamp`
    ('YYYY-MM-DDTHH:MM:SS', UTC) is the headers' time, OCCT's clock when None."""
    with tempfile.TemporaryDirectory(prefix="spur_cad_step_") as tmp:
        folder = Path(tmp)
        return {"gear.step": _export_shape(gear, "gear", folder, timestamp),
                "stock.step": _export_shape(stock, "stock", folder, timestamp),
                "job.step": _export_assembly(gear, stock, folder, timestamp)}
