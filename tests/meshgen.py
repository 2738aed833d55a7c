"""Synthetic test meshes with known topology (numpy only, no topstoc code)."""

import numpy as np


def icosphere(subdivisions: int = 3):
    """Unit sphere: 10 * 4^k + 2 vertices, genus 0."""
    t = (1 + 5 ** 0.5) / 2
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
                (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    vertices = [np.array(v, dtype=float) / np.linalg.norm(v) for v in vertices]
    for _ in range(subdivisions):
        midpoint = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                m = vertices[a] + vertices[b]
                vertices.append(m / np.linalg.norm(m))
                midpoint[key] = len(vertices) - 1
            return midpoint[key]

        refined = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    return np.array(vertices), np.array(faces, dtype=np.int32)


def torus(nu: int = 32, nv: int = 16, major: float = 1.0, minor: float = 0.35):
    """Torus as an nu x nv grid, genus 1, outward normals."""
    u = np.arange(nu) * 2 * np.pi / nu
    v = np.arange(nv) * 2 * np.pi / nv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    x = (major + minor * np.cos(vv)) * np.cos(uu)
    y = (major + minor * np.cos(vv)) * np.sin(uu)
    z = minor * np.sin(vv)
    vertices = np.stack([x, y, z], -1).reshape(-1, 3)
    idx = lambda i, j: (i % nu) * nv + (j % nv)  # noqa: E731
    faces = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            faces += [(a, b, c), (a, c, d)]
    return vertices, np.array(faces, dtype=np.int32)


def grid(n: int = 10, m: int = 10):
    """Flat n x m quad grid in the xy plane, triangulated: a disk with one boundary loop."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(m + 1, dtype=float), indexing="ij")
    vertices = np.stack([xs, ys, np.zeros_like(xs)], -1).reshape(-1, 3)
    idx = lambda i, j: i * (m + 1) + j  # noqa: E731
    faces = []
    for i in range(n):
        for j in range(m):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            faces += [(a, b, c), (a, c, d)]
    return vertices, np.array(faces, dtype=np.int32)


def voxel_surface(filled: np.ndarray):
    """Boundary surface of a set of unit voxels, outward oriented, vertices welded.

    Manifold as long as no two filled voxels touch only along an edge or at a corner.
    """
    filled = np.pad(np.asarray(filled, dtype=bool), 1)
    quads = []
    offsets = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    # (axis direction, the 4 cube corners of that face in outward counter-clockwise order)
    sides = [((-1, 0, 0), (0, 4, 7, 3)), ((1, 0, 0), (1, 2, 6, 5)), ((0, -1, 0), (0, 1, 5, 4)),
             ((0, 1, 0), (3, 7, 6, 2)), ((0, 0, -1), (0, 3, 2, 1)), ((0, 0, 1), (4, 5, 6, 7))]
    for cell in np.argwhere(filled):
        for direction, corners in sides:
            neighbour = cell + direction
            if not filled[tuple(neighbour)]:
                quads.append([tuple(cell + offsets[c]) for c in corners])
    index = {}
    vertices = []
    faces = []
    for quad in quads:
        ids = []
        for corner in quad:
            if corner not in index:
                index[corner] = len(vertices)
                vertices.append(corner)
            ids.append(index[corner])
        faces += [(ids[0], ids[1], ids[2]), (ids[0], ids[2], ids[3])]
    return np.array(vertices, dtype=float), np.array(faces, dtype=np.int32)


def open_housing(size=(24, 16, 10), window=(6, 18, 5, 11), holes: int = 3):
    """A CAD-like housing of unit voxels: walls and a floor one voxel thick, open at the top, a
    window (x0, x1, y0, y1) through the floor and `holes` 2 x 2 holes through one wall (closed,
    genus holes + 1): flat faces, where a collapse slides a vertex along a plane at no cost."""
    nx, ny, nz = size
    filled = np.zeros(size, dtype=bool)
    filled[:, :, 0] = filled[0] = filled[-1] = filled[:, 0] = filled[:, -1] = True
    x0, x1, y0, y1 = window
    filled[x0:x1, y0:y1, 0] = False
    for k in range(holes):
        filled[4 + 6 * k:6 + 6 * k, 0, 4:6] = False
    return voxel_surface(filled)


def genus_slab(genus: int, scale: int = 2):
    """A slab with `genus` square holes in a row (closed, orientable, genus g)."""
    cells = np.ones((2 * genus + 1, 3, 1), dtype=bool)
    for i in range(genus):
        cells[2 * i + 1, 1, 0] = False
    filled = np.kron(cells, np.ones((scale, scale, scale), dtype=bool))
    return voxel_surface(filled)


def genus_grid(rows: int, columns: int, scale=(1, 1, 1)):
    """A slab with rows x columns square holes in a grid (closed, orientable, genus rows*columns).

    scale: voxels per cell along x, y, z (a finer surface of the same genus)."""
    cells = np.ones((2 * rows + 1, 2 * columns + 1, 1), dtype=bool)
    cells[1::2, 1::2, 0] = False
    return voxel_surface(np.kron(cells, np.ones(scale, dtype=bool)))


def disjoint(*meshes):
    """Several meshes side by side as one mesh (vertex ids offset, positions shifted apart)."""
    vertices, faces, offset, shift = [], [], 0, 0.0
    for v, f in meshes:
        v = np.asarray(v, dtype=float).copy()
        v[:, 0] += shift - v[:, 0].min()
        shift = v[:, 0].max() + 1.0
        vertices.append(v)
        faces.append(np.asarray(f) + offset)
        offset += len(v)
    return np.concatenate(vertices), np.concatenate(faces).astype(np.int32)


# --- Surfaces and complexes for topology tests (abstract where no embedding exists) -----------

def _strip_positions(count: int) -> np.ndarray:
    """Placeholder positions for abstract complexes (topology ignores them; they must be finite)."""
    return np.stack([np.arange(count, dtype=float), np.zeros(count), np.zeros(count)], -1)


def mobius(n: int = 12, width: int = 2):
    """Moebius strip: n columns of width + 1 vertices, the last column glued to the first flipped.

    Non-orientable, one boundary loop, euler characteristic 0.
    """
    rows = width + 1
    idx = lambda i, j: i * rows + j  # noqa: E731
    u = np.repeat(np.arange(n) * 2 * np.pi / n, rows)
    w = np.tile(np.linspace(-0.3, 0.3, rows), n)
    vertices = np.stack([(1 + w * np.cos(u / 2)) * np.cos(u), (1 + w * np.cos(u / 2)) * np.sin(u),
                         w * np.sin(u / 2)], -1)
    faces = []
    for i in range(n):
        for j in range(width):
            a, b = idx(i, j), idx(i, j + 1)
            if i < n - 1:
                c, d = idx(i + 1, j), idx(i + 1, j + 1)
            else:  # the half twist: row j meets row width - j
                c, d = idx(0, width - j), idx(0, width - j - 1)
            faces += [(a, c, d), (a, d, b)]
    return vertices, np.array(faces, dtype=np.int32)


def klein_bottle(nu: int = 8, nv: int = 6):
    """Klein bottle as an abstract complex: a torus grid whose last column is glued back flipped.

    Closed, non-orientable, euler 0: over Z2, betti (1, 2, 1) and 2 cross-caps.
    """
    idx = lambda i, j: i * nv + (j % nv)  # noqa: E731
    faces = []
    for i in range(nu):
        for j in range(nv):
            a, b = idx(i, j), idx(i, j + 1)
            if i < nu - 1:
                c, d = idx(i + 1, j), idx(i + 1, j + 1)
            else:
                c, d = idx(0, -j), idx(0, -(j + 1))
            faces += [(a, c, d), (a, d, b)]
    return _strip_positions(nu * nv), np.array(faces, dtype=np.int32)


def projective_plane():
    """The 6-vertex real projective plane (hemi-icosahedron): over Z2 betti (1, 1, 1), 1 cross-cap."""
    faces = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5), (0, 5, 1), (1, 2, 4), (2, 3, 5), (3, 4, 1),
             (4, 5, 2), (5, 1, 3)]
    return _strip_positions(6), np.array(faces, dtype=np.int32)


def pinched_sphere(subdivisions: int = 1):
    """Sphere with two antipodal vertices identified (a pinched torus): one non-manifold vertex,
    all edges manifold, betti (1, 1, 1)."""
    vertices, faces = icosphere(subdivisions)
    faces = np.where(faces == 3, 0, faces)  # icosphere vertices 0 and 3 are antipodal
    keep = np.arange(len(vertices)) != 3
    remap = np.cumsum(keep) - 1
    return vertices[keep], remap[faces].astype(np.int32)


def theta_surface(ring: int = 8):
    """Three disks (cones) sharing their boundary circle: every ring edge has three triangles.

    Betti (1, 0, 2): two independent 2-cycles, the third disk pair being their sum.
    """
    angles = np.arange(ring) * 2 * np.pi / ring
    circle = np.stack([np.cos(angles), np.sin(angles), np.zeros(ring)], -1)
    apexes = np.array([[0, 0, 1.0], [0, 0, -1.0], [0.3, 0.3, 0.0]])
    faces = [(j, (j + 1) % ring, ring + k) for k in range(3) for j in range(ring)]
    return np.concatenate([circle, apexes]), np.array(faces, dtype=np.int32)


def book(pages: int = 3):
    """Triangles sharing one edge (0, 1), like the pages of a book: contractible, non-manifold."""
    vertices = np.concatenate([[[0, 0, 0], [0, 0, 1.0]],
                               [[np.cos(a), np.sin(a), 0.5] for a in np.arange(pages) * 2 * np.pi / pages]])
    faces = [(0, 1, 2 + k) for k in range(pages)]
    return vertices, np.array(faces, dtype=np.int32)


def tetrahedra_sharing_edge():
    """Boundaries of two tetrahedra glued along one edge (4 triangles on it): betti (1, 0, 2)."""
    vertices = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0.5], [0, 1, 0.5], [-1, 0, 0.5], [0, -1, 0.5]], dtype=float)
    faces = []
    for tet in ((0, 1, 2, 3), (0, 1, 4, 5)):
        a, b, c, d = tet
        faces += [(a, b, c), (a, c, d), (a, d, b), (b, d, c)]
    return vertices, np.array(faces, dtype=np.int32)


def complete_graph(k: int = 4):
    """Edges of the complete graph K_k with no triangle: betti (1, (k-1)(k-2)/2, 0)."""
    vertices = _strip_positions(k)
    edges = np.array([(a, b) for a in range(k) for b in range(a + 1, k)], dtype=np.int32)
    return vertices, np.zeros((0, 3), dtype=np.int32), edges


def subdivide(vertices, triangles, levels: int = 1):
    """Midpoint subdivision (each triangle into four, positions unchanged): same surface, same
    topology, four times the triangles per level."""
    v = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles, dtype=np.int64)
    for _ in range(levels):
        edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
        unique, index = np.unique(edges, axis=0, return_inverse=True)
        index = index.reshape(-1) if index.ndim > 1 else index
        mid = len(v) + index.reshape(3, -1)  # midpoint ids of edges 01, 12, 20 per triangle
        v = np.concatenate([v, 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])])
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        ab, bc, ca = mid
        t = np.concatenate([np.stack([a, ab, ca], 1), np.stack([b, bc, ab], 1), np.stack([c, ca, bc], 1),
                            np.stack([ab, bc, ca], 1)])
    return v, t.astype(np.int32)


def bumpy_torus(triangles: int, chunk: int = 1 << 20):
    """A closed genus-1 torus of about `triangles` triangles (a (2k x k) grid, 2 triangles per
    cell) with bumps of several frequencies on its tube and a tenth of an edge of noise, like a
    dense scan (the same mesh on every run): float64 (n, 3)
    vertices and int32 (m, 3) triangles, filled `chunk` grid points at a time so that the
    arrays themselves are the only big allocation (100M triangles: 2.4 GB)."""
    nv = max(3, int(round((triangles / 4) ** 0.5)))
    nu = max(3, int(round(triangles / (2 * nv))))
    vertices = np.empty((nu * nv, 3))
    faces = np.empty((2 * nu * nv, 3), dtype=np.int32)
    for start in range(0, nu * nv, chunk):
        ids = np.arange(start, min(start + chunk, nu * nv), dtype=np.int64)
        i, j = ids // nv, ids % nv
        u, v = i * (2 * np.pi / nu), j * (2 * np.pi / nv)
        bumps = 1 + 0.12 * np.sin(7 * u) * np.sin(5 * v) + 0.05 * np.sin(41 * u + 3 * v) * np.cos(29 * v)
        noise = np.random.default_rng(start).uniform(-1, 1, len(ids)) * (0.1 * 2 * np.pi * 0.35 / nv)
        r = 0.35 * bumps + noise
        vertices[start:start + len(ids), 0] = (1 + r * np.cos(v)) * np.cos(u)
        vertices[start:start + len(ids), 1] = (1 + r * np.cos(v)) * np.sin(u)
        vertices[start:start + len(ids), 2] = r * np.sin(v)
        a, b = ids, ((i + 1) % nu) * nv + j
        c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
        rows = faces[2 * start:2 * (start + len(ids))]
        rows[0::2, 0], rows[0::2, 1], rows[0::2, 2] = a, b, c
        rows[1::2, 0], rows[1::2, 1], rows[1::2, 2] = a, c, d
    return vertices, faces
