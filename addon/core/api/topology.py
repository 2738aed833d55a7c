"""Topology of a triangle mesh: invariants per connected component and generator edges.

docs/design.md §4.1, thesis chapter 3 and 4.2.1. Works on any triangle mesh read as a simplicial
complex over Z2, in the caller's vertex ids:

* the Betti numbers and the Euler characteristic describe the surface (and wire edges): the
  complex of the triangles and edges with their vertices, as GUDHI and MeshLab count it. A
  vertex in no triangle or edge is no part of it: it is listed apart in
  ``Topology.isolated_vertices`` and counted in no Betti number;
* a triangle with three distinct vertices is a 2-simplex; repeated copies (same vertex set,
  any order) count once (``duplicate_triangles``);
* a triangle with a repeated vertex is read as the edge (or vertex) it spans
  (``collapsed_triangles``): nothing it contributes to the complex is lost;
* optional extra edges (wire edges, bare edge graphs) are 1-simplices.

>>> info = topology(vertices, triangles)
>>> info.betti, [c.summary for c in info.components]
((1, 6, 1), ['genus 3, closed, orientable'])
>>> for g in generators(vertices, triangles):
...     g.edges, g.loops        # 2g generator edges, one closed loop through each
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..support.native import engine

_KINDS = ("vertex", "graph", "surface")  # native kind codes 0, 1, 2


def _flag(value: int) -> bool | None:
    return None if value < 0 else bool(value)


def _count(value: int) -> int | None:
    return None if value < 0 else value


def _plural(count: int, word: str, plural: str | None = None) -> str:
    return f"{count} {word if count == 1 else (plural or word + 's')}"


@dataclass(slots=True)
class ComponentTopology:
    """Invariants of one connected component.

    ``kind`` is ``"surface"`` (at least one triangle) or ``"graph"`` (edges only; isolated
    vertices are listed apart, see :class:`Topology`). The surface properties (closed,
    manifold, orientable, genus...) are ``None`` where they are not defined: for graphs,
    orientability next to an edge of three or more triangles, genus on a non-manifold or
    non-orientable component.
    """

    index: int
    kind: str
    first_vertex: int  #: smallest vertex id; components are numbered in this order
    vertices: int
    edges: int
    faces: int
    euler: int  #: vertices - edges + faces
    betti: tuple[int, int, int]  #: over Z2
    boundary_edges: int  #: edges with exactly one triangle
    closed: bool | None  #: surface without boundary edges
    manifold: bool | None  #: every edge in 1 or 2 triangles, every vertex one fan, no wire edge
    orientable: bool | None  #: triangles can be oriented consistently (None next to 3+ triangle edges)
    consistently_oriented: bool | None  #: the given corner orders already agree
    genus: int | None  #: orientable manifold: euler = 2 - 2 genus - boundary loops
    crosscaps: int | None  #: non-orientable manifold: euler = 2 - crosscaps - boundary loops
    boundary_loops: list[np.ndarray] = field(repr=False)  #: closed vertex cycles (first vertex not repeated)
    boundary_paths: list[np.ndarray] = field(repr=False)  #: open boundary chains (only at non-manifold edges)
    nonmanifold_edges: np.ndarray = field(repr=False)  #: (k, 2) edges with 0 or 3+ triangles
    nonmanifold_edge_faces: np.ndarray = field(repr=False)  #: (k,) their number of triangles
    nonmanifold_vertices: np.ndarray = field(repr=False)  #: vertices whose triangles are not one fan

    @property
    def summary(self) -> str:
        """One line for a panel or a log, e.g. ``"genus 3, closed, orientable"``."""
        b0, b1, b2 = self.betti
        if self.kind == "graph":
            return "edge graph, tree" if b1 == 0 else f"edge graph, {_plural(b1, 'independent cycle')}"
        border = "closed" if self.closed else _plural(len(self.boundary_loops), "boundary loop")
        if self.manifold:
            if self.orientable:
                text = f"genus {self.genus}, {border}, orientable"
                return text if self.consistently_oriented else text + " (triangles inconsistently oriented)"
            return f"non-orientable, {_plural(self.crosscaps, 'cross-cap')}, {border}"
        parts = []
        if len(self.nonmanifold_edges):
            parts.append(_plural(len(self.nonmanifold_edges), "edge"))
        if len(self.nonmanifold_vertices):
            parts.append(_plural(len(self.nonmanifold_vertices), "vertex", "vertices"))
        if self.closed:
            border = "closed"
        else:
            pieces = [_plural(len(self.boundary_loops), "boundary loop")] if self.boundary_loops else []
            if self.boundary_paths:
                pieces.append(_plural(len(self.boundary_paths), "open boundary chain"))
            border = " and ".join(pieces)
        orientation = {True: ", orientable", False: ", non-orientable", None: ""}[self.orientable]
        return (f"non-manifold ({', '.join(parts)}), {border}{orientation}, "
                f"genus undefined, betti {b0}/{b1}/{b2}")

    def to_dict(self) -> dict:
        """JSON-ready description (docs/design.md §6 keys plus the details)."""
        return {
            "index": self.index, "kind": self.kind, "summary": self.summary,
            "vertices": self.vertices, "edges": self.edges, "faces": self.faces, "euler": self.euler,
            "betti": list(self.betti), "closed": self.closed, "orientable": self.orientable,
            "manifold": self.manifold, "genus": self.genus, "crosscaps": self.crosscaps,
            "consistently_oriented": self.consistently_oriented,
            "boundary_edges": self.boundary_edges,
            "boundary_loops": [loop.tolist() for loop in self.boundary_loops],
            "boundary_paths": [path.tolist() for path in self.boundary_paths],
            "nonmanifold_edges": self.nonmanifold_edges.tolist(),
            "nonmanifold_vertices": self.nonmanifold_vertices.tolist(),
        }


@dataclass(frozen=True)
class ComponentGenerators:
    """Generator edges of one closed orientable manifold component (thesis 3.2.3, 4.2.1).

    ``edges`` are the 2g edges left unpaired by the persistence pairing of the component
    (computed tree-cotree in linear time; see native/include/topstoc/topology/generators.hpp), ordered
    by the length of their loop, shortest first. ``loops[i]`` is a simple closed vertex cycle that starts with ``edges[i]`` and
    closes back to its first vertex; the loops form a basis of H1 over Z2. ``cut_edges`` are the
    generator edges plus the tree edges joining the loops: cutting the surface along them leaves
    one disk (they make good UV seams).
    """

    component: int
    genus: int
    root: int
    edges: np.ndarray = field(repr=False)  #: (2g, 2) int32
    loops: list[np.ndarray] = field(repr=False)
    cut_edges: np.ndarray = field(repr=False)  #: (k, 2) int32, lower vertex first

    def to_dict(self) -> dict:
        return {"component": self.component, "genus": self.genus, "edges": self.edges.tolist(),
                "loops": [loop.tolist() for loop in self.loops]}


@dataclass(frozen=True)
class Topology:
    """Invariants of a whole mesh: totals, Betti numbers, one :class:`ComponentTopology` per
    connected component with at least one edge, and the isolated vertices apart (in no
    component and no Betti number: betti[0] = len(components))."""

    betti: tuple[int, int, int]  #: of the triangles and edges (isolated vertices not counted)
    vertices: int  #: all vertices, isolated ones included
    edges: int
    faces: int
    components: list[ComponentTopology]
    isolated_vertices: np.ndarray = field(repr=False)  #: (k,) ids of vertices in no edge or triangle
    vertex_component: np.ndarray = field(repr=False)  #: (n,) index into components, -1 if isolated
    collapsed_triangles: int  #: triangles with a repeated vertex, read as an edge or a vertex
    duplicate_triangles: int  #: repeats of an earlier triangle's vertex set, counted once
    generators: list[ComponentGenerators] = field(default_factory=list, repr=False)  #: when asked for

    @property
    def euler(self) -> int:
        """V - E + F of the triangles and edges (isolated vertices not counted): b0 - b1 + b2."""
        return self.vertices - len(self.isolated_vertices) - self.edges + self.faces

    def triangle_component(self, triangles) -> np.ndarray:
        """Component index of each of the caller's triangles."""
        return self.vertex_component[np.asarray(triangles)[:, 0]]

    def summary(self) -> str:
        """One line: ``"1 component: genus 3, closed, orientable"``, or counts for many."""
        count = len(self.components)
        isolated = len(self.isolated_vertices)
        extra = f", {_plural(isolated, 'isolated vertex', 'isolated vertices')}" if isolated else ""
        if count == 0:
            return _plural(isolated, "isolated vertex", "isolated vertices") if isolated else "empty"
        if count == 1:
            return f"1 component: {self.components[0].summary}{extra}"
        surfaces = sum(c.kind == "surface" for c in self.components)
        parts = [_plural(surfaces, "surface")] if surfaces else []
        if count > surfaces:
            parts.append(_plural(count - surfaces, "edge graph"))
        b0, b1, b2 = self.betti
        return f"{count} components ({', '.join(parts)}){extra}, betti {b0}/{b1}/{b2}"

    def to_dict(self) -> dict:
        """JSON-ready (docs/design.md §6: ``betti`` and ``components``; plus totals and generators)."""
        out = {"betti": list(self.betti), "vertices": self.vertices, "edges": self.edges,
               "faces": self.faces, "euler": self.euler, "summary": self.summary(),
               "collapsed_triangles": self.collapsed_triangles,
               "duplicate_triangles": self.duplicate_triangles,
               "components": [c.to_dict() for c in self.components],
               "isolated_vertices": self.isolated_vertices.tolist()}
        if self.generators:
            out["generators"] = [g.to_dict() for g in self.generators]
        return out


