"""TopStoc's plain-Python API on numpy arrays (no Blender needed).

>>> import numpy as np, topstoc
>>> mesh = topstoc.Mesh(vertices, triangles)
>>> result = mesh.decimate(ratio=0.1, seed=1)
"""

from .decimate import (Box, DecimateResult, DecimateStats, View, decimate, decimate_with_samples,
                       sampling_probabilities)
from .loops import (Cancelled, ComponentLoops, Loop, LoopsResult, handle_tunnel_loops,
                    self_intersections, tetrahedralize_surface)
from .mesh import Mesh, MeshReport

__all__ = [
    "Box", "Cancelled", "ComponentLoops", "DecimateResult", "DecimateStats", "Loop", "LoopsResult",
    "Mesh", "MeshReport", "View", "decimate", "decimate_with_samples", "handle_tunnel_loops",
    "sampling_probabilities", "self_intersections", "tetrahedralize_surface",
]
