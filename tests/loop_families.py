"""Closed surfaces of known kinds and high genus for the handle and tunnel loops (numpy only).

Issue 39 asks the loops to cost what the size and genus ask, whatever the shape. The families:
perforated plates with irregular (elliptic) holes, Swiss-cheese balls with random tunnels, strut
lattices, Schwarz-P and gyroid surfaces cut by a box, knotted tubes and chains of linked rings,
next to the regular hole grid of tests/meshgen.py. The implicit ones are contoured by marching
tetrahedra (six per grid cube), which always gives a closed, oriented 2-manifold; each family is
deterministic in its seed. `FAMILIES` and `BIG_FAMILIES` are the members the benchmark times.
"""

from __future__ import annotations

import numpy as np

import meshgen

# The cube's six tetrahedra around its main diagonal (corner bits: x = 1, y = 2, z = 4); they
# share faces with the neighbouring cubes' tetrahedra, so the contour is watertight.
_CUBE_TETS = np.array([[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]])
_CORNERS = np.array([[(c >> 0) & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)])
_TET_EDGES = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def contour(field, shape, box_min, box_max):
    """The surface {field < 0} of a function on a grid of `shape` points spanning the box, by
    marching tetrahedra: outward-oriented triangles, vertices shared between tetrahedra.
    field(x, y, z) takes arrays of grid coordinates; its zero level never sits on a grid point
    (values there are nudged)."""
    axes = [np.linspace(box_min[i], box_max[i], shape[i]) for i in range(3)]
    values = field(*np.meshgrid(*axes, indexing="ij"))
    values = np.where(np.abs(values) < 1e-9, 1e-9, values)
    nx, ny, nz = shape
    inside = values < 0
    # Cubes whose eight corners disagree: the only ones the surface passes through.
    corner_in = np.stack([inside[cx:nx - 1 + cx, cy:ny - 1 + cy, cz:nz - 1 + cz] for cx, cy, cz in _CORNERS], -1)
    cubes = np.argwhere(corner_in.any(-1) & ~corner_in.all(-1))
    points = cubes[:, None, None, :] + _CORNERS[_CUBE_TETS][None]      # (cubes, 6, 4, 3)
    points = points.reshape(-1, 4, 3)
    flat = (points[..., 0] * ny + points[..., 1]) * nz + points[..., 2]  # grid point ids
    f = values.reshape(-1)[flat]
    triangles = []
    for tet_case in range(1, 15):
        inside_bits = [(tet_case >> k) & 1 for k in range(4)]
        sign = (f < 0).astype(int)
        pick = np.all(sign == np.array(inside_bits), axis=1)
        if not pick.any():
            continue
        crossing = [k for k, (a, b) in enumerate(_TET_EDGES) if inside_bits[a] != inside_bits[b]]
        ids = flat[pick]
        keys = [np.sort(ids[:, list(_TET_EDGES[k])], axis=1) for k in crossing]
        ring = _ring_order(crossing)
        for corners in ([ring[0], ring[1], ring[2]],) if len(ring) == 3 else ([ring[0], ring[1], ring[2]],
                                                                              [ring[0], ring[2], ring[3]]):
            inner = ids[:, inside_bits.index(1)]
            triangles.append((np.stack([keys[c] for c in corners], 1), inner))
    edge_keys = np.concatenate([t.reshape(-1, 2) for t, _ in triangles])
    unique, index = np.unique(edge_keys, axis=0, return_inverse=True)
    index = index.reshape(-1)
    grid_points = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    fa, fb = values.reshape(-1)[unique[:, 0]], values.reshape(-1)[unique[:, 1]]
    t = np.clip(fa / (fa - fb), 0.05, 0.95)[:, None]  # clipped: no triangle collapses onto a grid point
    vertices = grid_points[unique[:, 0]] * (1 - t) + grid_points[unique[:, 1]] * t
    faces, inner = [], []
    offset = 0
    for tri, corner in triangles:
        faces.append(index[offset:offset + tri.size // 2].reshape(-1, 3))
        inner.append(corner)
        offset += tri.size // 2
    faces, inner = np.concatenate(faces), np.concatenate(inner)
    # Outward: the normal points away from an inside corner of the tetrahedron.
    p = vertices[faces]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    flip = np.einsum("ij,ij->i", normal, p.mean(1) - grid_points[inner]) < 0
    faces[flip] = faces[flip][:, ::-1]
    return vertices, faces.astype(np.int32)


def _ring_order(crossing):
    """The crossed tetrahedron edges in order around the cut (consecutive ones share a face)."""
    faces = [{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}]
    ring = [0]
    while len(ring) < len(crossing):
        last = set(_TET_EDGES[crossing[ring[-1]]])
        for k in range(len(crossing)):
            if k not in ring and any(last | set(_TET_EDGES[crossing[k]]) <= face for face in faces):
                ring.append(k)
                break
    return ring


def _box(x, y, z, half):
    """Signed box distance (negative inside), a max-norm approximation is enough here."""
    return np.maximum(np.maximum(np.abs(x) - half[0], np.abs(y) - half[1]), np.abs(z) - half[2])


def perforated_plate(holes: int, seed: int = 0, resolution: float = 2.0):
    """A plate with `holes` elliptic holes of random size, aspect and angle, none touching."""
    rng = np.random.default_rng(seed)
    side = 2.6 * np.sqrt(holes) + 2
    placed = []
    while len(placed) < holes:
        c = rng.uniform(-side / 2 + 1.4, side / 2 - 1.4, 2)
        a, b = rng.uniform(0.25, 0.9), rng.uniform(0.2, 0.5)
        if all(np.hypot(*(c - q[0])) > a + q[1] + 0.45 for q in placed):
            placed.append((c, a, b, rng.uniform(0, np.pi)))
        if len(placed) < holes and rng.random() < 1e-4:
            side += 0.5
    def field(x, y, z):
        d = _box(x, y, z, (side / 2, side / 2, 0.3))
        for c, a, b, angle in placed:
            u = (x - c[0]) * np.cos(angle) + (y - c[1]) * np.sin(angle)
            v = -(x - c[0]) * np.sin(angle) + (y - c[1]) * np.cos(angle)
            d = np.maximum(d, (1 - np.sqrt((u / a) ** 2 + (v / b) ** 2)) * b)
        return d
    n = int(side * resolution) + 3
    return contour(field, (n, n, 4), (-side / 2 - 0.3, -side / 2 - 0.3, -0.6), (side / 2 + 0.3, side / 2 + 0.3, 0.6))


def random_slab(holes: int, seed: int = 0, thickness: int = 2):
    """A voxel slab with `holes` rectangular holes of random sides (1 to 4 voxels) at random
    places, a voxel or more apart: a perforated plate that is not a grid of holes."""
    rng = np.random.default_rng(seed)
    side = int(3.2 * np.sqrt(holes)) + 4
    cells = np.ones((side, side, thickness), dtype=bool)
    placed = 0
    for _ in range(200 * holes):
        if placed == holes:
            break
        w, h = rng.integers(1, 5, 2)
        x, y = rng.integers(1, side - w - 1), rng.integers(1, side - h - 1)
        if cells[x - 1:x + w + 1, y - 1:y + h + 1, 0].all():
            cells[x:x + w, y:y + h, :] = False
            placed += 1
    if placed < holes:
        raise ValueError(f"placed {placed} of {holes} holes")
    return meshgen.voxel_surface(cells)


def swiss_cheese(tunnels: int, seed: int = 0, resolution: float = 12.0):
    """A ball pierced by `tunnels` straight tunnels of random radius along random chords
    (tunnels may cross: the genus is what results)."""
    rng = np.random.default_rng(seed)
    lines = []
    for _ in range(tunnels):
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        offset = rng.uniform(-0.7, 0.7, 3)
        lines.append((offset - offset.dot(direction) * direction, direction, rng.uniform(0.04, 0.1)))
    def field(x, y, z):
        d = np.sqrt(x * x + y * y + z * z) - 1.0
        for point, direction, radius in lines:
            px, py, pz = x - point[0], y - point[1], z - point[2]
            along = px * direction[0] + py * direction[1] + pz * direction[2]
            dist = np.sqrt(np.maximum(px * px + py * py + pz * pz - along * along, 0))
            d = np.maximum(d, radius - dist)
        return d
    n = int(2.2 * resolution) + 1
    return contour(field, (n, n, n), (-1.1, -1.1, -1.1), (1.1, 1.1, 1.1))


def strut_lattice(cells: int, resolution: int = 6, radius: float = 0.22):
    """Struts along the edges of a cells^3 cube lattice (a scaffold): the genus is the cycle rank
    of the struts' graph, 3c(c + 1)^2 - (c + 1)^3 + 1 for c cells (81 for 3)."""
    def field(x, y, z):
        fx, fy, fz = (np.abs(t - np.round(t)) for t in (x, y, z))
        d = np.minimum(np.minimum(np.hypot(fy, fz), np.hypot(fx, fz)), np.hypot(fx, fy)) - radius
        return np.maximum(d, _box(x - cells / 2, y - cells / 2, z - cells / 2, (cells / 2 + radius,) * 3))
    n = cells * resolution + 7
    pad = 0.5
    return contour(field, (n, n, n), (-pad,) * 3, (cells + pad,) * 3)


def schwarz_p(cells: int, resolution: int = 8):
    """Schwarz's P surface cos x + cos y + cos z = 0 filled on one side, cut by a box of cells^3
    periods."""
    period = 2 * np.pi
    def field(x, y, z):
        p = np.cos(x) + np.cos(y) + np.cos(z) - 0.3
        return np.maximum(p, _box(x - cells * np.pi, y - cells * np.pi, z - cells * np.pi, (cells * np.pi - 0.8,) * 3))
    n = cells * resolution + 3
    return contour(field, (n, n, n), (-0.3,) * 3, (cells * period + 0.3,) * 3)


def gyroid(cells: float, resolution: int = 10, thickness: float = 0.0):
    """The gyroid sin x cos y + sin y cos z + sin z cos x = 0 filled on one side inside a box
    of `cells` periods a side."""
    period = 2 * np.pi
    extent = cells * period
    def field(x, y, z):
        s = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x) - thickness
        return np.maximum(s, _box(x - extent / 2, y - extent / 2, z - extent / 2, (extent / 2 - 0.35,) * 3))
    n = int(cells * resolution) + 3
    return contour(field, (n, n, n), (-0.2,) * 3, (extent + 0.2,) * 3)


def _tube(curve, radius: float, around: int):
    """A closed tube of `around` vertices a ring about a closed polyline (rotation-minimising
    frames, the seam twist spread along the tube)."""
    m = len(curve)
    tangent = np.roll(curve, -1, 0) - np.roll(curve, 1, 0)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    normal = np.cross(tangent[0], [0.3, 0.5, 0.81])
    normal /= np.linalg.norm(normal)
    normals = [normal]
    for i in range(1, m + 1):
        t = tangent[i % m]
        n = normals[-1] - normals[-1].dot(t) * t
        normals.append(n / np.linalg.norm(n))
    twist = np.arctan2(np.cross(normals[m], normals[0]).dot(tangent[0]), normals[m].dot(normals[0]))
    angles = np.linspace(0, 2 * np.pi, around, endpoint=False)
    vertices = []
    for i in range(m):
        n = normals[i]
        b = np.cross(tangent[i], n)
        a = angles + twist * i / m
        vertices.append(curve[i] + radius * (np.cos(a)[:, None] * n + np.sin(a)[:, None] * b))
    vertices = np.concatenate(vertices)
    faces = []
    for i in range(m):
        for j in range(around):
            a, b = i * around + j, i * around + (j + 1) % around
            c, d = ((i + 1) % m) * around + (j + 1) % around, ((i + 1) % m) * around + j
            faces += [(a, d, c), (a, c, b)]
    return vertices, np.array(faces, dtype=np.int32)


def torus_knot(p: int = 2, q: int = 3, samples: int = 400, around: int = 16, radius: float = 0.25):
    """A tube around the (p, q) torus knot (p = 2, q = 3: the trefoil): genus 1, knotted."""
    t = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    r = 2 + np.cos(q * t)
    return _tube(np.stack([r * np.cos(p * t), r * np.sin(p * t), -np.sin(q * t)], 1), radius, around)


def linked_rings(count: int, samples: int = 48, around: int = 12):
    """A chain of `count` rings, each through the next: `count` components of genus 1."""
    t = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    parts = []
    for i in range(count):
        ring = np.stack([np.cos(t) + 1.5 * i, np.sin(t), 0 * t], 1)
        if i % 2:
            ring = np.stack([ring[:, 0], ring[:, 2], ring[:, 1]], 1)
        parts.append(_tube(ring, 0.2, around))
    vertices, faces, offset = [], [], 0
    for v, f in parts:
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.concatenate(vertices), np.concatenate(faces).astype(np.int32)


def hole_grid(rows: int = 7, columns: int = 19):
    """The reference: a slab with rows x columns square holes (tests/bench/bench_loops.py)."""
    return meshgen.genus_grid(rows, columns, scale=(2, 2, 3))


# name -> maker: the families at the sizes the benchmark runs (tests/bench/bench_loops.py); the
# tests use smaller members. Up to 20k triangles and genus 150, then one of 1M at genus 1,000.
FAMILIES = {
    "grid 7x19": lambda: hole_grid(7, 19),
    "voxel plate, 150 random holes": lambda: random_slab(150, seed=1),
    "elliptic plate, 30 holes": lambda: perforated_plate(30, seed=1),
    "swiss cheese, 40 tunnels": lambda: swiss_cheese(40, seed=4, resolution=8),
    "strut lattice 3x3x3": lambda: strut_lattice(3, resolution=3),
    "schwarz-p 4x4x4": lambda: schwarz_p(4, resolution=3),
    "gyroid 2.5 periods": lambda: gyroid(2.5, resolution=5),
    "trefoil tube": lambda: torus_knot(2, 3),
    "(3, 5) torus knot tube": lambda: torus_knot(3, 5, samples=600),
    "8 linked rings": lambda: linked_rings(8),
}
BIG_FAMILIES = {
    "voxel plate, 1000 random holes, subdivided twice": lambda: meshgen.subdivide(*random_slab(1000, seed=1), 2),
}
