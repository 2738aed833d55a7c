"""Whether a decimated mesh kept the topology of each input component, from invariants alone.

The engine's partition checks cannot judge some clusters of a non-manifold input (a sample
whose link repeats arcs along a non-manifold edge), and its final output check compares Euler
characteristics and boundary loops only on manifold components. This comparison covers every
component: each input component must map to exactly one output component (through ``kept``)
with the same Euler characteristic, Betti numbers (over Z2), boundary loops and open boundary
paths, manifoldness and orientability (core/api/topology.py computes them).
"""
from __future__ import annotations

import numpy as np

from .topology import ComponentTopology, Topology, topology


def _signature(component: ComponentTopology) -> tuple:
    """The invariants compared (not the counts of non-manifold vertices: shortening a
    non-manifold curve lowers them without changing the topology)."""
    return (component.kind, component.euler, tuple(component.betti), len(component.boundary_loops),
            len(component.boundary_paths), component.manifold, component.orientable)


def invariants_kept(before: Topology, out_vertices, out_triangles, kept) -> bool:
    """True when every input component with an edge (before: the input's topology) has exactly
    one output component, of the same invariants (see the module text); kept[i] is the input
    vertex of output vertex i."""
    after = topology(out_vertices, out_triangles)
    kept = np.asarray(kept)
    pieces: dict[int, list] = {}
    for component in after.components:
        source = int(before.vertex_component[kept[component.first_vertex]])
        pieces.setdefault(source, []).append(component)
    if set(pieces) - set(range(len(before.components))):
        return False  # an output piece from an isolated input vertex
    return all(len(pieces.get(index, ())) == 1 and _signature(pieces[index][0]) == _signature(component)
               for index, component in enumerate(before.components))
