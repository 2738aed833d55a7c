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


def with_pinched_handles(vertices, triangles, count: int, *, seed: int = 0, height: float = 1.2,
                         waist: float = 0.5):
    """A copy of a scan with ``count`` pinched handles added, like a scanner's bridge across a
    crease: two triangles a few rings apart are removed and joined by a thin three-sided arch
    (bottom rings the removed triangles, a middle ring ``waist`` times as wide raised ``height``
    times the triangles' distance along their normal). Arches that would cross the surface or
    another arch are skipped. Returns (vertices, triangles, the arches' vertex ids (count, 9))."""
    from topstoc.core.api.loops import self_intersections

    v = np.array(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64).copy()
    rng = np.random.default_rng(seed)
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    centres = v[t].mean(axis=1)
    boxes = v[t].min(axis=1), v[t].max(axis=1)
    spacing = np.median(np.linalg.norm(v[t[:, 0]] - v[t[:, 1]], axis=1))
    taken = np.zeros(len(v), dtype=bool)  # vertices near an arch already made
    arches, removed = [], []
    for first in rng.permutation(len(t)):
        if len(arches) == count:
            break
        distance = np.linalg.norm(centres - centres[first], axis=1)
        near = np.flatnonzero((distance > 2.5 * spacing) & (distance < 3.5 * spacing)
                              & (normals @ normals[first] > 0.9))
        near = [k for k in near if not np.isin(t[k], t[first]).any()]
        if not near or taken[t[first]].any():
            continue
        second = int(near[0])
        if taken[t[second]].any():
            continue
        middle, faces = _arch_between(v, t[first], t[second], normals[first] + normals[second], height, waist)
        faces = np.where(faces < 0, len(v) - 1 - faces, faces)  # middle vertex -1-k becomes len(v) + k
        trial_v = np.vstack([v, middle])
        low, high = trial_v[faces].reshape(-1, 3).min(axis=0), trial_v[faces].reshape(-1, 3).max(axis=0)
        near = np.all(boxes[1] >= low, axis=1) & np.all(boxes[0] <= high, axis=1)  # boxes meet the arch's
        near[removed + [first, second]] = False  # (arches stand apart: only the scan's triangles can cross)
        pairs = np.asarray(self_intersections(trial_v, np.vstack([t[:len(near)][near], faces]).astype(np.int32)))
        if (pairs.reshape(-1, 2) >= near.sum()).any():  # the arch crosses something (old crossings stay)
            continue
        taken[np.unique(t[:len(centres)][distance < 6 * spacing])] = True
        arches.append(np.concatenate([t[first], np.arange(len(v), len(v) + 3), t[second]]))
        removed += [int(first), second]
        v, t = trial_v, np.vstack([t, faces])
    kept = np.ones(len(t), dtype=bool)
    kept[removed] = False
    return v, t[kept].astype(np.int32), np.array(arches, dtype=np.int64).reshape(-1, 9)


def _arch_between(v, a, b, normal, height: float, waist: float):
    """(3 middle-ring positions, 12 arch triangles) joining triangle ``a``'s rim to triangle ``b``'s:
    the middle ring's vertices numbered -1, -2, -3 (placed by the caller). The arch keeps the
    surface oriented: it runs along a's edges as a does and along b's the other way."""
    lower = a
    upper = b[::-1]  # b reversed: the surface around b's hole runs along b's edges backwards
    shift = min(range(3), key=lambda s: np.linalg.norm(v[np.roll(upper, s)] - v[lower], axis=1).sum())
    upper = np.roll(upper, shift)
    normal = normal / np.linalg.norm(normal)
    gap = np.linalg.norm(v[a].mean(axis=0) - v[b].mean(axis=0))
    centre = (v[a].mean(axis=0) + v[b].mean(axis=0)) / 2 + height * gap * normal
    middle = centre + waist * ((v[lower] - v[lower].mean(axis=0)) + (v[upper] - v[upper].mean(axis=0))) / 2
    m = np.array([-1, -2, -3])
    faces = []
    for i in range(3):
        j = (i + 1) % 3
        faces += [[lower[i], lower[j], m[j]], [lower[i], m[j], m[i]], [m[i], m[j], upper[j]], [m[i], upper[j], upper[i]]]
    return middle, np.array(faces, dtype=np.int64)

