"""The objects' properties as job-file values: adding them (schema.py's fields), reading and writing them, and
the Job they describe. Used by the proxies (features), the task panel and the commands and importing none of
them, so that features can open the task panel without an import loop.
"""

from __future__ import annotations

import FreeCAD

from spur_cad_workbench import schema

PROP_READ_ONLY = 1
PROP_OUTPUT = 8


def property_value(field, value):
    """A job-file value as the property takes it: a speed or a micrometre length as a Quantity in its key's unit
    (mm/min, um)."""
    if field.unit in schema.SET_IN_KEY_UNIT:
        return FreeCAD.Units.Quantity(f"{float(value)!r} {field.unit}")
    return value


def _set_choices(obj, field) -> bool:
    """Give a drop-down property its list (keeping a value still in it); False if it had that list already."""
    if list(obj.getEnumerationsOfProperty(field.prop) or []) == list(field.choices):
        return False
    current = getattr(obj, field.prop)
    setattr(obj, field.prop, list(field.choices))
    if current in field.choices:
        setattr(obj, field.prop, current)
    return True


def add_fields(obj, fields, values: dict | None = None, outputs: bool = False) -> list[str]:
    """Add the properties of `fields` that `obj` lacks, set them from `values` (inputs) when given;
    re-create those whose saved type differs from the schema's (keeping the value) and update
    drop-down lists. Returns the names of the properties added or changed."""
    attr = PROP_READ_ONLY | PROP_OUTPUT if outputs else 0
    changed = []
    for field in fields:
        value = values.get(field.prop) if values is not None else None
        expressions: list[tuple[str, str]] = []
        if field.prop in obj.PropertiesList:
            if obj.getGroupOfProperty(field.prop) != field.group:  # a group of an older schema
                obj.setGroupOfProperty(field.prop, field.group)
                changed.append(field.prop)
            if obj.getTypeIdOfProperty(field.prop) == field.property_type:
                if field.kind == "choice" and _set_choices(obj, field):
                    changed.append(field.prop)
                continue
            value = schema.plain_value(field, getattr(obj, field.prop))  # a type of an older schema
            # removing a property drops the expressions bound to it (a spreadsheet driving the gear): kept
            expressions = [(path, text) for path, text in obj.ExpressionEngine if path == field.prop]
            obj.removeProperty(field.prop)
        obj.addProperty(field.property_type, field.prop, field.group, field.doc, attr)
        changed.append(field.prop)
        if field.kind == "choice":
            setattr(obj, field.prop, list(field.choices))
        if value is not None and not outputs:
            setattr(obj, field.prop, property_value(field, value))
        for path, text in expressions:
            obj.setExpression(path, text)
    return changed


def read_values(obj, fields) -> dict:
    """{property name: plain value in the job file's unit} of `fields` on `obj`."""
    return {field.prop: schema.plain_value(field, getattr(obj, field.prop)) for field in fields}


def write_values(obj, values: dict) -> None:
    """Set properties whose value differs (setting an equal value would still touch the object)."""
    for prop, value in values.items():
        field = schema.field_by_prop(prop)
        if schema.plain_value(field, getattr(obj, prop)) != value:
            setattr(obj, prop, property_value(field, value))


def write_outputs(obj, values: dict) -> None:
    """Set read-only computed properties."""
    write_values(obj, values)


def add_bookkeeping(obj) -> None:
    """SchemaVersion (for migration) and Status (last recompute's outcome), both read-only."""
    if "SchemaVersion" not in obj.PropertiesList:
        obj.addProperty("App::PropertyInteger", "SchemaVersion", schema.STATUS_GROUP,
                        "schema of this object's properties", PROP_READ_ONLY)
        obj.SchemaVersion = schema.SCHEMA_VERSION
    if "Status" not in obj.PropertiesList:
        obj.addProperty("App::PropertyString", "Status", schema.STATUS_GROUP, "outcome of the last recompute",
                        PROP_READ_ONLY | PROP_OUTPUT)
    for prop in ("SchemaVersion", "Status"):
        if obj.getGroupOfProperty(prop) != schema.STATUS_GROUP:  # "Base" before schema 3
            obj.setGroupOfProperty(prop, schema.STATUS_GROUP)


def linked(obj, prop: str, kind: str):
    """The object linked by `prop`, checked to be a spur_cad `kind` ('gear', 'stock', ...)."""
    from spur_cad.errors import SpurCadError

    target = getattr(obj, prop, None)
    if target is None:
        raise SpurCadError(f"no {kind} linked (property {prop})")
    if getattr(getattr(target, "Proxy", None), "KIND", None) != kind:
        raise SpurCadError(f"{prop} links {target.Label}, which is not a spur_cad {kind}")
    return target


def document_values(obj) -> dict[str, dict]:
    """Property values of the gear / stock / job behind `obj` (and the objects it links)."""
    kind = obj.Proxy.KIND
    if kind == "gear":
        return {"gear": read_values(obj, schema.GEAR_FIELDS)}
    if kind == "stock":
        gear = linked(obj, "Gear", "gear")
        return {"gear": read_values(gear, schema.GEAR_FIELDS), "stock": read_values(obj, schema.STOCK_FIELDS)}
    if kind == "job":
        stock = linked(obj, "Stock", "stock")
        gear = linked(obj, "Gear", "gear")
        return {"gear": read_values(gear, schema.GEAR_FIELDS), "stock": read_values(stock, schema.STOCK_FIELDS),
                "job": read_values(obj, schema.JOB_FIELDS)}
    raise ValueError(f"not a spur_cad object with job values: {obj.Label}")


def source_of(obj) -> str:
    """What a job built from the document says it came from: the document's file, else its name."""
    return obj.Document.FileName or obj.Document.Name


def job_of(obj):
    """The validated spur_cad Job (or its gear/stock part) described by `obj`; raises SpurCadError."""
    from spur_cad.job import job_from_dict

    return job_from_dict(schema.job_data(document_values(obj)), source_of(obj))
