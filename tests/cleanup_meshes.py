"""Meshes with known small and large handles and holes, for the clean-up (numpy only).

Voxel surfaces (tests/meshgen.py) with arches on top: an arch of cross-section a x a over an
opening of a x a voxels is one handle whose handle and tunnel loops are both 4a long. The
positions can be jittered like a scan; cells are one unit, so a jitter below 0.1 keeps the
surface free of self-intersections.
"""

import numpy as np

import meshgen


def _arch(cells: np.ndarray, x: int, y: int, top: int, a: int) -> None:
    """Two posts a x a x a and a bridge over an a x a x a opening, standing on z = top."""
    cells[x:x + a, y:y + a, top:top + a] = True
    cells[x + 2 * a:x + 3 * a, y:y + a, top:top + a] = True
    cells[x:x + 3 * a, y:y + a, top + a:top + 2 * a] = True


def block_with_arches(small: int, large: int = 0, *, large_size: int = 3, jitter: float = 0.0, seed: int = 0):
    """A block with ``small`` unit arches (loops of length 4) and ``large`` arches of
    ``large_size`` (loops 4 * large_size) on its top; genus small + large.

    Arches stand on a grid with a free voxel between neighbours (no edge-only contacts)."""
    small_pitch, large_pitch = 4, 3 * large_size + 1
    per_row = max(1, int(np.ceil(np.sqrt(small))))
    width = max(per_row * small_pitch + 1, large * large_pitch + 1, 8)
    depth = per_row * 2 + 1 + (large_size + 1 if large else 0)
    cells = np.zeros((width, depth + 1, 2 + 2 * max(1, large_size)), dtype=bool)
    cells[:, :, :2] = True
    for i in range(small):
        _arch(cells, 1 + (i % per_row) * small_pitch, 1 + (i // per_row) * 2, 2, 1)
    for i in range(large):
        _arch(cells, 1 + i * large_pitch, per_row * 2 + 1, 2, large_size)
    vertices, triangles = meshgen.voxel_surface(cells)
    return _jittered(vertices, jitter, seed), triangles


def perforated_plate(small: int, large: int, *, side: int = 40, small_size: int = 1, large_size: int = 4,
                     jitter: float = 0.0, seed: int = 0):
    """A flat grid (one border) with ``small`` square holes of ``small_size`` quads a side
    (border 4 * small_size) and ``large`` of ``large_size``, at random places, each at least a
    quad away from the others and from the plate's edge."""
    vertices, triangles = meshgen.grid(side, side)
    quads = triangles.reshape(-1, 2, 3)  # grid() emits the two triangles of quad (i, j) together
    remove = np.zeros((side, side), dtype=bool)
    rng = np.random.default_rng(seed)
    for count, size in ((large, large_size), (small, small_size)):
        spots = [(i, j) for i in range(1, side - size, size + 1) for j in range(1, side - size, size + 1)]
        placed = 0
        for index in rng.permutation(len(spots)):
            i, j = spots[index]
            if placed == count:
                break
            if not remove[i - 1:i + size + 1, j - 1:j + size + 1].any():  # a quad between holes
                remove[i:i + size, j:j + size] = True
                placed += 1
        if placed < count:
            raise ValueError(f"a {side} x {side} plate holds {placed} holes of {size} quads, not {count}")
    kept = quads[~remove.reshape(-1)].reshape(-1, 3)
    return _jittered(vertices, jitter, seed), kept.astype(np.int32)


def _jittered(vertices, jitter: float, seed: int):
    if jitter <= 0:
        return vertices
    rng = np.random.default_rng(seed)
    return vertices + rng.uniform(-jitter, jitter, vertices.shape)


def smoothed(vertices, triangles, iterations: int = 30):
    """Taubin smoothing (lambda 0.5, mu -0.53): rounds a voxel surface into an organic one of the
    same topology without shrinking it (thin arches become smooth little handles)."""
    t = np.asarray(triangles)
    edges = np.unique(np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1), axis=0)
    degree = np.bincount(edges.ravel(), minlength=len(vertices))[:, None]
    v = np.array(vertices, dtype=float)
    for _ in range(iterations):
        for factor in (0.5, -0.53):
            total = np.zeros_like(v)
            np.add.at(total, edges[:, 0], v[edges[:, 1]])
            np.add.at(total, edges[:, 1], v[edges[:, 0]])
            v = v + factor * (total / degree - v)
    return v
