"""Bulk access to a Blender mesh's collections and attributes (foreach_get / foreach_set only,
no per-element loops), shared by reading and writing.

Where Blender keeps a field as a plain attribute (positions and UV maps from 3.5, material slots
and flat shading from 4.0, index fields from 3.6/4.0), it is read and written through that
attribute: its foreach_get/set copy the array at once, while MeshVertex.co, MeshUVLoop.uv and the
like go one element at a time (30 to 100 times slower in 4.5 and 5.0). Blender 3.x's edge, loop
and polygon structs go through dna_arrays.
"""

from __future__ import annotations

from typing import Optional

import bpy
import numpy as np

from ...core.support import fresh_memory
from . import dna_arrays


def read_array(collection, key: str, count: int, width: int, dtype) -> np.ndarray:
    """``count`` elements' property ``key`` (``width`` values each) as a new array of ``dtype``."""
    buffer = fresh_memory.empty(count * width, dtype)
    if count:
        collection.foreach_get(key, buffer)
    return buffer.reshape(count, width) if width > 1 else buffer


def read_indices(collection, key: str, count: int, width: int = 1) -> np.ndarray:
    """An index property as int32. Blender keeps many index fields as unsigned ints: a uint32
    buffer takes foreach_get's raw-copy path there (about 10x faster than int32 on 3.4)."""
    return read_array(collection, key, count, width, np.uint32).view(np.int32)


def typed_attribute(mesh, name: str, domain: str, data_type: str):
    """``mesh``'s attribute ``name`` when it has that domain and type, else None."""
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.domain, attribute.data_type) == (domain, data_type):
        return attribute
    return None


def attribute_for_write(mesh, name: str, data_type: str, domain: str):
    """``mesh``'s attribute ``name`` of that type and domain: the one it has, or made now (one of
    that name with another type or domain is replaced). Making an attribute invalidates Python
    references to the mesh's other attributes."""
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.domain, attribute.data_type) != (domain, data_type):
        mesh.attributes.remove(attribute)
        attribute = None
    return attribute if attribute is not None else mesh.attributes.new(name, data_type, domain)


# The mesh collection holding each attribute domain's elements.
DOMAIN_COLLECTIONS = {"POINT": "vertices", "EDGE": "edges", "FACE": "polygons", "CORNER": "loops"}


def domain_size(mesh, domain: str) -> int:
    """How many elements an attribute domain has in ``mesh`` (-1 for a domain it has no collection for)."""
    return len(getattr(mesh, DOMAIN_COLLECTIONS[domain])) if domain in DOMAIN_COLLECTIONS else -1


def first_attribute(mesh: bpy.types.Mesh, names):
    """The first of ``names`` that ``mesh`` has as an attribute, or None."""
    for name in names:
        attribute = mesh.attributes.get(name)
        if attribute is not None:
            return attribute
    return None


def write_indices(mesh, attribute: Optional[str], collection, key: str, values: np.ndarray) -> None:
    """Writes an index field: the internal attribute where Blender has one (``attribute``, 3.6+ /
    4.0+: a plain int array; None where no version has one), else the 3.x struct field in one
    pass (dna_arrays.write_field, about a third faster for a preview frame's geometry), else
    through a uint32 buffer (foreach_set, which 3.x copies field by field)."""
    flat = np.ascontiguousarray(values, dtype=np.int32).ravel()
    layer = mesh.attributes.get(attribute) if attribute else None
    if layer is not None:
        layer.data.foreach_set("value", flat)
    elif not dna_arrays.write_field(collection, key, flat):
        collection.foreach_set(key, flat.view(np.uint32))
