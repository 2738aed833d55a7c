"""Mesh file I/O (topstoc.core.api.io): every test file against an independent parser written
here in plain Python/numpy, against the statistics in tests/data/LICENSES.md, round trips
through every format, and the error cases."""

import bz2
import gzip
import pathlib
import re
import struct
import warnings

import numpy as np
import pytest

from topstoc.core.api import io
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
MESH_FILES = sorted(p for p in DATA.rglob("*") if p.is_file() and re.search(r"\.(obj|ply|off|stl)(\.gz)?$", p.name)
                    and "regressions" not in p.parts)  # malformed on purpose: test_io_robust.py
UNREADABLE = {"openscad_unparseable.stl"}


# --- an independent reader: slow, simple, only what the test files need -----------------------

def _text(path):
    raw = path.read_bytes()
    return gzip.decompress(raw) if path.name.endswith(".gz") else raw


def _fan(polygon):
    return [(polygon[0], polygon[i], polygon[i + 1]) for i in range(1, len(polygon) - 1)]


def ref_off(data):
    lines = [line.split("#")[0].split() for line in data.decode("latin-1").splitlines()]
    lines = [line for line in lines if line]
    assert lines[0][0].endswith("OFF")
    counts = lines[0][1:] or lines[1]
    start = 1 if lines[0][1:] else 2
    n, f = int(counts[0]), int(counts[1])
    vertices = np.array([[float(x) for x in line[:3]] for line in lines[start:start + n]])
    triangles, polygon = [], []
    for i, line in enumerate(lines[start + n:start + n + f]):
        k = int(line[0])
        for tri in _fan([int(x) for x in line[1:1 + k]]):
            triangles.append(tri)
            polygon.append(i)
    return dict(vertices=vertices.reshape(-1, 3), triangles=np.array(triangles).reshape(-1, 3), polygon=polygon)


def ref_obj(data):
    vertices, uvs, triangles, polygon, corner_uvs, materials = [], [], [], [], [], []
    material, faces = None, 0
    for line in data.decode("latin-1").splitlines():
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "vt":
            uvs.append([float(x) for x in (parts[1:3] + ["0"])[:2]])
        elif parts[0] == "usemtl":
            material = " ".join(parts[1:])
        elif parts[0] == "f":
            corners = []
            for token in parts[1:]:
                fields = token.split("/")
                v = int(fields[0])
                t = int(fields[1]) if len(fields) > 1 and fields[1] else None
                v = v - 1 if v > 0 else len(vertices) + v
                t = None if t is None else (t - 1 if t > 0 else len(uvs) + t)
                corners.append((v, t))
            for tri in _fan(corners):
                triangles.append([c[0] for c in tri])
                corner_uvs.append([uvs[c[1]] if c[1] is not None else [np.nan, np.nan] for c in tri])
                polygon.append(faces)
                materials.append(material)
            faces += 1
    return dict(vertices=np.array(vertices).reshape(-1, 3), triangles=np.array(triangles).reshape(-1, 3),
                polygon=polygon, uvs=np.array(corner_uvs).reshape(-1, 3, 2) if uvs else None, materials=materials)


PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4",
             "float": "f4", "double": "f8", "int8": "i1", "uint8": "u1", "int16": "i2", "uint16": "u2",
             "int32": "i4", "uint32": "u4", "float32": "f4", "float64": "f8"}


