"""The figures of a normal-map bake, without Blender: how far the bake's rays reach, how wide the
UV islands' gaps are, and whether the image fits in memory (the Blender side: blender/decimation/bake.py).

Selected-to-active baking casts a ray inward from every texel's point on the low-poly surface
pushed out by the cage extrusion, over at most the max ray distance. The decimated surface lies
within the measured Hausdorff max ``d`` of the source, so an extrusion a little over ``d`` starts
every ray outside the source (nothing missed) and a reach of twice that stops it before the far
side of thin parts (nothing bleeds).
"""

from __future__ import annotations

import math

import numpy as np

from ..support.errors import TopStocError

MIN_SIZE = 16
MAX_SIZE = 16384
REACH_SLACK = 1.25          #: extrusion = this x the Hausdorff max (+ a floor), the ray twice that
REACH_FLOOR = 1e-4          #: of the bounding-box diagonal: coincident surfaces still get a ray
BYTES_PER_PIXEL = 4 * 4     #: Blender keeps a baked image as RGBA float while baking
MEMORY_SHARE = 0.5          #: an image may take at most this share of the available memory
MAX_OVERLAP = 0.01          #: a UV map with more of its texels covered twice gets a new one for the bake


def ray_reach(hausdorff_max: float, diagonal: float) -> tuple[float, float]:
    """(cage extrusion, max ray distance) for a result within ``hausdorff_max`` of its source whose
    bounding box has the diagonal ``diagonal`` (both in the same, world, units)."""
    if not (math.isfinite(hausdorff_max) and hausdorff_max >= 0):
        raise TopStocError(f"the distance between source and result is not a finite number ({hausdorff_max!r})")
    extrusion = REACH_SLACK * hausdorff_max + REACH_FLOOR * max(diagonal, 0.0)
    return extrusion, 2.0 * extrusion


def check_size(size) -> int:
    """The image's side in pixels (a whole number in [MIN_SIZE, MAX_SIZE]), else a one-line error."""
    if isinstance(size, bool) or not isinstance(size, int) or not MIN_SIZE <= size <= MAX_SIZE:
        raise TopStocError(f"the normal map size must be a whole number of pixels from {MIN_SIZE} to "
                           f"{MAX_SIZE}, got {size!r}")
    return size


def check_memory(size: int, available_bytes) -> None:
    """Refuses an image whose bake buffer would take more than MEMORY_SHARE of ``available_bytes``
    (None: unknown, allowed)."""
    needed = size * size * BYTES_PER_PIXEL
    if available_bytes is not None and needed > MEMORY_SHARE * available_bytes:
        raise TopStocError(f"a {size}x{size} normal map needs {needed / 2**20:,.0f} MiB while baking; only "
                           f"{available_bytes / 2**20:,.0f} MiB of memory are free: choose a smaller size")


def island_margin(margin_pixels: int, size: int) -> float:
    """The UV unwrap's island margin (a fraction of the UV square) that leaves ``margin_pixels`` of
    bleed on each side of every island, i.e. twice that between two islands, at ``size`` pixels."""
    return min(0.5, 2.0 * max(0, margin_pixels) / size)


def rasterize(uv_triangles: np.ndarray, resolution: int, edges: bool = True) -> tuple:
    """The texel centres (``resolution``² over the unit square) inside UV triangles: (texel index
    y * resolution + x, triangle, (k, 3) barycentric weights), one row per texel and triangle.
    ``edges``: a centre on an edge belongs to both triangles (no holes along shared edges);
    False: to neither (two islands that only touch do not overlap)."""
    uv = np.asarray(uv_triangles, dtype=np.float64).reshape(-1, 3, 2)
    pixel = uv * resolution - 0.5                 # texel centres at whole numbers
    low = np.clip(np.ceil(pixel.min(axis=1)), 0, resolution - 1).astype(np.int64)
    high = np.clip(np.floor(pixel.max(axis=1)), 0, resolution - 1).astype(np.int64)
    width, height = np.maximum(high - low + 1, 0).T
    count = width * height
    triangle = np.repeat(np.arange(len(uv)), count)
    offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    x = low[triangle, 0] + offset % np.maximum(width[triangle], 1)
    y = low[triangle, 1] + offset // np.maximum(width[triangle], 1)
    a, b, c = (pixel[triangle, k] for k in range(3))
    # twice the signed areas of the sub-triangles opposite each corner
    w = [(q[:, 0] - x) * (r[:, 1] - y) - (q[:, 1] - y) * (r[:, 0] - x) for q, r in ((b, c), (c, a), (a, b))]
    weights = np.stack(w, axis=1)
    if edges:
        inside = ((weights >= 0).all(axis=1) | (weights <= 0).all(axis=1)) & (weights.sum(axis=1) != 0)
    else:
        inside = (weights > 0).all(axis=1) | (weights < 0).all(axis=1)
    weights = weights[inside]
    weights /= weights.sum(axis=1, keepdims=True)
    return (y * resolution + x)[inside], triangle[inside], weights


def overlap_fraction(uv_triangles: np.ndarray, resolution: int = 512) -> float:
    """Share of the texels covered by a UV layout (``uv_triangles``: (m, 3, 2)) that more than one
    triangle covers (texel centres, ``resolution``² texels over the unit square); 1.0 for a layout
    that leaves the unit square (tiles, UDIMs): a single image cannot hold it either."""
    uv = np.asarray(uv_triangles, dtype=np.float64).reshape(-1, 3, 2)
    if len(uv) == 0:
        return 0.0
    if uv.min() < 0.0 or uv.max() > 1.0:
        return 1.0
    texels = rasterize(uv, resolution, edges=False)[0]
    hits = np.bincount(texels, minlength=resolution * resolution)
    covered = np.count_nonzero(hits)
    return float(np.count_nonzero(hits > 1)) / covered if covered else 0.0


def dilate(values: np.ndarray, filled: np.ndarray, steps: int) -> None:
    """Grows the filled texels of ``values`` ((h, w, c), in place) ``steps`` texels into the empty
    ones (``filled``: (h, w) bool, updated), each new texel the mean of its filled neighbours."""
    for _ in range(steps):
        padded = np.pad(values * filled[..., None], ((1, 1), (1, 1), (0, 0)))
        present = np.pad(filled, 1).astype(np.int64)
        total = padded[:-2, 1:-1] + padded[2:, 1:-1] + padded[1:-1, :-2] + padded[1:-1, 2:]
        count = present[:-2, 1:-1] + present[2:, 1:-1] + present[1:-1, :-2] + present[1:-1, 2:]
        grow = ~filled & (count > 0)
        if not grow.any():
            return
        values[grow] = total[grow] / count[grow][:, None]
        filled |= grow


def available_memory():
    """Bytes of memory free for new allocations (Linux's MemAvailable), None where unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None
