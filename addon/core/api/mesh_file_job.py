"""The one recipe that decimates a mesh file read with io.read_mesh (docs/design.md §1.5, §6):
prepare the Mesh, UV seams and material borders as borders, the look (UVs, colours) as
attributes where the refinement runs, decimate (mirrored when asked), carry the attributes
over (the look fitted to the input's where it was in the cost), write atomically.

``topstoc decimate`` (core/cli/decimate.py) runs it once; the batch (core/batch/mesh_asset.py) once
per LOD of each mesh file. The decimation itself is a DecimationJob (core/api/job.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..carry.appearance import Appearance, appearance_attributes, refines
from ..carry.attributes import material_regions, transfer_attributes, uv_seam_edges
from .decimate import DecimateResult, run_job
from .io import MeshData, dropped_attributes, write_mesh
from .job import DecimationJob, make_job
from ..carry.materials import carry_libraries
from .mesh import Mesh


@dataclass
class MeshFileJob:
    """A mesh file prepared for decimation: the Mesh, its borders and its look."""

    path: str
    data: MeshData
    mesh: Mesh
    seams: Optional[np.ndarray]     #: UV seam edges (k, 2), or None without UVs
    regions: Optional[np.ndarray]   #: material per triangle, or None
    appearance: Appearance          #: the look, where the refinement runs (else empty)
    attribute_kwargs: dict          #: ``attributes``/``attribute_weights`` for make_job, or {}

    def job(self, target: dict, options: dict, symmetry=None) -> DecimationJob:
        """The DecimationJob for one target (``ratio=``, ``target_vertices=``, ``max_error=``...)
        and the decimate options (seed, mode, guidance...)."""
        borders = self.seams if self.seams is not None and len(self.seams) else None
        return make_job(self.mesh, **target, **options, symmetry=symmetry, regions=self.regions, borders=borders,
                        **self.attribute_kwargs)

    def decimate(self, target: dict, options: dict, symmetry=None, progress=None) -> DecimateResult:
        """progress: the error-bounded search's, for a max_error target (run_job)."""
        return run_job(self.mesh, self.job(target, options, symmetry), progress)

    def write(self, result: DecimateResult, output: str) -> list:
        """Writes ``result`` with the input's attributes to ``output`` (the look fitted to the
        input's where it was in the cost); returns what its format cannot store (io.dropped_attributes)."""
        out = transfer_attributes(self.data, result, fit=bool(self.attribute_kwargs))
        out.material_libraries = carry_libraries(out.material_libraries, self.path, output)
        write_mesh(output, out)
        return dropped_attributes(out, output)


def prepare_file(path: str, data: MeshData, mode: str = "quality", refine=None, weight: float = 0.0) -> MeshFileJob:
    """The MeshFileJob of ``data`` (read from ``path``); the look enters at ``weight`` when the
    refinement (``mode``, ``refine``) runs, the only stage that uses it."""
    mesh = Mesh(data.vertices, data.triangles)
    seams = None if data.corner_uvs is None else uv_seam_edges(data.triangles, data.corner_uvs)
    appearance = Appearance()
    if weight > 0 and refines(mode or "quality", refine):
        appearance = appearance_attributes(data.triangles, data.corner_uvs, data.vertex_colors)
    return MeshFileJob(path, data, mesh, seams, material_regions(data), appearance,
                       appearance.decimate_kwargs(weight))