def ref_ply(data):
    """PLY with a vertex element of scalars and a face element holding one index list."""
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").splitlines()
    fmt = header[1].split()[1]
    elements = []
    for line in header:
        words = line.split()
        if words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            elements[-1][2].append(words[1:])
    body = data[end:]
    out = {}
    if fmt == "ascii":
        tokens = body.split()
        pos = 0
        for name, count, props in elements:
            rows = []
            for _ in range(count):
                row = []
                for prop in props:
                    if prop[0] == "list":
                        k = int(tokens[pos]); pos += 1
                        row.append([int(x) for x in tokens[pos:pos + k]]); pos += k
                    else:
                        row.append(float(tokens[pos])); pos += 1
                rows.append(row)
            out[name] = (props, rows)
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        pos = 0
        for name, count, props in elements:
            if all(p[0] != "list" for p in props):
                dtype = np.dtype([(p[1], order + PLY_TYPES[p[0]]) for p in props])
                table = np.frombuffer(body, dtype, count, pos)
                pos += dtype.itemsize * count
                out[name] = (props, [list(row) for row in table.tolist()])
            else:
                rows = []
                for _ in range(count):
                    row = []
                    for prop in props:
                        if prop[0] == "list":
                            ct, vt = PLY_TYPES[prop[1]], PLY_TYPES[prop[2]]
                            (k,) = struct.unpack_from(order + _STRUCT[ct], body, pos); pos += int(ct[1])
                            values = struct.unpack_from(order + _STRUCT[vt] * k, body, pos); pos += int(vt[1]) * k
                            row.append(list(values))
                        else:
                            t = PLY_TYPES[prop[0]]
                            row.append(struct.unpack_from(order + _STRUCT[t], body, pos)[0]); pos += int(t[1])
                    rows.append(row)
                out[name] = (props, rows)
    props, rows = out["vertex"]
    names = [p[-1] for p in props]
    vertices = np.array([[row[names.index(a)] for a in "xyz"] for row in rows], dtype=float).reshape(-1, 3)
    colors = None
    if "red" in names:
        channels = ["red", "green", "blue"] + (["alpha"] if "alpha" in names else [])
        colors = np.array([[row[names.index(c)] for c in channels] for row in rows]) / 255.0
    props, rows = out["face"]
    names = [p[-1] for p in props]
    triangles, polygon = [], []
    for i, row in enumerate(rows):
        for tri in _fan(row[names.index("vertex_indices")]):
            triangles.append(tri)
            polygon.append(i)
    return dict(vertices=vertices, triangles=np.array(triangles).reshape(-1, 3), polygon=polygon, colors=colors)


_STRUCT = {"i1": "b", "u1": "B", "i2": "h", "u2": "H", "i4": "i", "u4": "I", "f4": "f", "f8": "d"}


def ref_stl(data):
    """STL welded by exact position (first appearance order)."""
    corners = []
    if len(data) >= 84 and 84 + 50 * struct.unpack_from("<I", data, 80)[0] == len(data):
        count = struct.unpack_from("<I", data, 80)[0]
        for t in range(count):
            values = struct.unpack_from("<12f", data, 84 + 50 * t)
            corners += [values[3:6], values[6:9], values[9:12]]
    else:
        for line in data.decode("ascii").splitlines():
            parts = line.split()
            if parts and parts[0] == "vertex":
                corners.append(tuple(float(x) for x in parts[1:4]))
    ids, vertices = {}, []
    for c in corners:
        key = tuple(x + 0.0 for x in c)
        if key not in ids:
            ids[key] = len(vertices)
            vertices.append(key)
    triangles = np.array([ids[tuple(x + 0.0 for x in c)] for c in corners]).reshape(-1, 3)
    return dict(vertices=np.array(vertices, dtype=float).reshape(-1, 3), triangles=triangles,
                polygon=list(range(len(triangles))))


def reference(path):
    kind = re.search(r"\.(obj|ply|off|stl)", path.name).group(1)
    return {"obj": ref_obj, "ply": ref_ply, "off": ref_off, "stl": ref_stl}[kind](_text(path))


