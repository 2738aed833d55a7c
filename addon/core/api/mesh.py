"""The prepared mesh: validated once, reused by every decimation and analysis."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .decimate import decimate, decimate_with_samples
from .topology import topology
from ..support.digest import array_digest
from ..support.native import engine
from ..support.errors import TopStocError


@dataclass(frozen=True)
class MeshReport:
    """What validation found in the caller's arrays and what it repaired.

    Degenerate triangles (a repeated vertex) and exact duplicates are dropped; everything
    else is kept and counted. Counts refer to the caller's arrays.
    """

    input_vertices: int
    input_triangles: int
    degenerate_triangles: int
    duplicate_triangles: int
    zero_area_triangles: int
    isolated_vertices: int
    boundary_edges: int
    nonmanifold_edges: int
    nonmanifold_vertices: int
    inconsistent_edges: int
    components: int
    dropped_triangles: np.ndarray

    @property
    def manifold(self) -> bool:
        return self.nonmanifold_edges == 0 and self.nonmanifold_vertices == 0

    @property
    def closed(self) -> bool:
        return self.boundary_edges == 0

    def summary(self) -> str:
        """One line for a status bar or a log."""
        parts = [f"{self.input_vertices} vertices", f"{self.input_triangles} triangles",
                 f"{self.components} component{'s' if self.components != 1 else ''}"]
        for name, count in (("degenerate dropped", self.degenerate_triangles),
                            ("duplicates dropped", self.duplicate_triangles),
                            ("zero-area", self.zero_area_triangles),
                            ("isolated vertices", self.isolated_vertices),
                            ("boundary edges", self.boundary_edges),
                            ("non-manifold edges", self.nonmanifold_edges),
                            ("non-manifold vertices", self.nonmanifold_vertices),
                            ("inconsistently oriented edges", self.inconsistent_edges)):
            if count:
                parts.append(f"{count} {name}")
        return ", ".join(parts)


def as_vertices(vertices) -> np.ndarray:
    """The caller's vertex array as numpy, checked to be floats of shape (n, 3) (ValueError)."""
    array = np.asarray(vertices)
    if array.ndim != 2 or array.shape[1] != 3 or array.dtype.kind != "f":
        raise TopStocError(f"vertices must be a float32 or float64 array of shape (n, 3), "
                           f"got {array.dtype} array of shape {array.shape}")
    return array


def _as_triangles(triangles) -> np.ndarray:
    array = np.asarray(triangles)
    if array.ndim != 2 or array.shape[1] != 3 or array.dtype.kind not in "iu":
        raise TopStocError(f"triangles must be an int32 or int64 array of shape (m, 3), "
                           f"got {array.dtype} array of shape {array.shape}")
    return array


def _digest(array) -> str | None:
    return None if array is None else array_digest(array)


