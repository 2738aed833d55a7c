"""What a mesh looks like, as the engine's ``attributes``: UVs, colours and normals in the collapse cost.

Quality mode's collapses weigh ``decimate(attributes=, attribute_weights=)`` as generalised
quadrics (docs/design.md §2.10), so collapses that would bend a UV map or smear a colour cost
more. This module turns what a mesh carries into that argument, one layout for every caller
(the add-on, the command line, the batch): per corner of the caller's triangles, UV channels
(u, v) first, then colour channels (r, g, b; alpha is left out, it rarely shows in shading), then
normal channels (x, y, z of a unit vector).

Normals are passed only when they are data of their own: custom (split) normals, which the output
carries and which the shape cannot rebuild (a hard-surface asset's weighted or hard-edge shading).
Normals a program derives from the shape (smooth, flat, sharp edges, auto smooth) are left out:
the output gets them anew from its own faces, and the shape's quadrics already weigh the faces they
come from, so passing them would pay twice for the same thing and change every plain mesh's result.
A corner whose normal is missing (NaN) or of zero length takes its vertex's mean like a missing UV,
renormalised.

Missing UVs (NaN corners, as OBJ files without ``vt`` on some faces give): a corner without one
takes the mean UV its vertex has in the triangles that have one; a vertex with none anywhere takes
the mean of all known UVs, so a region without UVs is a constant field, which no collapse inside
it can bend (cost 0) and only the triangles bordering it see a slope. A map without any UV
contributes nothing. Colours must be finite.

The weight is the engine's: a difference ``d`` in a channel (UVs in texture units, colours in
[0, 1], normals as the length of the difference of two unit vectors: 2 sin(angle / 2), about the
angle in radians for small angles, 2 for opposite normals) costs as much as moving the surface by ``weight * d`` bounding-box diagonals
(ATTRIBUTE_WEIGHT by default); weight 0 passes nothing, so the result is the one without
attributes, to the bit. Fast mode ignores attributes (only the refinement uses them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

from ..support.errors import TopStocError

UV_CHANNELS = ("u", "v")
COLOR_CHANNELS = ("r", "g", "b")
NORMAL_CHANNELS = ("x", "y", "z")


@dataclass
class Appearance:
    """The engine's ``attributes`` for one mesh and what they hold."""

    values: Optional[np.ndarray] = None                #: (m, 3, k) float64 per triangle corner, or None
    channels: List[str] = field(default_factory=list)  #: what each of the k channels holds ("uv.u", "normal.x")
    uv_corners_filled: int = 0                         #: corners whose missing UV was filled in

    @property
    def used(self) -> List[str]:
        """The kinds of channel present, in order: "uv", "color", "normal"."""
        return list(dict.fromkeys(name.split(".")[0] for name in self.channels))

    def decimate_kwargs(self, weight: float) -> dict:
        """``decimate`` keywords at ``weight`` (validated): nothing when there are no channels
        or the weight is 0."""
        weight = attribute_weight(weight)
        if self.values is None or weight == 0.0:
            return {}
        return {"attributes": self.values, "attribute_weights": weight}


def refines(mode: str = "quality", refine=None) -> bool:
    """Whether a decimation with these ``decimate`` options runs the refinement, the only stage
    that uses attributes: quality and best modes unless ``refine`` is 0, fast mode when ``refine`` > 0."""
    if refine is None:
        return mode != "fast"
    return float(refine) > 0


def attribute_weight(weight) -> float:
    """``weight`` as a float; TopStocError unless it is a finite number >= 0."""
    try:
        value = float(weight)
    except (TypeError, ValueError):
        raise TopStocError(f"the attribute weight must be a number, got {weight!r}") from None
    if not math.isfinite(value) or value < 0:
        raise TopStocError(f"the attribute weight must be finite and >= 0, got {weight!r}")
    return value