def licence_figures():
    """V and triangles per file from the statistics table in tests/data/LICENSES.md."""
    figures = {}
    for line in (DATA / "LICENSES.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 3 and re.fullmatch(r"\d+", cells[1]) and re.fullmatch(r"\d+", cells[2]):
            figures[cells[0]] = (int(cells[1]), int(cells[2]))
    return figures


# --- every test file -------------------------------------------------------------------------

@pytest.mark.parametrize("path", [p for p in MESH_FILES if p.name not in UNREADABLE],
                         ids=lambda p: p.name)
def test_reads_like_the_reference(path):
    data = read_mesh(path, allow_empty=True)
    ref = reference(path)
    assert data.vertices.dtype == np.float64 and data.triangles.dtype == np.int32
    assert data.vertices.shape == ref["vertices"].shape
    assert data.triangles.shape == ref["triangles"].shape
    # Decimal text parses to the same doubles (both use correctly rounded conversion).
    np.testing.assert_array_equal(data.vertices, ref["vertices"])
    np.testing.assert_array_equal(data.triangles, ref["triangles"])
    np.testing.assert_array_equal(data.triangle_polygon, ref["polygon"])
    if ref.get("uvs") is not None:
        np.testing.assert_array_equal(data.corner_uvs, ref["uvs"])
    if ref.get("materials") and any(m is not None for m in ref["materials"]):
        names = [data.material_names[i] if i >= 0 else None for i in data.triangle_material]
        assert names == ref["materials"]


def test_statistics_match_licences_table():
    figures = licence_figures()
    assert len(figures) >= 20
    for relative, (welded_vertices, triangles) in figures.items():
        data = read_mesh(DATA / relative, allow_empty=True)
        assert data.num_triangles == triangles, relative
        # The table counts the vertices that faces use, position-welded where meshstat could
        # weld without changing the topology, else as indexed.
        used = np.unique(data.triangles.ravel())
        assert welded_vertices in (len(used), len(np.unique(data.vertices[used], axis=0))), relative


def test_dragon_keeps_the_files_vertex_order_and_duplicates():
    data = read_mesh(DATA / "nonmanifold_degenerate" / "dragon_vrip_res4.ply.gz")
    assert data.num_vertices == 5205  # the file's count; faces use 5203 of them
    assert data.num_triangles == 11102


def test_duck_and_spider_uvs_and_materials():
    duck = read_mesh(DATA / "uv_materials" / "duck" / "duck_via_assimp.obj")
    assert duck.material_names == ["blinn3"]
    assert duck.material_libraries == ["duck_via_assimp.mtl"]
    assert np.all(duck.triangle_material == 0)
    assert duck.corner_uvs.shape == (4212, 3, 2) and np.isfinite(duck.corner_uvs).all()
    assert duck.triangle_polygon.max() + 1 == 2144  # quads and triangles in the file

    spider = read_mesh(DATA / "uv_materials" / "spider" / "spider.obj")
    assert spider.material_names == ["HLeibTex", "Skin", "BeinTex", "Augentex"]  # order of first use
    counts = np.bincount(spider.triangle_material, minlength=4)
    text = (DATA / "uv_materials" / "spider" / "spider.obj").read_text(errors="replace").splitlines()
    expected, current = {}, None
    for line in text:
        if line.startswith("usemtl"):
            current = line.split()[1]
        elif line.startswith("f "):
            expected[current] = expected.get(current, 0) + 1
    assert dict(zip(spider.material_names, counts.tolist())) == expected
    assert np.isfinite(spider.corner_uvs).all()


@pytest.mark.parametrize("name", ["openscad_empty.stl"])
def test_empty_stl_is_an_error_unless_allowed(name):
    with pytest.raises(ValueError, match=f"{name}: the mesh has no triangles: the file is empty"):
        read_mesh(DATA / "nonmanifold_degenerate" / name)
    data = read_mesh(DATA / "nonmanifold_degenerate" / name, allow_empty=True)
    assert data.vertices.shape == (0, 3) and data.triangles.shape == (0, 3)


# --- round trips -----------------------------------------------------------------------------

def attributed_mesh():
    """Two quads and a pentagon with UVs (a seam at vertex 1), colours and materials."""
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0.5], [2, 1, 0.1],
                         [3, 0.5, 0.25], [0.1, 0.2, 1 / 3]], dtype=np.float64)
    polygons = [[0, 1, 2, 3], [1, 4, 5, 2], [4, 6, 5, 7, 2]]
    triangles, polygon = [], []
    for i, p in enumerate(polygons):
        for tri in _fan(p):
            triangles.append(tri)
            polygon.append(i)
    triangles = np.array(triangles, dtype=np.int32)
    rng = np.random.default_rng(5)
    uvs = rng.random((len(triangles), 3, 2))
    # Corners that share a polygon corner share its UV, as a reader produces them.
    for t, tri in enumerate(triangles):
        first = polygon.index(polygon[t])
        uvs[t, 0] = uvs[first, 0]
        if t != first:
            uvs[t, 1] = uvs[t - 1, 2]
    colors = np.round(rng.random((len(vertices), 4)) * 255) / 255
    return MeshData(vertices=vertices, triangles=triangles, triangle_polygon=np.array(polygon),
                    corner_uvs=uvs, vertex_colors=colors, triangle_material=np.array([0, 0, 1, 1, -1, -1, -1]),
                    material_names=["red", "green paint"], material_libraries=["scene.mtl"])


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off", ".stl", ".obj.gz", ".ply.gz", ".off.bz2", ".stl.gz"])
def test_round_trip_keeps_what_the_format_carries(tmp_path, suffix):
    mesh = attributed_mesh()
    before = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in vars(mesh).items()}
    path = tmp_path / f"mesh{suffix}"
    write_mesh(path, mesh)
    for key, value in before.items():  # the caller's data is untouched
        np.testing.assert_array_equal(getattr(mesh, key), value)
    back = read_mesh(path)
    kind = suffix.split(".")[1]
    if kind == "stl":
        # Welded in order of first appearance; positions become float32.
        corners = back.vertices[back.triangles]
        np.testing.assert_array_equal(corners, mesh.vertices[mesh.triangles].astype(np.float32))
        return
    np.testing.assert_array_equal(back.vertices, mesh.vertices)
    np.testing.assert_array_equal(back.triangles, mesh.triangles)
    np.testing.assert_array_equal(back.triangle_polygon, mesh.triangle_polygon)  # polygons rebuilt
    np.testing.assert_array_equal(back.vertex_colors, mesh.vertex_colors)
    if kind in ("obj", "ply"):
        np.testing.assert_array_equal(back.corner_uvs, mesh.corner_uvs)
    if kind == "obj":
        np.testing.assert_array_equal(back.triangle_material, mesh.triangle_material)
        assert back.material_names == mesh.material_names
        assert back.material_libraries == ["scene.mtl"]


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off"])
@pytest.mark.parametrize("name", ["genus_positive/cgal_torus_quad.off", "open_boundary/kivy_suzanne_monkey.obj",
                                  "uv_materials/spider/spider.obj",
                                  "nonmanifold_degenerate/dragon_vrip_res4.ply.gz"])
