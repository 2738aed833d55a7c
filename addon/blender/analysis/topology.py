"""The Topology panel's data: invariants (fast) and handle/tunnel loops (slow, in a thread).

Invariants come from topstoc.core.api.topology on the mesh as Blender stores it: its loop
triangles (n-gons fan-triangulated; χ and the Betti numbers do not depend on how) plus its
loose edges. V, E and F are shown in Blender's own terms (vertices, edges, polygons), per
component too. Everything is stored on the object (props/results.py), so undo restores it
with the mesh.

The loop list holds the handle and tunnel loops of the last search (valid while the mesh's
connectivity is unchanged, or carried through the add-on's own edits) and the boundary loops
of the last analysis, sorted by length (shortest first).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from ...core.api import component_loops, loops as core_loops
from ...core.api.topology import Topology, topology as compute_topology
from ...core.support.errors import TopStocError
from ..io import mesh_access, mesh_read
from ..preview import watch
from ..preview.cache import prepared_meshes
from .failures import stored_failure

SEARCH_KINDS = ("HANDLE", "TUNNEL")


class AnalysisError(TopStocError):
    """An analysis that cannot run (message for the panel and the status bar)."""


def loose_edges(mesh) -> np.ndarray:
    """(k, 2) vertex pairs of the edges no polygon uses (wire edges)."""
    count = len(mesh.edges)
    if count == 0:
        return np.zeros((0, 2), dtype=np.int32)
    used = np.zeros(count, dtype=bool)
    if len(mesh.loops):
        used[mesh_read.corner_edges(mesh)] = True
    return mesh_access.read_indices(mesh.edges, "vertices", count, 2)[~used]


def _flat(arrays) -> list:
    return np.concatenate([np.asarray(a, dtype=np.int64).reshape(-1) for a in arrays]).tolist() if arrays else []


def _per_component(component_of: np.ndarray, elements_first_vertex: np.ndarray, count: int) -> np.ndarray:
    if len(elements_first_vertex) == 0:
        return np.zeros(count, dtype=np.int64)
    owner = component_of[elements_first_vertex]
    return np.bincount(owner[owner >= 0], minlength=count)


def loop_length(co: np.ndarray, ids) -> float:
    ids = np.asarray(ids)
    return float(np.linalg.norm(co[ids] - co[np.roll(ids, -1)], axis=1).sum()) if len(ids) > 1 else 0.0


def _fillable(vertices, triangles) -> dict:
    """{frozenset of loop vertices: fillable} from the editing engine's boundary loops."""
    try:
        from ...core.api import edit
    except ImportError:
        return {}
    return {frozenset(loop.vertices.tolist()): loop.fillable for loop in edit.boundary_loops(vertices, triangles)}


def analyse(obj, carried_loops: Optional[list] = None) -> Topology:
    """Computes the invariants of ``obj``'s mesh and stores them on ``obj.topstoc.topology``.

    Handle and tunnel loops of an earlier search stay when the connectivity did not change;
    ``carried_loops`` (kind, vertex ids) replaces them after one of the add-on's own edits.
    Raises AnalysisError (the message is stored for the panel too).
    """
    topology = obj.topstoc.topology
    with stored_failure(topology, AnalysisError):
        mesh_read.check_mesh_object(obj, AnalysisError)
        start = time.perf_counter()
        mesh = obj.data
        arrays = mesh_read.read_mesh(mesh)
        wires = loose_edges(mesh)
        try:
            info = compute_topology(arrays.vertices, arrays.triangles, wires, generators=True)
        except ValueError as error:
            raise AnalysisError(f"'{obj.name}': {error}") from None
        seconds = time.perf_counter() - start
    stamp = watch.connectivity_stamp(obj.data)
    _store(obj, info, arrays, wires, stamp, seconds, carried_loops)
    return info


