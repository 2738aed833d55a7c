"""Handle and tunnel loops (docs/design.md §4.3; thesis 3.2.2-3.2.4, 4.2.1, 5.2.2).

On a closed surface in space, a *handle loop* bounds a disk inside the solid but not outside
(it goes around a handle, like the meridian of a cup's handle); a *tunnel loop* bounds outside
but not inside (it goes through the hole). A closed orientable component of genus g has g
independent loops of each kind, and together they span all its loops (its first homology).

Method (Dey, Li, Sun 2007): TetGen tetrahedralizes the inside and the outside of the surface;
persistence (PHAT) pairs the simplices of the surface, then the inside's, then the outside's;
a surface cycle killed by an inside triangle is a handle, by an outside triangle a tunnel.
Short simple loops spanning the same classes are then picked and tightened on the surface
without changing their class. Large components are tetrahedralized through a coarse TopStoc
decimation of themselves, free of self-intersections, and the loops carried back to the full
mesh (thesis 5.2.2). Every result is checked (simple closed edge cycles, spanning the surface's
homology, shortening kept each class) before it is returned.

>>> result = handle_tunnel_loops(mesh)
>>> for loop in result.handles:
...     print(loop.vertices, loop.length)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from .mesh import Mesh
from ..support import params
from ..support.native import engine
from ..support.errors import TopStocError

#: Raised when a progress callback returns False.
Cancelled = engine.Cancelled

METRICS = ("length", "edges")


@dataclass(frozen=True)
class Loop:
    """One handle or tunnel loop: a simple closed cycle of mesh edges.

    ``vertices`` are the caller's vertex ids in order; the last one connects back to the
    first. ``generator`` is the unpaired edge (two vertex ids) whose class the persistence
    pairing assigned to this loop; on the coarse route it is the full-mesh edge between the two
    clusters of the coarse generator edge. ``initial_vertices`` and ``initial_length`` describe
    the loop before shortening (same homology class, never shorter).
    """

    kind: str
    vertices: np.ndarray
    generator: tuple
    length: float
    initial_length: float
    initial_vertices: np.ndarray

    @property
    def edges(self) -> np.ndarray:
        """(k, 2) vertex pairs of the loop's edges, in order."""
        return np.stack([self.vertices, np.roll(self.vertices, -1)], axis=1)

    def __len__(self) -> int:
        return len(self.vertices)


@dataclass(frozen=True)
class ComponentLoops:
    """The loops of one connected component (components are ordered by smallest vertex id).

    ``status`` is "ok" for a closed orientable manifold component (its ``genus`` handles and
    tunnels are listed) or "open" (no loops: they are defined for closed surfaces only;
    ``detail`` says why). ``route`` tells whether the component was tetrahedralized whole
    ("full") or through a coarse decimation ("coarse"), ``analysed_vertices`` how many vertices
    that surface had.
    """

    first_vertex: int
    vertices: int
    edges: int
    faces: int
    boundary_loops: int
    genus: int
    status: str
    detail: str
    route: str
    analysed_vertices: int
    tetrahedra: int
    handles: tuple
    tunnels: tuple

    @property
    def loops(self) -> tuple:
        """Handles then tunnels."""
        return self.handles + self.tunnels


@dataclass(frozen=True)
class LoopsResult:
    """Handle and tunnel loops of every component, with timings per stage (seconds)."""

    components: tuple
    seconds: dict
    coarse_target: int
    coarse_rounds: int
    coarse_samples_added: int

    @property
    def handles(self) -> list:
        return [loop for c in self.components for loop in c.handles]

    @property
    def tunnels(self) -> list:
        return [loop for c in self.components for loop in c.tunnels]

    @property
    def genus(self) -> int:
        """Total genus of the closed orientable components."""
        return sum(c.genus for c in self.components if c.status == "ok")

    def as_json(self) -> dict:
        """The ``loops --json`` document (docs/design.md §6), vertex ids as plain lists."""
        def loop_json(loop: Loop) -> dict:
            return {"vertices": loop.vertices.tolist(), "generator": list(loop.generator),
                    "length": loop.length, "initial_length": loop.initial_length}

        return {
            "components": [
                {"genus": c.genus, "status": c.status, "detail": c.detail, "route": c.route,
                 "first_vertex": c.first_vertex, "vertices": c.vertices, "faces": c.faces,
                 "handles": [loop.vertices.tolist() for loop in c.handles],
                 "tunnels": [loop.vertices.tolist() for loop in c.tunnels],
                 "handle_loops": [loop_json(loop) for loop in c.handles],
                 "tunnel_loops": [loop_json(loop) for loop in c.tunnels]}
                for c in self.components],
            "seconds": dict(self.seconds),
            "coarse": {"target": self.coarse_target, "rounds": self.coarse_rounds,
                       "samples_added": self.coarse_samples_added},
        }


def _as_mesh(mesh, triangles) -> Mesh:
    if isinstance(mesh, Mesh):
        if triangles is not None:
            raise TopStocError("triangles are given by the Mesh already")
        return mesh
    if triangles is None:
        if hasattr(mesh, "vertices") and hasattr(mesh, "triangles"):  # MeshData
            return Mesh(mesh.vertices, mesh.triangles)
        raise TopStocError("give a topstoc.Mesh, a MeshData, or vertices and triangles")
    return Mesh(mesh, triangles)