def test_round_trip_of_test_files(tmp_path, name, suffix):
    original = read_mesh(DATA / name)
    write_mesh(tmp_path / f"copy{suffix}", original)
    back = read_mesh(tmp_path / f"copy{suffix}")
    np.testing.assert_array_equal(back.vertices, original.vertices)
    np.testing.assert_array_equal(back.triangles, original.triangles)
    _, first = np.unique(original.triangle_polygon, return_inverse=True)
    _, again = np.unique(back.triangle_polygon, return_inverse=True)
    np.testing.assert_array_equal(first, again)  # same grouping into polygons
    if suffix != ".off" and original.corner_uvs is not None:
        np.testing.assert_array_equal(back.corner_uvs, original.corner_uvs)


def test_ply_writes_float32_when_exact_and_double_otherwise(tmp_path):
    exact = MeshData(vertices=np.array([[0, 0, 0], [1, 0, 0], [0, 0.5, 0]]), triangles=[[0, 1, 2]])
    write_mesh(tmp_path / "a.ply", exact)
    assert b"property float x" in (tmp_path / "a.ply").read_bytes()[:300]
    inexact = MeshData(vertices=np.array([[0, 0, 0], [1, 0, 0], [0, 0.1, 0]]), triangles=[[0, 1, 2]])
    write_mesh(tmp_path / "b.ply", inexact)
    assert b"property double x" in (tmp_path / "b.ply").read_bytes()[:300]
    np.testing.assert_array_equal(read_mesh(tmp_path / "b.ply").vertices, inexact.vertices)


# --- format variants written by hand ---------------------------------------------------------

def _ply_bytes(order, vertex_props, vertices, count_type, index_type, faces, extra_face=None):
    o = {"little": "<", "big": ">"}[order]
    header = ["ply", f"format binary_{order}_endian 1.0", f"element vertex {len(vertices)}"]
    header += [f"property {t} {n}" for t, n in vertex_props]
    header += [f"element face {len(faces)}", f"property list {count_type} {index_type} vertex_indices"]
    if extra_face:
        header.append(extra_face[0])
    header.append("end_header")
    body = b"".join(struct.pack(o + "".join(_STRUCT[PLY_TYPES[t]] for t, _ in vertex_props), *row) for row in vertices)
    for i, face in enumerate(faces):
        body += struct.pack(o + _STRUCT[PLY_TYPES[count_type]], len(face))
        body += struct.pack(o + _STRUCT[PLY_TYPES[index_type]] * len(face), *face)
        if extra_face:
            body += extra_face[1](i)
    return ("\n".join(header) + "\n").encode() + body


@pytest.mark.parametrize("order", ["little", "big"])
@pytest.mark.parametrize("count_type,index_type", [("uchar", "int"), ("uint8", "uint32"), ("ushort", "short"),
                                                   ("int", "uchar"), ("char", "ushort")])
