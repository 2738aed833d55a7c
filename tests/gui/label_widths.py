"""Which texts of a panel Blender draws cut ("Regene…"), from the layout Blender built.

Runs inside Blender (imported by labels_script.py). ``UILayout.introspect()`` gives the layout
as Blender resolved it: property splits made into label and value columns, expanded enums into
rows of buttons, every button's type and full text. Blender's layout rules (ui_layout.cc) then
give each button its width: a column passes its width on, a split gives its first column its
factor (0.4 for a property split), a row shares its width in proportion to each item's natural
width (``ui_text_icon_width``: ten units for a text in a panel, one for an icon alone) with a
floor of two units. A text is cut
when its width (blf, Blender's UI font and size) and the button's own margins do not fit.
"""

from __future__ import annotations

import ast

import blf
import bpy

PROPERTY_SPLIT = 0.4  # UI_ITEM_PROP_SEP_DIVIDE

# eButType values (UI_interface.h, the same in 3.4 and 4.x): (name, extra width in units beside
# the text: margins, icon, a menu's arrow, a number field's arrows, a checkbox's box)
BUTTON_TYPES = {512: ("button", 0.7), 1024: ("choice", 0.7), 1536: ("text field", 1.0), 2048: ("menu", 1.7),
                3072: ("number", 1.2), 3584: ("slider", 1.2), 4096: ("toggle", 0.7), 4608: ("toggle", 0.7),
                5120: ("toggle", 0.7), 6144: ("toggle", 0.7), 6656: ("checkbox", 1.5), 7168: ("checkbox", 1.5),
                10240: ("label", 0.7), 12288: ("search", 1.7)}


def unit() -> float:
    """Blender's UI_UNIT_X in pixels (20 at scale 1)."""
    return 20.0 * (bpy.context.preferences.system.ui_scale or 1.0)


def text_width(text: str) -> float:
    """Pixel width of ``text`` in the widget font at the current UI scale."""
    scale = bpy.context.preferences.system.ui_scale or 1.0
    style = bpy.context.preferences.ui_styles[0].widget
    try:
        blf.size(0, style.points * scale)
    except TypeError:  # Blender before 4.0 takes a dpi argument
        blf.size(0, style.points * scale, 72)
    return blf.dimensions(0, text)[0]


#: Texts the panels drew with an icon (introspect() does not say): filled by IconRecorder
ICON_TEXTS = set()


def _icon(item) -> bool:
    return item.get("draw_string", "") in ICON_TEXTS


class IconRecorder:
    """Stands for a UILayout in a panel's draw(): passes every call on, and notes the texts drawn
    with an icon (a default text resolved as Blender does: the property's or operator's name)."""

    def __init__(self, layout):
        object.__setattr__(self, "_layout", layout)

    def __getattr__(self, name):
        attribute = getattr(self._layout, name)
        if name in ("row", "column", "split", "box", "grid_flow", "column_flow", "menu_pie"):
            return lambda *args, **kwargs: IconRecorder(attribute(*args, **kwargs))
        if name in ("label", "operator", "prop", "prop_search", "menu", "operator_menu_enum"):
            def call(*args, **kwargs):
                if kwargs.get("icon", "NONE") != "NONE":
                    ICON_TEXTS.add(_default_text(name, args, kwargs))
                return attribute(*args, **kwargs)
            return call
        return attribute

    def __setattr__(self, name, value):
        setattr(self._layout, name, value)


def _default_text(kind, args, kwargs) -> str:
    if "text" in kwargs:
        return kwargs["text"]
    if kind == "operator":
        module, name = args[0].split(".")
        return getattr(bpy.types, f"{module.upper()}_OT_{name}").bl_label
    if kind in ("prop", "prop_search"):
        return args[0].bl_rna.properties[args[1]].name
    return ""


def needed(item) -> float:
    """Width a button needs to show its whole text."""
    kind, extra = BUTTON_TYPES.get(item["type"], ("other", 0.7))
    text = item.get("draw_string", "")
    width = text_width(text) + extra * unit()
    return width + (unit() if _icon(item) else 0.0)


