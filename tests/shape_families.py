"""Generated meshes of one size in shapes a decimator meets, for finding slow corners: each is
what a benchmark on one kind of mesh does not contain (numpy only, no topstoc code).

Each family is a function of an approximate triangle count returning float64 (n, 3) vertices
and int32 (m, 3) triangles, the same mesh on every run. The bumpy torus is the reference the
others are compared with (closed, one component, well-shaped triangles).
"""

import numpy as np

import fan_meshes
import loop_families
import meshgen


def bumpy_torus(triangles: int):
    """The reference: a closed genus-1 scan-like torus (meshgen.bumpy_torus)."""
    return meshgen.bumpy_torus(triangles)


def many_spheres(triangles: int):
    """Icospheres of 1,280 triangles scattered apart: many small components (a particle scene)."""
    v, f = meshgen.icosphere(3)
    count = max(1, triangles // len(f))
    offsets = np.random.default_rng(1).uniform(-50, 50, (count, 3))
    vertices = (v[None] + offsets[:, None]).reshape(-1, 3)
    faces = (f[None] + (np.arange(count) * len(v))[:, None, None]).reshape(-1, 3)
    return vertices, faces.astype(np.int32)


def triangle_soup(triangles: int):
    """Unwelded triangles, three vertices each (an STL exported without merging): nothing to collapse."""
    rng = np.random.default_rng(2)
    centres = rng.uniform(0, 100, (triangles, 1, 3))
    vertices = (centres + rng.normal(0, 0.3, (triangles, 3, 3))).reshape(-1, 3)
    return vertices, np.arange(3 * triangles, dtype=np.int32).reshape(-1, 3)


def sheet_with_holes(triangles: int):
    """A wavy open sheet with 2 % of its triangles missing: a scan with thousands of small holes."""
    side = max(2, int((triangles / 2) ** 0.5))
    vertices, faces = meshgen.grid(side, side)
    vertices[:, 2] = 0.3 * np.sin(vertices[:, 0] / 7) * np.cos(vertices[:, 1] / 5)
    keep = np.random.default_rng(3).random(len(faces)) > 0.02
    return vertices, faces[keep]


def sliver_sphere(triangles: int):
    """A UV sphere of 250 rings and as many segments as the size needs: slivers near the poles."""
    rings = 250
    return fan_meshes.uv_sphere(max(8, triangles // (2 * rings)), rings)


def fanned_cylinder(triangles: int):
    """A cylinder of four rows with fanned caps: two vertices of valence equal to the segments."""
    return fan_meshes.cylinder_caps(max(8, triangles // 12), 4)


def needle_strip(triangles: int):
    """A flat strip 8 cells across, each cell 1,000 times longer than it is wide: every triangle a
    needle (a long part's tessellation sliced finely along its length)."""
    rows = max(1, triangles // 16)
    x, y = np.meshgrid(np.arange(9.0), 0.001 * np.arange(rows + 1), indexing="ij")
    vertices = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    i, j = (a.ravel() for a in np.meshgrid(np.arange(8), np.arange(rows), indexing="ij"))
    a = i * (rows + 1) + j
    b, d = a + rows + 1, a + 1
    faces = np.vstack([np.column_stack([a, b, b + 1]), np.column_stack([a, b + 1, d])])
    return vertices, faces.astype(np.int32)


def perforated_plate(triangles: int):
    """A plate with 1,000 random holes (genus 1,000), subdivided up to the size: CAD-like."""
    vertices, faces = loop_families.perforated_plate(1000)
    while 4 * len(faces) <= triangles:
        vertices, faces = meshgen.subdivide(vertices, faces, 1)
    return vertices, faces


def holed_scan(triangles: int):
    """The bumpy torus with 20 triangles missing far apart: a closed scan with a few small holes."""
    vertices, faces = meshgen.bumpy_torus(triangles)
    missing = np.arange(20) * (len(faces) // 20) + len(faces) // 40
    return vertices, np.delete(faces, missing, axis=0)


def torn_scan(triangles: int):
    """The bumpy torus with 0.1 % of its triangles missing and a fin on one edge in 2,000."""
    vertices, faces = meshgen.bumpy_torus(triangles)
    rng = np.random.default_rng(4)
    faces = faces[rng.random(len(faces)) > 0.001]
    fins = faces[rng.choice(len(faces), len(faces) // 2000)]
    tips = vertices[fins[:, 2]] + rng.normal(0, 0.01, (len(fins), 3))
    fin_faces = np.column_stack([fins[:, 0], fins[:, 1], len(vertices) + np.arange(len(fins))]).astype(np.int32)
    return np.vstack([vertices, tips]), np.vstack([faces, fin_faces])


def welded_points(triangles: int):
    """The bumpy torus with 2 % of its vertices moved onto a neighbour: zero-area triangles."""
    vertices, faces = meshgen.bumpy_torus(triangles)
    moved = np.random.default_rng(5).choice(len(vertices), len(vertices) // 50, replace=False)
    vertices = vertices.copy()
    vertices[moved] = vertices[(moved + 1) % len(vertices)]
    return vertices, faces


def flipped_patches(triangles: int):
    """The bumpy torus with a band of a quarter of its triangles and 1 % of the others at random
    wound the other way: the flipped patches of an export or of parts merged from mirrors."""
    vertices, faces = meshgen.bumpy_torus(triangles)
    centre_angle = np.arctan2(vertices[faces[:, 0], 1], vertices[faces[:, 0], 0])
    flip = (centre_angle < -np.pi / 2) | (np.random.default_rng(6).random(len(faces)) < 0.01)
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return vertices, faces


def foliage_cards(triangles: int):
    """Separate quads scattered in a box, two triangles each (leaves or grass cards): hundreds of
    thousands of tiny open components, each at its floor of one triangle below half the count."""
    count = max(1, triangles // 2)
    rng = np.random.default_rng(7)
    centres = rng.uniform(0, 100, (count, 1, 3))
    u, w = rng.normal(0, 0.2, (count, 1, 3)), rng.normal(0, 0.2, (count, 1, 3))
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
    vertices = (centres + corners[None, :, :1] * u + corners[None, :, 1:] * w).reshape(-1, 3)
    base = 4 * np.arange(count)[:, None, None]
    faces = (base + np.array([[0, 1, 2], [0, 2, 3]])[None]).reshape(-1, 3)
    return vertices, faces.astype(np.int32)


def hair_strips(triangles: int):
    """Separate bent strips of 8 quads (hair or grass cards of 16 triangles), scattered: many small
    components with something to collapse in each."""
    count = max(1, triangles // 16)
    rng = np.random.default_rng(8)
    s = np.linspace(0, 1, 9)
    profile = np.stack([np.zeros(9), s, 0.3 * s * s], -1)  # a curved spine, 9 rings of 2 vertices
    ring = np.concatenate([profile - [0.05, 0, 0], profile + [0.05, 0, 0]])  # 18 vertices: left, right
    turn = rng.normal(size=(count, 3, 3))
    q, _ = np.linalg.qr(turn)
    vertices = (np.einsum("nij,vj->nvi", q, ring) + rng.uniform(0, 100, (count, 1, 3))).reshape(-1, 3)
    k = np.arange(8)
    quads = np.concatenate([np.column_stack([k, k + 9, k + 10]), np.column_stack([k, k + 10, k + 1])])
    faces = (quads[None] + 18 * np.arange(count)[:, None, None]).reshape(-1, 3)
    return vertices, faces.astype(np.int32)


def long_cable(triangles: int):
    """A tube of 12 sides wound as a helix of 100 turns, 300,000 times longer than it is thick, its
    triangles needles along it (a CAD spring or cable): thin, curved and sliver-heavy."""
    around = 12
    along = max(4, triangles // (2 * around))
    angle = 200 * np.pi * np.linspace(0, 1, along)
    centre = np.column_stack([50 * np.cos(angle), 50 * np.sin(angle), 1000 * angle / angle[-1]])
    tangent = np.column_stack([-50 * np.sin(angle), 50 * np.cos(angle), np.full(along, 1000 / angle[-1])])
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    normal = -np.column_stack([np.cos(angle), np.sin(angle), np.zeros(along)])  # towards the axis
    binormal = np.cross(tangent, normal)
    phi = 2 * np.pi * np.arange(around) / around
    ring = np.cos(phi)[None, :, None] * normal[:, None] + np.sin(phi)[None, :, None] * binormal[:, None]
    vertices = (centre[:, None] + 0.05 * ring).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(along - 1), np.arange(around), indexing="ij")
    a = (i * around + j).ravel()
    b = (i * around + (j + 1) % around).ravel()
    c, d = a + around, b + around
    faces = np.vstack([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    return vertices, faces.astype(np.int32)


FAMILIES = {f.__name__: f for f in (bumpy_torus, many_spheres, triangle_soup, sheet_with_holes, sliver_sphere,
                                    needle_strip, fanned_cylinder, perforated_plate, holed_scan, torn_scan,
                                    welded_points, flipped_patches, foliage_cards, hair_strips, long_cable)}