def _store(obj, info, arrays, wires, stamp: str, seconds: float, carried_loops) -> None:
    mesh = obj.data
    topology = obj.topstoc.topology
    count = len(info.components)
    component_of = info.vertex_component
    edges = mesh_access.read_indices(mesh.edges, "vertices", len(mesh.edges), 2)
    starts = mesh_access.read_indices(mesh.polygons, "loop_start", len(mesh.polygons))
    polygon_first = mesh_read.corner_vertices(mesh)[starts] if len(mesh.polygons) else np.zeros(0, dtype=np.int32)
    edges_per = _per_component(component_of, edges[:, 0] if len(edges) else edges.reshape(-1), count)
    faces_per = _per_component(component_of, polygon_first, count)

    topology.vertices, topology.edges, topology.faces = len(mesh.vertices), len(mesh.edges), len(mesh.polygons)
    topology.triangles = len(arrays.triangles)
    topology.euler = info.euler
    topology.betti0, topology.betti1, topology.betti2 = info.betti
    genera = [c.genus for c in info.components if c.kind == "surface"]
    topology.genus = -1 if any(g is None for g in genera) else int(sum(genera))
    topology.boundary_loops = sum(len(c.boundary_loops) for c in info.components)
    topology.nonmanifold_edges = sum(len(c.nonmanifold_edges) for c in info.components)
    topology.nonmanifold_vertices = sum(len(c.nonmanifold_vertices) for c in info.components)
    topology.isolated_vertices = len(info.isolated_vertices)
    topology.duplicate_triangles = info.duplicate_triangles
    topology.summary = info.summary()
    topology.components.clear()
    for i, c in enumerate(info.components):
        item = topology.components.add()
        item.name = f"Component {i}"
        item.vertices, item.edges, item.faces, item.triangles = c.vertices, int(edges_per[i]), int(faces_per[i]), c.faces
        item.euler = c.euler
        item.betti0, item.betti1, item.betti2 = c.betti
        item.genus = -1 if c.genus is None else c.genus
        item.boundary_loops = len(c.boundary_loops)
        item.closed, item.manifold, item.orientable = bool(c.closed), bool(c.manifold), bool(c.orientable)
        item.summary = c.summary
    topology.component_index = min(topology.component_index, max(0, count - 1))

    topology["generator_edges"] = _flat([g.edges for g in info.generators])
    boundaries = [loop for c in info.components for loop in c.boundary_loops]
    topology["boundary_vertices"] = _flat(boundaries)
    topology["nonmanifold_edge_ids"] = _flat([c.nonmanifold_edges for c in info.components])
    topology["nonmanifold_vertex_ids"] = _flat([c.nonmanifold_vertices for c in info.components])

    # The loop list: searched loops that still fit, then this analysis' boundary loops.
    if carried_loops is not None:
        searched = carried_loops
    elif topology.loops_stamp == stamp:
        searched = [(loop.kind, list(loop["vertices"])) for loop in topology.loops if loop.kind in SEARCH_KINDS]
    else:
        searched = []
        if topology.loops_state == "OK" and any(loop.kind in SEARCH_KINDS for loop in topology.loops):
            topology.loops_state, topology.loops_message = "NONE", "The mesh changed: find the loops again"
    if carried_loops is not None:
        topology.loops_stamp = stamp
    active = topology.loop_index
    co = arrays.vertices
    fillable = _fillable(arrays.vertices, arrays.triangles) if boundaries else {}
    _set_loops(topology, co, searched + [("BOUNDARY", loop) for loop in boundaries], info, fillable)
    topology.loop_index = min(active, max(0, len(topology.loops) - 1))
    topology.stamp = stamp
    topology.seconds = seconds
    topology.state, topology.message = "OK", ""
    topology.revision += 1


def _set_loops(topology, co, entries, info, fillable) -> None:
    """The loop list, shortest first (the small flaws a clean-up removes come first), each
    with its length as a fraction of the bounding box's diagonal."""
    topology.loops.clear()
    counters = {"HANDLE": 0, "TUNNEL": 0, "BOUNDARY": 0}
    diagonal = float(np.linalg.norm(np.ptp(co, axis=0))) if len(co) else 0.0
    measured = sorted(((loop_length(co, ids), kind, np.asarray(ids, dtype=np.int64)) for kind, ids in entries),
                      key=lambda entry: entry[0])  # stable: equal lengths keep their order
    for length, kind, ids in measured:
        item = topology.loops.add()
        counters[kind] += 1
        item.name = f"{kind.capitalize()} {counters[kind]}"
        item.kind = kind
        item.component = int(info.vertex_component[ids[0]]) if info is not None and len(ids) else 0
        item.length = length
        item.relative = length / diagonal if diagonal > 0 else 0.0
        item.num_edges = len(ids)
        item.fillable = fillable.get(frozenset(ids.tolist()), True) if kind == "BOUNDARY" else True
        item["vertices"] = ids.tolist()


def loop_vertices(item) -> np.ndarray:
    """The vertex ids of a loop list entry."""
    return np.asarray(item["vertices"], dtype=np.int64) if "vertices" in item else np.zeros(0, dtype=np.int64)


def active_loop(obj):
    topology = obj.topstoc.topology
    if 0 <= topology.loop_index < len(topology.loops):
        return topology.loops[topology.loop_index]
    return None


def is_current(obj, fresh: bool = False) -> bool:
    """True when the stored invariants describe the mesh's present connectivity.

    ``fresh`` recomputes the fingerprint instead of trusting the memo (operators use it right
    after leaving Edit Mode).
    """
    topology = obj.topstoc.topology
    if topology.state != "OK":
        return False
    stamp = watch.connectivity_stamp(obj.data) if fresh else watch.current_stamp(obj)
    return topology.stamp == stamp


