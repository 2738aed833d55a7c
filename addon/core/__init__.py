"""TopStoc's plain-Python API on numpy arrays (no Blender needed).

>>> import numpy as np, topstoc
>>> mesh = topstoc.Mesh(vertices, triangles)
>>> result = mesh.decimate(ratio=0.1, seed=1)
"""

from .decimate import (Box, DecimateResult, DecimateStats, View, decimate, decimate_with_samples,
                       sampling_probabilities)
from .io import MeshData, read_mesh, write_mesh
from .mesh import Mesh, MeshReport
from .topology import ComponentGenerators, ComponentTopology, Topology, generators, topology

__all__ = [
    "Box", "DecimateResult", "DecimateStats", "Mesh", "MeshReport", "View", "decimate",
    "decimate_with_samples", "sampling_probabilities",
    # topology
    "ComponentGenerators", "ComponentTopology", "Topology", "generators", "topology",
    # mesh files (io.py)
    "MeshData", "read_mesh", "write_mesh",
]