def natural(item) -> float:
    """The width Blender gives an item in a row before sharing (ui_text_icon_width): in a panel's
    rows (alignment "EXPAND", not of variable size) ten units for any text, one unit for an icon
    alone, so texts share a row equally; a nested layout: the sum (row) or the widest (column)."""
    if "items" in item:
        sizes = [natural(child) for child in item["items"]]
        if not sizes:
            return 0.0
        return sum(sizes) if item["type"] in ("LAYOUT_ROW", "LAYOUT_SPLIT") else max(sizes)
    text = item.get("draw_string", "")
    if not text:
        return unit()
    return 10 * unit()


def _with_label(items) -> bool:
    """A row Blender made for a property's name beside its menu or field (ui_item_with_label,
    outside a property split): its label's natural width is a third of the field's."""
    return (len(items) == 2 and items[0].get("type") == 10240 and "rna" not in items[0]
            and "rna" in items[1])


def _row_widths(items, width: float, align: bool) -> list:
    """ui_litem_layout_row: shares ``width`` in proportion to the natural widths; items that would
    get less than min(2 units, natural) keep that minimum and the rest is shared again."""
    space = 0.0 if align else 0.3 * unit()
    available = width - (len(items) - 1) * space
    sizes = [natural(i) for i in items]
    if _with_label(items):
        sizes[0] = sizes[1] / 3
    fixed = [False] * len(items)
    while True:
        free_total = sum(s for s, f in zip(sizes, fixed) if not f)
        fixed_total = sum(min(2 * unit(), s) for s, f in zip(sizes, fixed) if f)
        share = (available - fixed_total) / free_total if free_total else 0.0
        changed = False
        for k, size in enumerate(sizes):
            if not fixed[k] and size * share < min(2 * unit(), size):
                fixed[k] = changed = True
        if not changed:
            break
    return [min(2 * unit(), s) if f else s * share for s, f in zip(sizes, fixed)]


def _is_property_split(item) -> bool:  # (its labels never have an icon: Blender draws it in the value)
    """A split Blender made for use_property_split: a column holding the label, then the value."""
    first = item["items"][0] if item["items"] else {}
    return (len(item["items"]) == 2 and first.get("type") == "LAYOUT_COLUMN"
            and all(child.get("type") == 10240 for child in first.get("items", [])))


def cut_texts(item, width: float, path=()) -> list:
    """(text, needed, available) of every button in ``item`` whose text does not fit."""
    kind = item.get("type")
    if "items" not in item:
        text = item.get("draw_string", "")
        if text and needed(item) > width:
            return [(text, round(needed(item)), round(width), " > ".join(path))]
        return []
    children = item["items"]
    if kind == "LAYOUT_BOX":
        widths = [width - 2 * 0.25 * unit()] * len(children)
    elif kind == "LAYOUT_ROW":
        widths = _row_widths(children, width, align=True) if children else []
    elif kind == "LAYOUT_SPLIT" and children:
        # a split of the panels' own has no factor in introspect(): the least share it could give
        factor = PROPERTY_SPLIT if _is_property_split(item) else min(PROPERTY_SPLIT, 1 / len(children))
        first = width * factor
        rest = (width - first) / max(1, len(children) - 1)
        widths = [first] + [min(first, rest) if not _is_property_split(item) else rest] * (len(children) - 1)
    elif kind in ("LAYOUT_GRID_FLOW", "LAYOUT_COLUMN_FLOW"):  # columns not introspected: the worst case
        widths = [width / max(1, len(children))] * len(children)
    else:
        widths = [width] * len(children)
    found = []
    for child, child_width in zip(children, widths):
        found += cut_texts(child, child_width, path + (kind,))
    return found


def parse(introspection) -> list:
    """introspect() returns a list whose items are dicts (or their text in some versions)."""
    items = introspection if isinstance(introspection, list) else [introspection]
    return [ast.literal_eval(i) if isinstance(i, str) else i for i in items]