@dataclass
class LoopSearch:
    """One handle/tunnel search: prepared on the main thread, run anywhere, stored on the main
    thread (``run`` touches no Blender data)."""

    object_name: str
    mesh: object                 #: topstoc.core.Mesh
    stamp: str
    fraction: float = 0.0
    stage: str = "starting"
    cancelled: bool = False
    result: Optional[core_loops.LoopsResult] = None
    error: Optional[str] = None
    seconds: float = 0.0
    listener: Optional[Callable] = None  #: also told the progress; returning False cancels

    def _progress(self, fraction: float, stage: str) -> bool:
        self.fraction, self.stage = float(fraction), str(stage)
        if self.listener is not None and self.listener(fraction, stage) is False:
            self.cancelled = True
        return not self.cancelled

    def run(self) -> None:
        start = time.perf_counter()
        try:  # a refused component (not manifold, self-intersecting) spoils no other
            self.result = component_loops.loops_by_component(self.mesh.vertices, self.mesh.triangles, mesh=self.mesh,
                                                             progress=self._progress)
        except core_loops.Cancelled:
            self.error = "cancelled"
        except ValueError as error:
            self.error = f"'{self.object_name}': {error}"
        if self.result is not None and component_loops.all_refused(self.result):  # nothing to show
            self.error = f"'{self.object_name}': " + "; ".join(component_loops.refusals(self.result))
        self.seconds = time.perf_counter() - start


def start_search(obj) -> LoopSearch:
    """Reads the mesh (main thread) for a search. Raises AnalysisError for unusable meshes."""
    mesh_read.check_mesh_object(obj, AnalysisError)
    if len(obj.data.polygons) == 0:
        raise AnalysisError(f"'{obj.name}' has no faces")
    try:
        prepared = prepared_meshes.get(obj.data)
    except ValueError as error:
        raise AnalysisError(f"'{obj.name}': {error}") from None
    return LoopSearch(obj.name, prepared.mesh, watch.connectivity_stamp(obj.data))


def finish_search(obj, search: LoopSearch) -> str:
    """Stores a finished search on ``obj`` (main thread); returns the status line.

    Raises AnalysisError when the search failed or the mesh changed while it ran.
    """
    topology = obj.topstoc.topology
    if search.error is None and watch.connectivity_stamp(obj.data) != search.stamp:
        search.error = f"'{obj.name}' changed during the search"
    if search.error is not None:
        topology.loops_state = "NONE" if search.error == "cancelled" else "ERROR"
        topology.loops_message = "Search cancelled" if search.error == "cancelled" else search.error
        topology.revision += 1
        raise AnalysisError(topology.loops_message)
    result = search.result
    found = [("HANDLE", loop.vertices) for loop in result.handles] + \
            [("TUNNEL", loop.vertices) for loop in result.tunnels]
    parts = [f"{len(result.handles)} handle and {len(result.tunnels)} tunnel loops in {search.seconds:.2f} s"]
    refused = component_loops.refusals(result)
    if refused:  # one line: the first refused component, and how many more
        more = f" (and {len(refused) - 1} more refused)" if len(refused) > 1 else ""
        parts.append(f"{refused[0]}{more}; left without loops")
    skipped = [c for c in result.components if c.status not in ("ok", component_loops.REFUSED)]
    if skipped:
        parts.append(f"{len(skipped)} component{'s' if len(skipped) > 1 else ''} without loops "
                     f"({skipped[0].detail})")
    if any(c.route == "coarse" for c in result.components):
        parts.append("via a coarse mesh")
    topology.loops_seconds = search.seconds
    topology.loops_state, topology.loops_message = "OK", "; ".join(parts)
    analyse(obj, carried_loops=found)  # fast; keeps one code path for the list and its numbers
    topology.loop_index = 0
    return topology.loops_message


def find_loops(obj, progress: Optional[Callable[[float, str], Optional[bool]]] = None) -> str:
    """Searches the handle and tunnel loops of ``obj`` synchronously (batch, tests)."""
    search = start_search(obj)
    search.listener = progress
    search.run()
    return finish_search(obj, search)


def carry_loops(obj, result, dropped: int = -1) -> list:
    """The searched loops (but entry ``dropped``) mapped through an edit, kept where every edge
    still exists: (kind, vertex ids) pairs for ``analyse(carried_loops=...)``."""
    vertex_source = np.asarray(result.vertex_source, dtype=np.int64)
    vertex_map = np.full(int(result.input_vertices), -1, dtype=np.int64)
    copies = np.flatnonzero(vertex_source >= 0)
    vertex_map[vertex_source[copies][::-1]] = copies[::-1]  # the first copy of each vertex
    triangles = np.asarray(result.triangles, dtype=np.int64).reshape(-1, 3)
    n = max(len(result.vertices), 1)
    pairs = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    edge_keys = np.unique(np.minimum(pairs[:, 0], pairs[:, 1]) * n + np.maximum(pairs[:, 0], pairs[:, 1]))
    carried = []
    for index, item in enumerate(obj.topstoc.topology.loops):
        if item.kind not in SEARCH_KINDS or index == dropped:
            continue
        ids = vertex_map[loop_vertices(item)]
        if len(ids) < 3 or (ids < 0).any():
            continue
        following = np.roll(ids, -1)
        keys = np.minimum(ids, following) * n + np.maximum(ids, following)
        if np.isin(keys, edge_keys).all():
            carried.append((item.kind, ids.tolist()))
    return carried
