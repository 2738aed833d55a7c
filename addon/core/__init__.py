"""TopStoc's plain-Python API on numpy arrays (no Blender needed).

>>> import numpy as np, topstoc
>>> mesh = topstoc.Mesh(vertices, triangles)
>>> result = mesh.decimate(ratio=0.1, seed=1)
"""

from .api.clean import CleanResult, clean
from .api.decimate import (Box, DecimateResult, DecimateStats, View, decimate, decimate_with_samples,
                           sampling_probabilities)
from .api.edit import EditResult, cut_along_loop, delete_faces, fill_holes, fill_loops, remove_handle
from .api.error_bound import ErrorBoundReport
from .support.errors import TopStocError
from .api.hausdorff import Distance, HausdorffResult, OneSidedDistance, closest_points, hausdorff
from .api.io import MeshData, read_mesh, write_mesh
from .api.loops import (Cancelled, ComponentLoops, Loop, LoopsResult, handle_tunnel_loops, self_intersections,
                        shorten_loop, tetrahedralize_surface)
from .api.mesh import Mesh, MeshReport
from .api.mesh_edges import MeshEdges, mesh_edges
from .api.topology import ComponentGenerators, ComponentTopology, Topology, generators, topology

__all__ = [
    "Box", "DecimateResult", "DecimateStats", "Mesh", "MeshReport", "View", "decimate",
    "decimate_with_samples", "sampling_probabilities",
    # the base of every error TopStoc raises on purpose (a ValueError)
    "TopStocError",
    # editing (topstoc.core.api.edit also has boundary_loops and the result's parts)
    "CleanResult", "clean",
    "EditResult", "cut_along_loop", "delete_faces", "fill_holes", "fill_loops", "remove_handle",
    # measurement (hausdorff.py) and error-bounded decimation (error_bound.py)
    "Distance", "ErrorBoundReport", "HausdorffResult", "OneSidedDistance", "closest_points", "hausdorff",
    # topology
    "ComponentGenerators", "ComponentTopology", "Topology", "generators", "topology",
    # edges of a triangle list, for hosts that store them (mesh_edges.py)
    "MeshEdges", "mesh_edges",
    # mesh files (io.py)
    "MeshData", "read_mesh", "write_mesh",
    # handle and tunnel loops (loops.py)
    "Cancelled", "ComponentLoops", "Loop", "LoopsResult", "handle_tunnel_loops", "self_intersections",
    "shorten_loop", "tetrahedralize_surface",
]