class Mesh:
    """A triangle mesh prepared for TopStoc: adjacency, normals and importance weights.

    Build it once per mesh state; every decimation, measurement and analysis reuses it, so a
    re-decimation costs milliseconds. The caller's arrays are copied and never modified.

    >>> mesh = Mesh(vertices, triangles)          # (n, 3) floats, (m, 3) ints
    >>> result = mesh.decimate(ratio=0.1, seed=1)
    >>> result.vertices, result.triangles
    """

    #: keep_floods' default: floods are kept for meshes of fewer triangles (see __init__)
    KEEP_FLOODS_BELOW = 1_000_000

    def __init__(self, vertices, triangles, progress=None, keep_floods=None):
        """progress: optional ``progress(fraction, stage)``, called from the preparing thread at
        each step (validate, order, adjacency, normals and weights, components); returning False
        stops the preparation with ``topstoc.core.Cancelled`` (the live preview's Esc).
        keep_floods: keep the floods of recent decimations so that nearby targets come sooner
        (see layout_and_floods), and the collapse states of recent quality decimations of meshes
        collapsed whole so that lower targets come sooner (see kept_for_reuse); False saves that
        memory, and the draw's per-vertex tables are not kept either; results are the same.
        None (the default): kept for meshes under KEEP_FLOODS_BELOW triangles; above, from a
        layout's second decimation on (a slider's, not a one-off's: a decimation's flood, its
        first check and the draw's tables, 8 bytes a triangle and more, would sit under the next
        one's peak)."""
        vertices = as_vertices(vertices)
        triangles = _as_triangles(triangles)
        # The engine copies what it needs (reading float64 and int32 arrays in place) and can
        # give the caller's arrays back: the read-only copies below are made on first use only.
        self._native = engine.Mesh(vertices, triangles, progress=progress)
        self._vertices = None
        self._triangles = None
        self._topology = None  # the input's, computed on first use (input_topology)
        self._loose = None  # loose_triangles, counted on first use
        self._layouts: dict = {}
        # True, False, or None: kept from a layout's second decimation on
        self._keep_floods = (bool(keep_floods) if keep_floods is not None
                             else True if self._native.num_faces < self.KEEP_FLOODS_BELOW else None)

    # -- the caller's data, read-only --------------------------------------------------------
    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64 positions as given (read-only copy)."""
        if self._vertices is None:
            vertices = self._native.caller_vertices
            vertices.setflags(write=False)
            self._vertices = vertices
        return self._vertices

    @property
    def triangles(self) -> np.ndarray:
        """(m, 3) int32 triangles as given, including any the validation dropped (read-only)."""
        if self._triangles is None:
            triangles = self._native.caller_triangles
            triangles.setflags(write=False)
            self._triangles = triangles
        return self._triangles

    @property
    def num_vertices(self) -> int:
        return self._native.num_vertices

    @property
    def num_triangles(self) -> int:
        """Triangles after dropping degenerate and duplicate ones."""
        return self._native.num_faces

    @property
    def diagonal(self) -> float:
        """Length of the bounding-box diagonal."""
        return self._native.diagonal

    @property
    def weights(self) -> np.ndarray:
        """Importance weight x(v) of thesis eq. 4.1 per vertex, in [0, 1]."""
        return self._native.weights

    @property
    def normals(self) -> np.ndarray:
        """Unit area-weighted vertex normals (zero where a vertex has no area)."""
        return self._native.normals

    @property
    def native(self):
        """The engine's prepared mesh (for the other topstoc.core modules)."""
        return self._native

    def report(self) -> MeshReport:
        """What validation found and repaired."""
        return MeshReport(**self._native.report)

    def feature_layout(self, regions=None, borders=None, feature_angle: float = 0.0):
        """Feature layout for per-triangle region ids and flagged edges, cached per content.

        regions: one integer per triangle of the caller's array (material slot, UV island...);
        clusters never cross a change of region. borders: (k, 2) vertex pairs that clusters
        never cross (UV seams, sharp edges); each must be an edge of the mesh. feature_angle
        (radians, 0 = off): creases sharper than this become borders too.
        """
        return self.layout_and_floods(regions, borders, feature_angle)[0]

    def layout_and_floods(self, regions=None, borders=None, feature_angle: float = 0.0):
        """The feature layout (see feature_layout) and the floods kept for decimations with it:
        a decimation updates the flood of an earlier one at a nearby target (same seed) instead
        of flooding afresh, with the same result (2 kept per layout, 9 bytes per vertex and 1
        per triangle each; ``clear_floods`` frees them). None instead of the floods when the
        mesh was made with keep_floods=False."""
        return self.kept_for_reuse(regions, borders, feature_angle)[:2]

    def kept_for_reuse(self, regions=None, borders=None, feature_angle: float = 0.0):
        """(layout, floods, collapse states) for decimations with this layout: the floods as in
        layout_and_floods; the collapse states (engine.CollapseSnapshots, 2 kept per layout, a few
        hundred bytes per vertex each) let a quality decimation of a mesh collapsed whole resume toward
        a lower target from where an earlier one's collapses stopped depending on its target, with
        the same result (the input's search structure for their distance passes and the fit of
        small results is kept with them, a few hundred bytes per vertex more). None for both when
        the mesh was made with keep_floods=False."""
        key = (_digest(regions), _digest(borders), float(feature_angle))
        entry = self._layouts.get(key)
        if entry is not None and entry[1] is None and self._keep_floods is None:
            entry = self._layouts[key] = (entry[0], engine.FloodCachePool(), engine.CollapseSnapshots())
        if entry is None:
            layout = engine.build_feature_layout(self._native, regions, borders, float(feature_angle))
            entry = ((layout, engine.FloodCachePool(), engine.CollapseSnapshots()) if self._keep_floods
                     else (layout, None, None))
            if len(self._layouts) >= 8:
                self._layouts.pop(next(iter(self._layouts)))
            self._layouts[key] = entry
        return entry

    def clear_floods(self) -> None:
        """Frees the floods and collapse states kept for re-decimation (see kept_for_reuse)."""
        for _layout, floods, snapshots in self._layouts.values():
            if floods is not None:
                floods.clear()
                snapshots.clear()

    def clear_layouts(self) -> None:
        """Frees the feature layouts and their floods (a one-shot job's: a later decimation builds
        them again, with the same result)."""
        self._layouts.clear()

    @property
    def loose_triangles(self) -> int:
        """Triangles that are pieces of their own (an unwelded mesh is made of them; the engine's
        Mesh::loose_face, which the draw and the collapses keep whole), counted once."""
        if self._loose is None:
            self._loose = self._native.loose_faces
        return self._loose

    @property
    def input_topology(self):
        """The input's topology (core/api/topology.py), computed once: every decimation of a
        mesh whose partition checks leave issues compares its output with it (invariants.py)."""
        if self._topology is None:
            # Copies made for this alone are not kept (24 bytes a triangle for the mesh's life).
            vertices = self._vertices if self._vertices is not None else self._native.caller_vertices
            triangles = self._triangles if self._triangles is not None else self._native.caller_triangles
            self._topology = topology(vertices, triangles)
        return self._topology

    def decimate(self, ratio=None, target_vertices=None, target_triangles=None, **options):
        """TopStoc decimation; see topstoc.core.api.decimate.decimate for every option."""
        return decimate(self, ratio, target_vertices, target_triangles, **options)

    def decimate_with_samples(self, samples, **options):
        """Re-creates a decimation from its saved sample list (thesis 4.1.3)."""
        return decimate_with_samples(self, samples, **options)

    def __repr__(self) -> str:
        return f"<topstoc.Mesh {self.num_vertices} vertices, {self.num_triangles} triangles>"
