"""Handle and tunnel loops component by component, so that one bad component spoils no other.

``handle_tunnel_loops`` refuses the whole mesh (ValueError) when one component is not manifold,
not orientable, or refused by TetGen. ``loops_by_component`` then asks again for each connected
component alone: a refused component is listed with status "refused" and the reason, the others
with their loops, in the whole mesh's vertex ids. A mesh it accepts whole costs one call.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np

from .loops import ComponentLoops, LoopsResult, handle_tunnel_loops

#: ``ComponentLoops.status`` of a component whose loops were refused.
REFUSED = "refused"


def loops_by_component(vertices: np.ndarray, triangles: np.ndarray, mesh=None, **options) -> LoopsResult:
    """``handle_tunnel_loops(vertices, triangles, **options)``, per component when it refuses
    the whole (module docstring); components ordered by smallest vertex id either way.
    ``mesh``: the same surface as a prepared ``topstoc.Mesh``, used for the whole-mesh call."""
    try:
        return handle_tunnel_loops(vertices, triangles, **options) if mesh is None else \
            handle_tunnel_loops(mesh, **options)
    except ValueError:
        pass
    from .topology import topology

    triangles = np.asarray(triangles, dtype=np.int64)
    labels = topology(vertices, triangles).triangle_component(triangles)
    components, seconds = [], {}
    for label in np.unique(labels):  # topology numbers components by smallest vertex id
        rows = triangles[labels == label]
        used = np.unique(rows)
        try:
            found = handle_tunnel_loops(vertices[used], np.searchsorted(used, rows).astype(np.int32), **options)
        except ValueError as error:
            components.append(_refused(used, rows, _reason(str(error).splitlines()[0], used)))
            continue
        components += [_in_whole_mesh(c, used) for c in found.components]
        for stage, value in found.seconds.items():
            seconds[stage] = seconds.get(stage, 0.0) + value
    return LoopsResult(components=tuple(components), seconds=seconds, coarse_target=0, coarse_rounds=0,
                       coarse_samples_added=0)


def refusals(result: LoopsResult) -> list:
    """One line per refused component: "component N (from vertex V): <reason>"."""
    return [f"component {number} (from vertex {c.first_vertex}): {c.detail}"
            for number, c in enumerate(result.components) if c.status == REFUSED]


def all_refused(result: LoopsResult) -> bool:
    """True when no component could be searched because each was refused (nothing was found)."""
    return bool(result.components) and all(c.status == REFUSED for c in result.components)


def _reason(message: str, used: np.ndarray) -> str:
    """The engine's message about a sub-mesh, in the whole mesh's vertex ids, without the
    sub-mesh's own component name: "component 0 (from vertex 0) is non-manifold: … edge 3-7" -> "non-manifold: … edge 203-207"."""
    message = re.sub(r"^component \d+ \(from vertex \d+\) (is )?", "", message)
    message = re.sub(r"edge (\d+)-(\d+)", lambda m: f"edge {used[int(m[1])]}-{used[int(m[2])]}", message)
    return re.sub(r"vertex (\d+)", lambda m: f"vertex {used[int(m[1])]}", message)


def _refused(used: np.ndarray, rows: np.ndarray, reason: str) -> ComponentLoops:
    edges = np.unique(np.sort(rows[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    return ComponentLoops(first_vertex=int(used[0]), vertices=len(used), edges=len(edges), faces=len(rows),
                          boundary_loops=0, genus=0, status=REFUSED, detail=reason, route="",
                          analysed_vertices=0, tetrahedra=0, handles=(), tunnels=())


def _in_whole_mesh(component: ComponentLoops, used: np.ndarray) -> ComponentLoops:
    """``component`` (of the sub-mesh on vertices ``used``) in the whole mesh's vertex ids."""
    def moved(loop):
        return dataclasses.replace(loop, vertices=used[loop.vertices], initial_vertices=used[loop.initial_vertices],
                                   generator=tuple(int(used[v]) for v in loop.generator))

    return dataclasses.replace(component, first_vertex=int(used[component.first_vertex]),
                               handles=tuple(map(moved, component.handles)),
                               tunnels=tuple(map(moved, component.tunnels)))