def test_binary_ply_variants(tmp_path, order, count_type, index_type):
    props = [("double", "x"), ("float", "y"), ("float", "z"), ("uchar", "red"), ("uchar", "green"),
             ("uchar", "blue"), ("float", "nx")]
    vertices = [(0.1, 0.0, 0.0, 255, 0, 10, 1.0), (1.0, 0.0, 0.0, 0, 255, 20, 1.0), (1.0, 1.0, 0.0, 1, 2, 3, 1.0),
                (0.0, 1.0, 0.5, 4, 5, 6, 1.0), (2.0, 0.5, 0.25, 7, 8, 9, 1.0)]
    faces = [[0, 1, 2, 3], [1, 4, 2]]
    # An extra per-face property after the list must be read past.
    path = tmp_path / "variant.ply"
    path.write_bytes(_ply_bytes(order, props, vertices, count_type, index_type, faces,
                                ("property float quality", lambda i: struct.pack({"little": "<", "big": ">"}[order] + "f", i))))
    data = read_mesh(path)
    ref = ref_ply(path.read_bytes())
    np.testing.assert_array_equal(data.vertices, ref["vertices"])
    np.testing.assert_array_equal(data.vertices[:, 0], [0.1, 1, 1, 0, 2])  # double kept exactly
    np.testing.assert_array_equal(data.triangles, [[0, 1, 2], [0, 2, 3], [1, 4, 2]])
    np.testing.assert_array_equal(data.triangle_polygon, [0, 0, 1])
    np.testing.assert_array_equal(data.vertex_colors, ref["colors"])



def _grid_strips_ply(rows, cols, strips):
    """A rows × cols grid of vertices in z = 0 and a tristrips element of `strips` (index lists)."""
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {rows * cols}", "property float x",
              "property float y", "property float z", f"element tristrips {len(strips)}",
              "property list int int vertex_indices", "end_header"]
    body = b"".join(struct.pack("<fff", c, r, 0.0) for r in range(rows) for c in range(cols))
    for strip in strips:
        body += struct.pack("<i", len(strip)) + struct.pack(f"<{len(strip)}i", *strip)
    return ("\n".join(header) + "\n").encode() + body


@pytest.mark.parametrize("joined", ["restart", "degenerate"])
def test_ply_triangle_strips_read_as_the_grid_they_cover(tmp_path, joined):
    rows, cols = 4, 5
    v = lambda r, c: r * cols + c  # noqa: E731
    strips = [[i for c in range(cols) for i in (v(r, c), v(r + 1, c))] for r in range(rows - 1)]
    if joined == "restart":  # one row of the element, the strips separated by -1
        rows_of_element = [[i for k, s in enumerate(strips) for i in ([-1] if k else []) + s]]
    else:  # one strip: repeated indices join the rows (zero-area triangles, no faces), an even count between
        joined_strip = []
        for k, s in enumerate(strips):
            joined_strip += ([joined_strip[-1], s[0]] if k else []) + s
        rows_of_element = [joined_strip]
    path = tmp_path / "strips.ply"
    path.write_bytes(_grid_strips_ply(rows, cols, rows_of_element))
    data = read_mesh(path)
    # The grid's quads, each cut along its diagonal from (r, c + 1) to (r + 1, c): the strip's triangles.
    quads = [(v(r, c), v(r + 1, c), v(r, c + 1), v(r + 1, c + 1)) for r in range(rows - 1) for c in range(cols - 1)]
    expected = {frozenset(t) for a, b, c, d in quads for t in ((a, b, c), (c, b, d))}
    assert len(data.triangles) == len(expected) == 2 * (rows - 1) * (cols - 1)
    assert {frozenset(t) for t in data.triangles.tolist()} == expected
    p = data.vertices[data.triangles]
    turn = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])[:, 2]
    assert np.all(turn < 0) or np.all(turn > 0)  # every triangle faces one way


def test_ply_strip_indices_other_than_the_restart_are_refused(tmp_path):
    path = tmp_path / "bad_strip.ply"
    path.write_bytes(_grid_strips_ply(2, 3, [[0, 3, 1, -2, 2, 5]]))
    with pytest.raises(io.TopStocError, match="vertex index -2 is out of range"):
        read_mesh(path)


