"""Guidance maths for the add-on and the batch tool (no Blender needed).

Every guidance source gives a value ``u`` in [-1, 1] per vertex (docs/design.md §2.2): ``u = 0`` follows
the global target, ``u > 0`` keeps more (``u = 1``: always kept), ``u < 0`` keeps less
(``u = -1``: never sampled unless the topology needs it).

How the sources map to ``u``:

- **Vertex group** (weight ``w`` in [0, 1]; vertices outside the group have no opinion):
  ``"DETAIL"`` (default) ``u = w`` - paint where detail matters, like a heat map;
  ``"SIGNED"`` ``u = 2w - 1`` - one group covers the whole range, 0.5 is neutral;
  ``"DECIMATE"`` ``u = 1 - w`` - Blender's own Decimate modifier convention, where weight 0
  locks a vertex and weight 1 lets it go freely.
- **Colour attribute** painted in Vertex Paint mode, read as display (sRGB) values:
  ``u = red - blue``. Orange/warm = more detail, blue/cool = less, any grey (and white or
  black) = neutral. The palette ``GUIDANCE_LEVELS`` / ``guidance_color`` uses green 0.5:
  keep = (1, 0.5, 0) orange, more = (0.75, 0.5, 0.25), neutral = (0.5, 0.5, 0.5) grey,
  less = (0.25, 0.5, 0.75), drop = (0, 0.5, 1) blue. Corner-domain colours are averaged per
  vertex.
- **Material slots**: each slot has a weight in [-1, 1]; a vertex takes the largest weight of
  the slots of its faces (so a border vertex leans to the side that wants more detail).

Combining enabled sources (``combine``), each with a strength ``s`` in [0, 1]:

1. every source's values are scaled: ``c = s * u``;
2. ``u = clip(sum of c, -1, 1)``;
3. hard decisions win: where any source says ``c = +1`` the vertex is kept (``u = 1``); else
   where any says ``c = -1`` it is dropped (``u = -1``). Keep beats drop, because lost detail
   cannot be recovered.

Applied afterwards by the engine: box empties (a vertex inside a box takes that box's
weight, the last box wins where boxes overlap) and the view (back faces ``p *= back_ratio``,
silhouette band ``p = 1``, outside the frustum at most ``outside_probability``). UV seams,
sharp edges and material borders are not guidance but borders: no cluster crosses them
(UV seams are found by topstoc.core.carry.attributes.uv_seam_edges).
"""

from __future__ import annotations

from typing import Iterable, Optional, Sequence, Tuple

import numpy as np
from ..support.errors import TopStocError

#: Direct-selection levels (thesis fig. 4.13): name -> u.
GUIDANCE_LEVELS = {"KEEP": 1.0, "MORE": 0.5, "NEUTRAL": 0.0, "LESS": -0.5, "DROP": -1.0}

VERTEX_GROUP_MAPPINGS = ("DETAIL", "SIGNED", "DECIMATE")


def srgb_to_linear(values: np.ndarray) -> np.ndarray:
    """sRGB display values to scene-linear (the IEC 61966-2-1 curve), element-wise."""
    c = np.clip(np.asarray(values, dtype=np.float64), 0.0, None)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(values: np.ndarray) -> np.ndarray:
    """Scene-linear values to sRGB display values, element-wise."""
    c = np.clip(np.asarray(values, dtype=np.float64), 0.0, None)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1.0 / 2.4) - 0.055)


def guidance_color(u) -> np.ndarray:
    """The display (sRGB) RGBA colour that encodes guidance ``u`` (array or scalar)."""
    u = np.clip(np.asarray(u, dtype=np.float64), -1.0, 1.0)
    rgba = np.empty(u.shape + (4,))
    rgba[..., 0] = 0.5 + 0.5 * u
    rgba[..., 1] = 0.5
    rgba[..., 2] = 0.5 - 0.5 * u
    rgba[..., 3] = 1.0
    return rgba


def color_to_guidance(srgb: np.ndarray) -> np.ndarray:
    """Guidance from display (sRGB) colours of shape (..., 3 or 4): ``u = red - blue``."""
    srgb = np.asarray(srgb, dtype=np.float64)
    if srgb.ndim < 1 or srgb.shape[-1] not in (3, 4):
        raise TopStocError(f"colours must have 3 or 4 channels, got shape {srgb.shape}")
    u = np.clip(srgb[..., 0], 0, 1) - np.clip(srgb[..., 2], 0, 1)
    return np.where(np.isfinite(u), u, 0.0)