def _split(offsets: np.ndarray, values: np.ndarray) -> list[np.ndarray]:
    return [values[offsets[i]:offsets[i + 1]] for i in range(len(offsets) - 1)]


def _generators_from(raw: dict) -> ComponentGenerators:
    return ComponentGenerators(component=int(raw["component"]), genus=int(raw["genus"]), root=int(raw["root"]),
                      edges=raw["edges"], loops=_split(raw["loop_offsets"], raw["loop_vertices"]),
                      cut_edges=raw["cut_edges"])


def topology(vertices, triangles, edges=None, generators: bool = False) -> Topology:
    """Invariants of the complex spanned by ``vertices`` (n, 3), ``triangles`` (m, 3) and optional
    extra ``edges`` (k, 2), per connected component; with ``generators=True`` also the generator
    edges and loops of every closed orientable manifold component.

    Raises ValueError for wrong shapes or dtypes, out-of-range indices and non-finite
    coordinates (naming the offending element). The arrays are only read. An empty mesh has no
    components and Betti numbers (0, 0, 0).
    """
    raw = engine.topology(vertices, triangles, edges, generators)
    # Native components include isolated vertices; here they are listed apart and the others
    # renumbered (same order: by smallest vertex id).
    native = raw["components"]
    kinds = native["kind"]
    kept = kinds != 0
    renumber = np.full(len(kinds) + 1, -1, dtype=np.int32)  # last slot: -1 stays -1
    renumber[:-1][kept] = np.arange(int(kept.sum()), dtype=np.int32)
    # Plain lists: indexing them is much cheaper than numpy scalars.
    cols = {key: value[kept].tolist() for key, value in native.items()}
    component_of = renumber[raw["vertex_component"]]
    curves = _split(raw["boundary_offsets"], raw["boundary_vertices"])
    loops_of: dict[int, list] = {}
    paths_of: dict[int, list] = {}
    for curve, comp, closed in zip(curves, renumber[raw["boundary_component"]].tolist(),
                                   raw["boundary_closed"].tolist()):
        (loops_of if closed else paths_of).setdefault(comp, []).append(curve)
    nm_edges = raw["nonmanifold_edges"]
    nm_faces = raw["nonmanifold_edge_triangles"]
    nm_vertices = raw["nonmanifold_vertices"]
    nm_edge_comp = component_of[nm_edges[:, 0]] if len(nm_edges) else np.zeros(0, np.int32)
    nm_vertex_comp = component_of[nm_vertices] if len(nm_vertices) else np.zeros(0, np.int32)
    empty_pairs = np.zeros((0, 2), np.int32)
    empty = np.zeros(0, np.int32)
    components = []
    for i, kind in enumerate(cols["kind"]):
        has_nm = cols["nonmanifold_edges"][i] > 0 or cols["nonmanifold_vertices"][i] > 0
        components.append(ComponentTopology(
            index=i, kind=_KINDS[kind], first_vertex=cols["first_vertex"][i],
            vertices=cols["vertices"][i], edges=cols["edges"][i], faces=cols["triangles"][i],
            euler=cols["euler"][i], betti=tuple(cols["betti"][i]),
            boundary_edges=cols["boundary_edges"][i], closed=_flag(cols["closed"][i]),
            manifold=_flag(cols["manifold"][i]), orientable=_flag(cols["orientable"][i]),
            consistently_oriented=_flag(cols["consistently_oriented"][i]),
            genus=_count(cols["genus"][i]), crosscaps=_count(cols["crosscaps"][i]),
            boundary_loops=loops_of.get(i, []), boundary_paths=paths_of.get(i, []),
            nonmanifold_edges=nm_edges[nm_edge_comp == i] if has_nm else empty_pairs,
            nonmanifold_edge_faces=nm_faces[nm_edge_comp == i] if has_nm else empty,
            nonmanifold_vertices=nm_vertices[nm_vertex_comp == i] if has_nm else empty))
    gens = []
    for g in raw["generators"]:
        g["component"] = int(renumber[g["component"]])
        gens.append(_generators_from(g))
    return Topology(
        betti=tuple(int(sum(b[d] for b in cols["betti"])) for d in range(3)), vertices=int(raw["num_vertices"]),
        edges=int(raw["num_edges"]), faces=int(raw["num_triangles"]), components=components,
        isolated_vertices=native["first_vertex"][~kept], vertex_component=component_of,
        collapsed_triangles=int(raw["collapsed_triangles"]),
        duplicate_triangles=int(raw["duplicate_triangles"]), generators=gens)

def generators(vertices, triangles, edges=None) -> list[ComponentGenerators]:
    """Generator edges and loops of every closed orientable manifold component (genus-0
    components included, with no edges); other components are skipped. See :class:`ComponentGenerators`.
    """
    return topology(vertices, triangles, edges, generators=True).generators