def test_ascii_ply_with_uvs_and_alpha(tmp_path):
    text = """ply
format ascii 1.0
comment made by hand
element vertex 4
property float x
property float y
property float z
property uchar red
property uchar green
property uchar blue
property uchar alpha
property float s
property float t
element edge 1
property int vertex1
property int vertex2
element face 2
property list uchar int vertex_indices
end_header
0 0 0 255 0 0 255 0.0 0.0
1 0 0 0 255 0 128 1.0 0.0
1 1 0 0 0 255 0 1.0 1.0
0 1 0 10 20 30 40 0.0 1.0
0 1
3 0 1 2
3 0 2 3
"""
    (tmp_path / "uv.ply").write_text(text)
    data = read_mesh(tmp_path / "uv.ply")
    assert data.vertex_colors.shape == (4, 4)
    np.testing.assert_array_equal(data.vertex_colors[1], np.array([0, 255, 0, 128]) / 255)
    np.testing.assert_array_equal(data.corner_uvs[1], [[0, 0], [1, 1], [0, 1]])


def test_obj_statements(tmp_path):
    text = """# negative indices, v//vn, quads, a line, continuation, colours
mtllib a.mtl b.mtl
v 0 0 0 1 0 0
v 1 0 0 0 1 0
v 1 1 0 0 0 1
v 0 1 0 0.5 0.5 0.5
vt 0 0
vt 1 0
vt 1 1
vn 0 0 1
g group
usemtl first
f -4/-3 -3/-2 -2/-1
usemtl second material
f 1//1 3//1 \\
  4//1
l 1 2
f 1 2
usemtl first
f 2 3 4 1
"""
    (tmp_path / "s.obj").write_text(text)
    line = text.splitlines().index("f 1 2") + 1
    with pytest.warns(io.MeshFileWarning) as caught:
        data = read_mesh(tmp_path / "s.obj")
    assert [str(w.message) for w in caught] == [
        f"{tmp_path / 's.obj'}: skipped 1 face with fewer than 3 corners (the first at line {line})"]
    np.testing.assert_array_equal(data.triangles, [[0, 1, 2], [0, 2, 3], [1, 2, 3], [1, 3, 0]])
    np.testing.assert_array_equal(data.triangle_polygon, [0, 1, 3, 3])  # the 2-corner face is index 2
    assert data.skipped_faces == 1
    assert data.material_names == ["first", "second material"]
    np.testing.assert_array_equal(data.triangle_material, [0, 1, 0, 0])
    assert data.material_libraries == ["a.mtl b.mtl"]
    np.testing.assert_array_equal(data.corner_uvs[0], [[0, 0], [1, 0], [1, 1]])
    assert np.isnan(data.corner_uvs[1:]).all()
    np.testing.assert_array_equal(data.vertex_colors[3], [0.5, 0.5, 0.5])


