"""What the viewport overlays draw, as plain arrays (no ``gpu`` here; see overlays.py).

Each builder turns results stored on an object into primitives in the object's local
coordinates: lines (pairs of points), points, or triangles with one colour per corner.
Results that no longer describe the mesh (it changed since) give no primitive. The arrays
are what the GUI tests and the background tests check; overlays.py only uploads them.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np

from ...core.support import colors
from ..io import mesh_read
from ..analysis import clean_plan, metrics
from ..preview import watch

LINES, POINTS, TRIS = "LINES", "POINTS", "TRIS"


@dataclass
class Primitive:
    """One draw call: ``positions`` (k, 3) float32 in object space; LINES take them in pairs,
    TRIS in triples. ``color`` is uniform unless ``colors`` (k, 4) gives one per point."""

    name: str
    kind: str
    positions: np.ndarray
    color: tuple = (1.0, 1.0, 1.0, 1.0)
    colors: Optional[np.ndarray] = None
    size: str = "line"  # which overlay setting gives its width: line, active, point

    def __len__(self) -> int:
        return len(self.positions)


def positions(mesh) -> np.ndarray:
    return mesh_read.read_positions(mesh)


def _id_array(group, key: str, dtype=np.int32) -> np.ndarray:
    value = group.get(key)
    if value is None:
        return np.zeros(0, dtype=dtype)
    return np.asarray(value.to_list() if hasattr(value, "to_list") else value, dtype=dtype)


def _valid(ids: np.ndarray, n: int) -> bool:
    return len(ids) == 0 or (ids.min() >= 0 and ids.max() < n)


def loop_segments(vertex_ids: np.ndarray) -> np.ndarray:
    """(2k,) vertex ids of the k edges of a closed loop, in pairs."""
    return np.stack([vertex_ids, np.roll(vertex_ids, -1)], axis=1).reshape(-1)


def topology_current(obj) -> bool:
    """True when the stored topology was computed on the mesh as it is now."""
    topology = obj.topstoc.topology
    return topology.state == "OK" and topology.stamp == watch.current_stamp(obj)


def topology_primitives(obj, show) -> list:
    """Loops, generator edges, boundary and non-manifold elements (``show``: overlay settings)."""
    if obj.type != "MESH" or not topology_current(obj):
        return []
    topology = obj.topstoc.topology
    co = positions(obj.data)
    n = len(co)
    out = []
    wanted = {"HANDLE": show.show_handles, "TUNNEL": show.show_tunnels, "BOUNDARY": show.show_boundary}
    color = {"HANDLE": colors.HANDLE, "TUNNEL": colors.TUNNEL, "BOUNDARY": colors.BOUNDARY}
    segments = {"HANDLE": [], "TUNNEL": []}
    for index, loop in enumerate(topology.loops):
        ids = _id_array(loop, "vertices")
        if len(ids) < 2 or not _valid(ids, n) or not wanted[loop.kind]:
            continue
        if index == topology.loop_index:
            out.append(Primitive("active_loop", LINES, co[loop_segments(ids)], color[loop.kind], size="active"))
            # its corners as dots of the same width: a loop of a few short edges stays visible when
            # zoomed out, as a dot at least (Frame Loop then shows it whole)
            out.append(Primitive("active_loop_points", POINTS, co[ids], color[loop.kind], size="active"))
        elif loop.kind in segments:
            segments[loop.kind].append(loop_segments(ids))
    for kind, name in (("HANDLE", "handles"), ("TUNNEL", "tunnels")):
        if segments[kind]:
            out.append(Primitive(name, LINES, co[np.concatenate(segments[kind])], color[kind]))
    if show.show_generators:
        edges = _id_array(topology, "generator_edges")
        if len(edges) and _valid(edges, n):
            out.append(Primitive("generators", LINES, co[edges], colors.GENERATOR))
    if show.show_boundary:
        ids = _id_array(topology, "boundary_vertices")
        if len(ids) and _valid(ids, n):
            out.append(Primitive("boundary", POINTS, co[ids], colors.BOUNDARY, size="point"))
    if show.show_nonmanifold:
        edges = _id_array(topology, "nonmanifold_edge_ids")
        if len(edges) and _valid(edges, n):
            out.append(Primitive("nonmanifold_edges", LINES, co[edges], colors.NONMANIFOLD))
        ids = _id_array(topology, "nonmanifold_vertex_ids")
        if len(ids) and _valid(ids, n):
            out.append(Primitive("nonmanifold_vertices", POINTS, co[ids], colors.NONMANIFOLD, size="point"))
    return out


def _corner_positions(obj):
    arrays = mesh_read.read_mesh(obj.data)
    return arrays, arrays.vertices.astype(np.float32)[arrays.triangles.reshape(-1)]


def error_primitives(obj, show, percent: float = None) -> list:
    """Per-face Hausdorff error colours, red at ``percent`` of the original's diagonal (default:
    the overlay's scale; the overlays pass metrics.shared_error_percent of the objects shown)."""
    if obj.type != "MESH" or not show.show_error or not metrics.is_current(obj):
        return []
    errors = metrics.face_errors(obj)
    if errors is None:
        return []
    arrays, corners = _corner_positions(obj)
    percent = show.error_scale if percent is None else percent
    face_colors = colors.error_colors(errors, metrics.error_scale(obj, percent))
    return [Primitive("error", TRIS, corners, colors=np.repeat(face_colors, 3, axis=0))]


# Labels of the last decimation per object: (geometry epoch, samples digest) -> labels or None.
_labels: dict = {}


def _samples_entry(obj):
    from ..decimation.pipeline import LAST_SAMPLES

    entry = obj.topstoc.sample_sets.get(LAST_SAMPLES)
    return entry if entry is not None and "samples" in entry else None