def _fill_missing(triangles, corner_values, missing) -> np.ndarray:
    """``corner_values`` (m, 3, k) with the ``missing`` (m, 3) corners set to their vertex's mean
    over its known corners, or the mean of all known corners where a vertex has none."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    k = corner_values.shape[2]
    n = int(t.max()) + 1 if t.size else 0
    known = ~missing.ravel()
    vertex, flat = t.ravel(), corner_values.reshape(-1, k)
    count = np.bincount(vertex[known], minlength=n)
    sums = np.stack([np.bincount(vertex[known], weights=flat[known, i], minlength=n) for i in range(k)], axis=1)
    mean = np.where(count[:, None] > 0, sums / np.maximum(count, 1)[:, None], flat[known].mean(axis=0))
    flat = flat.copy()
    flat[~known] = mean[vertex[~known]]
    return flat.reshape(-1, 3, k)


def fill_missing_uvs(triangles, corner_uvs) -> tuple:
    """(corner UVs without NaN, corners filled) or (None, 0) when no corner has a UV; see the
    module docs for the rule. triangles (m, 3), corner_uvs (m, 3, 2); a corner counts as missing
    when either coordinate is NaN."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    uv = np.array(corner_uvs, dtype=np.float64)
    if uv.shape != (len(t), 3, 2):
        raise TopStocError(f"UVs must have shape (m, 3, 2) per triangle corner ({len(t)} triangles), "
                           f"got {uv.shape}")
    missing = ~np.isfinite(uv).all(axis=2)           # (m, 3)
    if missing.all():
        return None, 0
    if not missing.any():
        return uv, 0
    return _fill_missing(t, uv, missing), int(missing.sum())


def unit_corner_normals(triangles, corner_normals) -> Optional[np.ndarray]:
    """(m, 3, 3) unit normals per corner, or None when no corner has one; see the module docs.
    triangles (m, 3), corner_normals (m, 3, 3); a corner counts as missing when a coordinate is
    not finite or the normal has zero length."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    normals = np.asarray(corner_normals)
    if normals.dtype.kind not in "fiu" or normals.shape != (len(t), 3, 3):
        raise TopStocError(f"normals must be numbers of shape (m, 3, 3) per triangle corner ({len(t)} "
                           f"triangles), got {normals.dtype} {normals.shape}")
    normals = normals.astype(np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        length = np.linalg.norm(normals, axis=2)
    missing = ~(np.isfinite(length) & (length > 0))
    if missing.all():
        return None
    normals = normals / np.where(missing, 1.0, length)[:, :, None]
    if missing.any():
        normals = _fill_missing(t, np.where(missing[:, :, None], 0.0, normals), missing)
        length = np.linalg.norm(normals, axis=2, keepdims=True)  # a mean of unit vectors is shorter
        normals = np.where(length > 0, normals / np.where(length > 0, length, 1.0), normals)
    return normals


def _corner_colors(triangles, colors) -> np.ndarray:
    """(m, 3, 3) RGB per corner from per-vertex (n, c) or per-corner (m, 3, c) colours, c >= 3."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    c = np.asarray(colors)
    if c.dtype.kind not in "fiu":
        raise TopStocError(f"colours must be numbers, got dtype {c.dtype}")
    c = c.astype(np.float64)
    if c.ndim == 3 and c.shape[:2] == t.shape and c.shape[2] >= 3:
        rgb = c[:, :, :3]
    elif c.ndim == 2 and c.shape[1] >= 3 and (t.size == 0 or c.shape[0] > t.max()):
        rgb = c[t][:, :, :3]
    else:
        raise TopStocError(f"colours must have shape (n, 3 or 4) per vertex or (m, 3, 3 or 4) per corner "
                           f"({len(t)} triangles), got {c.shape}")
    bad = np.argwhere(~np.isfinite(rgb))
    if len(bad):
        tri, corner, channel = bad[0]
        raise TopStocError(f"colour channel {channel} of corner {corner} of triangle {tri} is "
                           f"{rgb[tri, corner, channel]}; it must be finite")
    return rgb


def appearance_attributes(triangles, corner_uvs=None, colors=None, corner_normals=None) -> Appearance:
    """The engine's ``attributes`` from a mesh's UVs, colours and custom normals (any may be None).

    triangles: (m, 3) the caller's triangles (the ones given to topstoc.Mesh); corner_uvs:
    (m, 3, 2) per triangle corner, NaN where a corner has none; colors: (n, 3|4) per vertex or
    (m, 3, 3|4) per corner, in [0, 1] for the weight to mean what it says; corner_normals:
    (m, 3, 3) per triangle corner, custom normals only (module docs), renormalised here."""
    parts, channels, filled = [], [], 0
    if corner_uvs is not None:
        uv, filled = fill_missing_uvs(triangles, corner_uvs)
        if uv is not None:
            parts.append(uv)
            channels += [f"uv.{name}" for name in UV_CHANNELS]
    if colors is not None:
        parts.append(_corner_colors(triangles, colors))
        channels += [f"color.{name}" for name in COLOR_CHANNELS]
    if corner_normals is not None:
        normals = unit_corner_normals(triangles, corner_normals)
        if normals is not None:
            parts.append(normals)
            channels += [f"normal.{name}" for name in NORMAL_CHANNELS]
    if not parts:
        return Appearance()
    values = np.ascontiguousarray(np.concatenate(parts, axis=2))
    return Appearance(values, channels, filled)