def vertex_group_guidance(weights: np.ndarray, assigned: np.ndarray, mapping: str = "DETAIL") -> np.ndarray:
    """Guidance from vertex-group weights (one per vertex); unassigned vertices get 0."""
    if mapping not in VERTEX_GROUP_MAPPINGS:
        raise TopStocError(f"vertex group mapping must be one of {VERTEX_GROUP_MAPPINGS}, got {mapping!r}")
    w = np.clip(np.asarray(weights, dtype=np.float64), 0.0, 1.0)
    if mapping == "DETAIL":
        u = w
    elif mapping == "SIGNED":
        u = 2.0 * w - 1.0
    else:
        u = 1.0 - w
    return np.where(np.asarray(assigned, dtype=bool), u, 0.0)


def corner_to_vertex_mean(num_vertices: int, corner_vertex: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Per-vertex mean of per-corner values (k channels); vertices with no corner get 0."""
    corner_vertex = np.asarray(corner_vertex, dtype=np.int64)
    values = np.asarray(values, dtype=np.float64).reshape(len(corner_vertex), -1)
    count = np.bincount(corner_vertex, minlength=num_vertices).astype(np.float64)
    out = np.stack([np.bincount(corner_vertex, weights=values[:, k], minlength=num_vertices)
                    for k in range(values.shape[1])], axis=1)
    return out / np.maximum(count, 1.0)[:, None]


def material_guidance(num_vertices: int, triangles: np.ndarray, triangle_slot: np.ndarray,
                      slot_weights: Sequence[float]) -> np.ndarray:
    """Per-vertex guidance from per-slot weights: the largest weight among a vertex's faces.

    Slots without a weight (index past the list) count as 0. Vertices in no face get 0.
    """
    weights = np.zeros(max(len(slot_weights), int(np.max(triangle_slot, initial=-1)) + 1))
    weights[:len(slot_weights)] = np.clip(np.asarray(slot_weights, dtype=np.float64), -1, 1)
    per_corner = np.repeat(weights[np.asarray(triangle_slot, dtype=np.int64)], 3)
    u = np.full(num_vertices, -np.inf)
    np.maximum.at(u, np.asarray(triangles, dtype=np.int64).ravel(), per_corner)
    return np.where(np.isfinite(u), u, 0.0)


def combine(sources: Iterable[Tuple[np.ndarray, float]], num_vertices: int) -> Optional[np.ndarray]:
    """Combines (u, strength) pairs by the rules in the module docs; None when no source."""
    total = np.zeros(num_vertices)
    keep = np.zeros(num_vertices, dtype=bool)
    drop = np.zeros(num_vertices, dtype=bool)
    used = False
    for values, strength in sources:
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (num_vertices,):
            raise TopStocError(f"a guidance source has shape {values.shape}, expected ({num_vertices},)")
        s = float(np.clip(strength, 0.0, 1.0))
        c = s * np.clip(np.nan_to_num(values, nan=0.0), -1.0, 1.0)
        total += c
        keep |= c >= 1.0
        drop |= c <= -1.0
        used = True
    if not used:
        return None
    u = np.clip(total, -1.0, 1.0)
    u[drop] = -1.0
    u[keep] = 1.0
    return u


def undirected_edges(triangles: np.ndarray) -> np.ndarray:
    """The distinct undirected edges (k, 2) of the triangles (low id first), sorted."""
    triangles = np.asarray(triangles, dtype=np.int64)
    if len(triangles) == 0:
        return np.zeros((0, 2), dtype=np.int32)
    a, b = triangles.ravel(), triangles[:, [1, 2, 0]].ravel()
    keep = a != b
    low, high = np.minimum(a, b)[keep], np.maximum(a, b)[keep]
    n1 = int(triangles.max()) + 1
    keys = np.unique(low * n1 + high)
    return np.stack([keys // n1, keys % n1], axis=1).astype(np.int32)


def edges_in(edges: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """The rows of ``candidates`` (k, 2) that are edges of ``edges`` (sorted, low id first)."""
    candidates = np.asarray(candidates, dtype=np.int64).reshape(-1, 2)
    if len(candidates) == 0 or len(edges) == 0:
        return np.zeros((0, 2), dtype=np.int32)
    low, high = candidates.min(axis=1), candidates.max(axis=1)
    n1 = int(max(edges.max(), high.max())) + 1
    known = edges[:, 0].astype(np.int64) * n1 + edges[:, 1]
    keys = np.unique(low * n1 + high)
    keys = keys[np.isin(keys, known)]
    return np.stack([keys // n1, keys % n1], axis=1).astype(np.int32)


def compact_regions(*ids: np.ndarray) -> Optional[np.ndarray]:
    """One region id per triangle from several per-triangle ids (None entries skipped)."""
    columns = [np.asarray(i, dtype=np.int64) for i in ids if i is not None]
    if not columns:
        return None
    if len(columns) == 1:
        return np.unique(columns[0], return_inverse=True)[1].astype(np.int32)
    _, inverse = np.unique(np.stack(columns, axis=1), axis=0, return_inverse=True)
    return inverse.reshape(-1).astype(np.int32)