def last_decimation(obj, context=None):
    """(samples, labels) of the object's last decimation, re-created from its saved samples
    (thesis 4.1.3); None when there is none or the mesh changed since."""
    entry = _samples_entry(obj)
    if entry is None:
        return None
    samples = _id_array(entry, "samples")
    key = (watch.epoch(obj), hashlib.blake2b(samples.data, digest_size=8).hexdigest(), entry.parameters)
    memo = _labels.get(obj.name_full)
    if memo is not None and memo[0] == key:
        return memo[1]
    from ..decimation import pipeline

    value = None
    try:
        run = pipeline.restore(context or bpy.context, obj, entry.name)
        value = (np.asarray(run.result.samples), np.asarray(run.result.labels))
    except (ValueError, KeyError):  # the mesh or its borders changed: nothing to show
        value = None
    _labels[obj.name_full] = (key, value)
    return value


def decimation_primitives(obj, show, context=None) -> list:
    """Sampled vertices and cluster regions of the last decimation (thesis fig. 4.1)."""
    if obj.type != "MESH" or not (show.show_samples or show.show_clusters) or obj.mode == "EDIT":
        return []
    found = last_decimation(obj, context)
    if found is None:
        return []
    samples, labels = found
    out = []
    if show.show_clusters:
        arrays, corners = _corner_positions(obj)
        if len(labels) == len(arrays.vertices):
            face_colors = colors.cluster_face_colors(arrays.triangles, labels)
            out.append(Primitive("clusters", TRIS, corners, colors=np.repeat(face_colors, 3, axis=0)))
    if show.show_samples:
        co = positions(obj.data)
        if _valid(samples, len(co)):
            out.append(Primitive("samples", POINTS, co[samples], colors.SAMPLE, size="point"))
    return out


def _segments(loops, n: int) -> np.ndarray:
    """Vertex-id pairs of the loops' edges whose two ends are vertices of the mesh (a loop
    through vertices the clean-up creates has gaps there)."""
    pairs = [np.stack([ids, np.roll(ids, -1)], axis=1) for _kind, ids in loops]
    if not pairs:
        return np.zeros(0, dtype=np.int64)
    pairs = np.concatenate(pairs)
    return pairs[((pairs >= 0) & (pairs < n)).all(axis=1)].reshape(-1)


def clean_preview_primitives(obj) -> list:
    """The clean-up's preview: what it will remove (green, thick) and leave (violet)."""
    shown = clean_plan.shown(obj)
    if shown is None:
        return []
    co = positions(obj.data)
    out = []
    for removed, name, color, size in ((False, "clean_leave", colors.CLEAN_LEAVE, "line"),
                                       (True, "clean_remove", colors.CLEAN_REMOVE, "active")):
        ids = _segments(shown.loops(removed), len(co))
        if len(ids):
            out.append(Primitive(name, LINES, co[ids], color, size=size))
            out.append(Primitive(name + "_points", POINTS, co[np.unique(ids)], color, size=size))
    return out


def marked_loops(obj, show) -> list:
    """(points (k, 3) in object space, colour) of the loops that get a ring when they are small
    on screen: every loop of the clean-up's preview when it is shown, else every handle and
    tunnel loop shown and the active loop (a hole's too)."""
    co = positions(obj.data) if obj.type == "MESH" else np.zeros((0, 3), np.float32)
    out = []
    shown = clean_plan.shown(obj)
    if shown is not None:
        for removed, color in ((False, colors.CLEAN_LEAVE), (True, colors.CLEAN_REMOVE)):
            for _kind, ids in shown.loops(removed):
                ids = ids[(ids >= 0) & (ids < len(co))]
                if len(ids):
                    out.append((co[ids], color))
    if shown is None and obj.type == "MESH" and topology_current(obj):  # the preview rings replace these
        topology = obj.topstoc.topology
        wanted = {"HANDLE": show.show_handles, "TUNNEL": show.show_tunnels, "BOUNDARY": show.show_boundary}
        color = {"HANDLE": colors.HANDLE, "TUNNEL": colors.TUNNEL, "BOUNDARY": colors.BOUNDARY}
        for index, loop in enumerate(topology.loops):
            if not wanted[loop.kind] or (loop.kind == "BOUNDARY" and index != topology.loop_index):
                continue
            ids = _id_array(loop, "vertices")
            if len(ids) and _valid(ids, len(co)):
                out.append((co[ids], color[loop.kind]))
    return out


def small_loop_rings(loops, matrix, width: float, height: float, min_pixels: float) -> list:
    """(x, y, radius, colour) in region pixels of a ring around each loop smaller than
    ``min_pixels`` on screen. ``loops``: (points, colour) pairs; ``matrix``: the view's
    perspective matrix times the object's world matrix (4 x 4). Loops behind the eye get none."""
    rings = []
    if min_pixels <= 0:
        return rings
    matrix = np.asarray(matrix, dtype=np.float64)
    for points, color in loops:
        clip = np.c_[np.asarray(points, dtype=np.float64), np.ones(len(points))] @ matrix.T
        if (clip[:, 3] <= 1e-12).any():
            continue
        pixels = (clip[:, :2] / clip[:, 3:4] + 1.0) * 0.5 * np.array([width, height])
        low, high = pixels.min(axis=0), pixels.max(axis=0)
        if (high - low).max() < min_pixels:
            centre = (low + high) / 2
            rings.append((float(centre[0]), float(centre[1]), min_pixels / 2, color))
    return rings


def object_primitives(obj, show, context=None, error_percent: float = None) -> list:
    """Everything the overlays draw for one object, in draw order (faces first)."""
    return (decimation_primitives(obj, show, context) + error_primitives(obj, show, error_percent)
            + topology_primitives(obj, show) + clean_preview_primitives(obj))
