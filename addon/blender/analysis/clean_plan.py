"""What the clean-up will do to a mesh, before it does it (the Clean Up operator's preview).

A plan is the clean-up run on the mesh's arrays without writing them back: the loops and holes it
removes and those it leaves, in the mesh's vertex ids. The operator shows the plan (overlays and
counts) while the user decides, then writes the very same result, so what was shown is what is
done. Plans are runtime state, kept per object for the mesh and the sizes they were made for.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ...core.api.clean import CleanResult, clean
from ..io import mesh_read
from ..preview import watch

_plans: dict = {}    # object name -> Plan (the last one made)
_shown: dict = {}    # object name -> Plan on preview
revision = [0]       # bumped when what is shown changes (the overlays' cache key)


@dataclass
class Plan:
    key: tuple                    #: (mesh fingerprint, sizes)
    result: CleanResult

    @property
    def handles(self) -> int:
        return self.result.count("handle") + self.result.count("tunnel")

    @property
    def holes(self) -> int:
        return self.result.count("hole")

    @property
    def left(self) -> int:
        return len(self.result.left)

    def loops(self, removed: bool) -> list:
        """(kind, vertex ids of the input) of the loops and holes removed (or left); ids of
        vertices an earlier step created are -1. A left component has no loop: not listed."""
        items = self.result.removed if removed else self.result.left
        return [(item.kind, np.asarray(item.vertices, dtype=np.int64)) for item in items if len(item.vertices) >= 3]

    def summary(self) -> str:
        return (f"removes {self.handles} handle{'s' if self.handles != 1 else ''}, fills {self.holes} "
                f"hole{'s' if self.holes != 1 else ''}; leaves {self.left}")


def mesh_key(obj) -> tuple:
    """Fingerprint of ``obj``'s mesh: connectivity and positions (object mode data)."""
    digest = hashlib.blake2b(mesh_read.read_positions(obj.data).data, digest_size=16).hexdigest()
    return watch.connectivity_stamp(obj.data), digest


def plan(obj, arrays, max_handle: str, max_hole: str, keep_largest: Optional[int]) -> Plan:
    """The clean-up of ``arrays`` (``obj``'s mesh as read) with these sizes: the last plan made
    for ``obj`` when it is for the same mesh and sizes, else a new one. Raises ValueError."""
    key = (mesh_key(obj), (max_handle, max_hole, keep_largest))
    known = _plans.get(obj.name_full)
    if known is not None and known.key == key:
        return known
    result = clean(arrays.vertices, arrays.triangles, max_handle=max_handle, max_hole=max_hole,
                   keep_largest=keep_largest)
    made = _plans[obj.name_full] = Plan(key, result)
    return made


def show(obj, shown: Plan) -> None:
    _shown[obj.name_full] = shown
    revision[0] += 1


def hide(obj=None) -> None:
    """Ends the preview of ``obj`` (of every object with None) and forgets its plans."""
    names = list(_shown) if obj is None else [obj.name_full]
    for name in names:
        _shown.pop(name, None)
        _plans.pop(name, None)
    revision[0] += 1


def any_shown() -> bool:
    return bool(_shown)


def shown(obj) -> Optional[Plan]:
    """The plan on preview for ``obj``, when one is and it still describes its mesh."""
    on_preview = _shown.get(obj.name_full)
    if on_preview is None or obj.type != "MESH" or obj.mode == "EDIT":
        return None
    if on_preview.key[0][0] != watch.current_stamp(obj):  # connectivity changed: the ids are stale
        return None
    return on_preview