def _loop(raw: dict) -> Loop:
    return Loop(kind=raw["kind"], vertices=raw["vertices"], generator=tuple(raw["generator"]),
                length=raw["length"], initial_length=raw["initial_length"],
                initial_vertices=raw["initial_vertices"])


def _component(raw: dict) -> ComponentLoops:
    return ComponentLoops(
        first_vertex=raw["first_vertex"], vertices=raw["vertices"], edges=raw["edges"],
        faces=raw["faces"], boundary_loops=raw["boundary_loops"], genus=raw["genus"],
        status=raw["status"], detail=raw["detail"], route=raw["route"],
        analysed_vertices=raw["analysed_vertices"], tetrahedra=raw["tetrahedra"],
        handles=tuple(_loop(loop) for loop in raw["handles"]),
        tunnels=tuple(_loop(loop) for loop in raw["tunnels"]))


def handle_tunnel_loops(mesh, triangles=None, *, coarse_vertices: Optional[int] = None,
                        full_route_faces: int = 20000, shorten: bool = True,
                        metric: str = "length", seed: int = 1,
                        progress: Optional[Callable[[float, str], Optional[bool]]] = None
                        ) -> LoopsResult:
    """Handle and tunnel loops of every closed orientable component.

    mesh: a ``topstoc.Mesh``, a ``MeshData`` from ``read_mesh``, or the vertices ((n, 3)
    floats) with ``triangles`` ((m, 3) ints). Vertex ids in the result are the input's.
    coarse_vertices: None decides per component (components above ``full_route_faces``
    triangles go through a coarse decimation of about max(3000, n/48) vertices); 0 always
    tetrahedralizes the full component; a positive count forces the coarse route with that
    target. shorten: tighten the loops on the surface (never longer, same class).
    metric: "length" (geometric) or "edges" (edge count, the thesis' metric) for choosing
    and shortening loops. seed: decimation seed of the coarse route.
    progress: called as ``progress(fraction, stage)`` from the computing thread (with the
    GIL); returning False cancels the run with ``Cancelled``.

    Raises ValueError for a component that is not manifold or not orientable, or that TetGen
    refuses (self-intersections), naming it and an offending element.
    """
    mesh = _as_mesh(mesh, triangles)
    if metric not in METRICS:
        raise TopStocError(f"metric must be one of {METRICS}, got {metric!r}")
    coarse = -1 if coarse_vertices is None else params.integer("coarse_vertices", coarse_vertices, 0, 2**31 - 1)
    full_route_faces = params.integer("full_route_faces", full_route_faces, 0, 2**31 - 1)
    seed = params.seed(seed)
    if progress is not None and not callable(progress):
        raise TopStocError("progress must be callable as progress(fraction, stage)")
    raw = engine.handle_tunnel_loops(
        mesh.native, coarse_vertices=coarse, full_route_faces=int(full_route_faces),
        shorten=bool(shorten), count_edges=metric == "edges", seed=int(seed), progress=progress)
    return LoopsResult(components=tuple(_component(c) for c in raw["components"]),
                       seconds=dict(raw["seconds"]), coarse_target=raw["coarse_target"],
                       coarse_rounds=raw["coarse_rounds"],
                       coarse_samples_added=raw["coarse_samples_added"])


def shorten_loop(mesh, loop, triangles=None, *, metric: str = "length") -> np.ndarray:
    """Shortens a simple closed loop of mesh edges without changing its homotopy class.

    For loops the user edited (thesis 4.2.1): ``loop`` lists vertex ids in order (the last
    joins the first) on a closed manifold component. Returns the shortened loop, never longer,
    with the same homology class over the integers (checked). ``mesh`` as in
    handle_tunnel_loops. Raises ValueError when the loop is not a simple edge cycle of such a
    component.
    """
    mesh = _as_mesh(mesh, triangles)
    if metric not in METRICS:
        raise TopStocError(f"metric must be one of {METRICS}, got {metric!r}")
    return engine.shorten_loop(mesh.native, np.asarray(loop), count_edges=metric == "edges")


def self_intersections(vertices, triangles) -> np.ndarray:
    """Pairs (i, j), i <= j, of triangles that intersect other than in shared vertices or a
    shared edge; (i, i) marks a zero-area triangle. Exact orientation tests."""
    return engine.self_intersections(np.asarray(vertices), np.asarray(triangles))


def tetrahedralize_surface(vertices, triangles) -> dict:
    """TetGen tetrahedralization of the inside and outside of a closed surface in a box.

    Returns ``points`` ((p, 3): the surface's vertices first, then the box corners and Steiner
    points), ``tets`` ((k, 4) point ids) and ``inside`` ((k,) 1 inside the surface, 0 outside).
    ``perturbed`` is True when TetGen ran on the surface's vertices moved by at most 1e-7 of their
    shortest edge (fast on coplanar and cospherical vertices; the points returned are the exact
    ones), False when TetGen refused that and the exact positions were used.
    Raises ValueError when TetGen refuses the surface (for instance when it intersects itself).
    """
    return engine.tetrahedralize_surface(np.asarray(vertices), np.asarray(triangles))


__all__ = ["Cancelled", "ComponentLoops", "Loop", "LoopsResult", "handle_tunnel_loops",
           "self_intersections", "shorten_loop", "tetrahedralize_surface"]