def test_off_variants(tmp_path):
    (tmp_path / "c.off").write_text("# comment\nCOFF 4 2 0\n0 0 0 255 0 0\n1 0 0 0 255 0 128\n"
                                    "1 1 0 0 0 255\n0 1 0 1 2 3\n4 0 1 2 3 1 1 1\n3 0 2 1\n")
    with pytest.raises(ValueError, match="line 4: vertex has 4 colour values"):
        read_mesh(tmp_path / "c.off")
    (tmp_path / "d.off").write_text("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n")
    np.testing.assert_array_equal(read_mesh(tmp_path / "d.off").vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    (tmp_path / "e.off").write_text("COFF\n3 1 0\n0 0 0 0.5 0.25 1\n1 0 0 1 0 0\n0 1 0 0 1 0\n3 0 1 2\n")
    np.testing.assert_array_equal(read_mesh(tmp_path / "e.off").vertex_colors[0], [0.5, 0.25, 1])  # decimals


def test_stl_welding_ascii_and_binary_agree(tmp_path):
    facets = [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((-0.0, 0, 0), (0, 1, 0), (0, 0, 0)),  # -0.0 == 0.0, degenerate
              ((1, 0, 0), (1, 1, 0), (0, 1, 0))]
    ascii_text = "solid t\n" + "".join(
        "facet normal 0 0 1\nouter loop\n" + "".join(f"vertex {x!r} {y!r} {z!r}\n" for x, y, z in f)
        + "endloop\nendfacet\n" for f in facets) + "endsolid t\n"
    (tmp_path / "a.stl").write_text(ascii_text)
    binary = b"solid but binary".ljust(80) + struct.pack("<I", len(facets))
    for f in facets:
        binary += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *v) for v in f) + b"\0\0"
    (tmp_path / "b.stl").write_bytes(binary)
    for name in ("a.stl", "b.stl"):
        data = read_mesh(tmp_path / name)
        np.testing.assert_array_equal(data.vertices, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
        np.testing.assert_array_equal(data.triangles, [[0, 1, 2], [0, 2, 0], [1, 3, 2]])  # degenerate kept


# --- errors ----------------------------------------------------------------------------------

def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing.obj"):
        read_mesh(tmp_path / "nothing.obj")


def test_unknown_extension(tmp_path):
    (tmp_path / "mesh.xyz").write_text("1 2 3\n")
    with pytest.raises(ValueError, match=r"mesh\.xyz: unknown mesh file extension"):
        read_mesh(tmp_path / "mesh.xyz")
    with pytest.raises(ValueError, match="unknown mesh file extension"):
        write_mesh(tmp_path / "mesh.fbx", attributed_mesh())


@pytest.mark.parametrize("name", ["empty.ply", "empty.off", "empty.obj", "empty.stl", "empty.obj.gz"])
@pytest.mark.parametrize("content", [b"", b"\n \r\n"])
def test_empty_files_are_errors_in_every_format(tmp_path, name, content):
    (tmp_path / name).write_bytes(gzip.compress(content) if name.endswith(".gz") else content)
    with pytest.raises(ValueError, match=re.escape(name) + ": the mesh has no triangles: the file is empty"):
        read_mesh(tmp_path / name)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be", "utf-16-le"])
@pytest.mark.parametrize("name", ["box.obj", "box.off", "box.obj.gz"])
def test_utf16_text_is_named_not_read_as_an_empty_mesh(tmp_path, name, encoding):
    # A byte-order mark, then text whose every other byte is zero: the readers saw no line.
    text = ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" if ".off" in name
            else "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    data = ("\ufeff" + text).encode(encoding) if encoding != "utf-16" else text.encode(encoding)
    (tmp_path / name).write_bytes(gzip.compress(data) if name.endswith(".gz") else data)
    with pytest.raises(ValueError, match=re.escape(f"{name}: the file is UTF-16 text")):
        read_mesh(tmp_path / name)


@pytest.mark.parametrize("name, content, held", [
    ("v.obj", "v 0 0 0\nv 1 0 0\n", "2 vertices, no faces"),
    ("l.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "2 vertices, 1 faces with fewer than 3 corners"),
    ("v.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n0 0 0\n", "1 vertex, no faces"),
    ("v.off", "OFF\n1 0 0\n0 0 0\n", "1 vertex, no faces"),
    ("s.stl", "solid s\nendsolid s\n", "0 vertices, no faces"),
])
def test_files_without_triangles_are_errors_unless_allowed(tmp_path, name, content, held):
    (tmp_path / name).write_text(content)
    with pytest.raises(ValueError, match=re.escape(f"{name}: the mesh has no triangles (the file holds {held})")):
        read_mesh(tmp_path / name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # l.obj's skipped line
        assert read_mesh(tmp_path / name, allow_empty=True).num_triangles == 0


def test_unparseable_stl_names_file_and_line():
    path = DATA / "nonmanifold_degenerate" / "openscad_unparseable.stl"
    with pytest.raises(ValueError, match=r"openscad_unparseable\.stl: line 4: vertex coordinate '\\x10' is not a number"):
        read_mesh(path)


XYZ_HEADER = ("ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n")


@pytest.mark.parametrize("name,content,message", [
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", r"line 4: face refers to vertex 4, but the file has 3"),
    ("b.obj", "v 0 0 0\nf 1 -2 1\n", r"line 2: vertex index -2 points before the first vertex"),
    ("c.obj", "v 0 0 0\nf 0 1 1\n", r"line 2: bad vertex index '0'"),
    ("d.obj", "v 0 0 zero\n", r"line 1: vertex coordinate 'zero' is not a number"),
    ("e.obj", "v 0 0 0\nvt 0 0\nf 1/2 1/1 1/1\n", r"line 3: face refers to texture coordinate 2"),
    ("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", r"line 6: face 0 refers to vertex 3, but the file has 3"),
    ("g.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", r"the file ends after 2 of 3 vertices"),
    ("h.off", "PLY\n", r"line 1: not an OFF file: the header is 'PLY'"),
    ("i.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 1\n",
     r"face 0 refers to vertex 1, but the file has 1 vertices"),
    ("j.ply", XYZ_HEADER.format(2) + "0 0 0\n0 0\n",
     r"line 10, element 'vertex' row 1: the file ends in the middle of the data"),
    ("k.ply", XYZ_HEADER.format(1) + "0 1,5 0\n",
     r"line 8, element 'vertex' row 0: expected a number, got '1,5'"),
    ("q.ply", XYZ_HEADER.format(10 ** 12) + "0 0 0\n", r"element 'vertex' announces 1000000000000 rows, more than"),
    ("r.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
     r"the vertex element has no x, y and z properties"),
    ("s.off", "OFF\n999999999 1 0\n0 0 0\n", r"the file ends after 1 of 999999999 vertices"),
    ("l.ply", "solid\n", r"not a PLY file"),
    ("m.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", r"line 2: unknown PLY format"),
    ("n.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n",
     r"line 4: unknown property type 'float128'"),
    ("o.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n", r"line 4: the file ends inside a facet"),
    ("p.stl", "not an stl", r"not an STL file"),
])
def test_bad_content_names_file_and_problem(tmp_path, name, content, message):
    (tmp_path / name).write_text(content)
    with pytest.raises(ValueError, match=re.escape(name) + ": " + message):
        read_mesh(tmp_path / name)


def test_truncated_binary_files(tmp_path):
    ply = _ply_bytes("little", [("float", "x"), ("float", "y"), ("float", "z")], [(0, 0, 0)] * 3,
                     "uchar", "int", [[0, 1, 2]] * 4)
    (tmp_path / "t.ply").write_bytes(ply[:-6])
    with pytest.raises(ValueError, match=r"t\.ply: byte 249, element 'face' row 3: the file ends in the middle of the data"):
        read_mesh(tmp_path / "t.ply")
    stl = b"binary".ljust(80) + struct.pack("<I", 10) + b"\0" * 50 * 9
    (tmp_path / "t.stl").write_bytes(stl)
    with pytest.raises(ValueError, match=r"t\.stl: binary STL: the header says 10 triangles \(byte 80\), but the file "
                                         r"ends at byte 534, inside triangle 9 \(50 bytes missing\)"):
        read_mesh(tmp_path / "t.stl")


def test_corrupt_compression(tmp_path):
    (tmp_path / "x.obj.gz").write_bytes(b"\x1f\x8b not really gzip")
    with pytest.raises(ValueError, match=r"x\.obj\.gz: cannot decompress"):
        read_mesh(tmp_path / "x.obj.gz")
    (tmp_path / "y.off.bz2").write_bytes(bz2.compress(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"))
    assert read_mesh(tmp_path / "y.off.bz2").num_triangles == 1


def test_dropped_attributes_follow_what_formats_carry():
    mesh = attributed_mesh()
    assert io.dropped_attributes(mesh, "a.obj.gz") == []
    assert io.dropped_attributes(mesh, "a.ply") == ["triangle_material"]
    assert io.dropped_attributes(mesh, "a.off") == ["corner_uvs", "triangle_material"]
    assert io.dropped_attributes(mesh, "a.stl") == ["corner_uvs", "vertex_colors", "triangle_material"]


def test_unwritable_destination_names_the_file(tmp_path):
    with pytest.raises(OSError, match=r"out\.obj: cannot write the file"):
        write_mesh(tmp_path / "no" / "such" / "out.obj", attributed_mesh())


def test_writing_bad_data_is_refused_and_leaves_no_file(tmp_path):
    bad = MeshData(vertices=np.zeros((3, 3)), triangles=[[0, 1, 3]])
    with pytest.raises(ValueError, match=r"bad\.obj: triangle 0 refers to vertex 3, outside \[0, 3\)"):
        write_mesh(tmp_path / "bad.obj", bad)
    assert not list(tmp_path.iterdir())
    with pytest.raises(ValueError, match="material 2"):
        write_mesh(tmp_path / "m.obj", MeshData(vertices=np.zeros((3, 3)), triangles=[[0, 1, 2]],
                                                triangle_material=[2], material_names=["a"]))


# --- the big mesh (only with ../shared/meshes) -----------------------------------------------

def test_big_binary_ply(shared_meshes):
    path = shared_meshes / "big" / "horse_loop2_1.55M.ply"
    if not path.exists():
        pytest.skip("horse_loop2_1.55M.ply is not available")
    data = read_mesh(path)
    raw = path.read_bytes()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    vertices = np.frombuffer(raw, "<f4", 3 * 775730, end).reshape(-1, 3)
    faces = np.frombuffer(raw, np.dtype([("n", "u1"), ("v", "<i4", 3)]), 1551456, end + vertices.nbytes)
    assert (faces["n"] == 3).all()
    np.testing.assert_array_equal(data.vertices, vertices)
    np.testing.assert_array_equal(data.triangles, faces["v"])
