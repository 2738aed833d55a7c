"""Bad and sloppy mesh files, names that do not read back, compressed bombs, and what every
write must give back (issue 17, I/O half). Inputs that once crashed are in
tests/data/regressions (README there) and tests/fuzz/regressions (found by tests/fuzz)."""

import bz2
import gzip
import pathlib
import warnings

import numpy as np
import pytest

import topstoc
from topstoc.core.api import io
from topstoc.core.api.io import MeshData, MeshFileWarning, read_mesh, write_mesh

REGRESSIONS = pathlib.Path(__file__).resolve().parents[1] / "data" / "regressions"
FUZZ_REGRESSIONS = pathlib.Path(__file__).resolve().parents[1] / "fuzz" / "regressions"
FUZZ_SEEDS = pathlib.Path(__file__).resolve().parents[1] / "fuzz" / "seeds"


def read_quietly(path, **options):
    """read_mesh, returning (data, [warning messages])."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = read_mesh(path, **options)
    return data, [str(w.message) for w in caught if issubclass(w.category, MeshFileWarning)]


# --- PLY layouts -------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["ply_two_vertex_elements_uv_oob.ply", "ply_two_vertex_elements_colors_mismatch.ply"])
def test_two_vertex_elements_are_refused_by_name(name):
    with pytest.raises(ValueError, match=r"line \d+: a second 'vertex' element"):
        read_mesh(REGRESSIONS / name)


def test_a_large_second_vertex_block_is_refused_before_reading(tmp_path):
    # The reproducer's crash: 4,000,000 rows in the second block (the header alone decides).
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
              "property float z\nproperty float u\nproperty float v\nelement vertex 4000000\nproperty float x\n"
              "property float y\nproperty float z\nend_header\n")
    path = tmp_path / "big.ply"
    path.write_bytes(header.encode() + bytes(20 + 12 * 1000))
    with pytest.raises(ValueError, match="a second 'vertex' element"):
        read_mesh(path)


def test_two_face_elements_and_repeated_properties_are_refused(tmp_path):
    base = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    (tmp_path / "faces.ply").write_text(base + "element face 1\nproperty list uchar int vertex_indices\n"
                                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n")
    with pytest.raises(ValueError, match="a second 'face' element"):
        read_mesh(tmp_path / "faces.ply")
    (tmp_path / "lists.ply").write_text(base + "element face 1\nproperty list uchar int vertex_indices\n"
                                        "property list uchar int vertex_index\nend_header\n"
                                        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2 3 0 2 1\n")
    with pytest.raises(ValueError, match="two vertex index lists"):
        read_mesh(tmp_path / "lists.ply")
    (tmp_path / "twice.ply").write_text(base + "property float x\nend_header\n")
    with pytest.raises(ValueError, match="property 'x' declared twice in element 'vertex'"):
        read_mesh(tmp_path / "twice.ply")


def test_old_blender_header_line_is_skipped_with_a_warning(tmp_path):
    # Blender 2.4x's PLY exporter wrote this line without "comment" in front.
    text = ("ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: 'cube.blend'\n"
            "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0.5\n0 1 0\n4 0 1 2 3\n")
    (tmp_path / "old.ply").write_text(text)
    data, messages = read_quietly(tmp_path / "old.ply")
    np.testing.assert_array_equal(data.vertices, [[0, 0, 0], [1, 0, 0], [1, 1, 0.5], [0, 1, 0]])
    np.testing.assert_array_equal(data.triangles, [[0, 1, 2], [0, 2, 3]])
    assert len(messages) == 1 and "line 3: skipped unknown PLY header line 'Created by Blender3D 247" in messages[0]


def test_a_clean_file_gives_no_warning(tmp_path):
    data = MeshData(vertices=np.eye(3), triangles=[[0, 1, 2]])
    for suffix in (".obj", ".ply", ".off", ".stl"):
        write_mesh(tmp_path / f"m{suffix}", data)
        assert read_quietly(tmp_path / f"m{suffix}")[1] == []


# --- names and encodings -----------------------------------------------------------------------

def test_latin1_obj_from_2001_reads(tmp_path):
    raw = (b"# Fichier cr\xe9\xe9 par Mod\xe8leur 3.1 (2001), \xa9 Soci\xe9t\xe9\n"
           b"mtllib biblioth\xe8que.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl mat\xe9riau\nf 1 2 3\n")
    (tmp_path / "old.obj").write_bytes(raw)
    data, messages = read_quietly(tmp_path / "old.obj")
    assert data.material_names == [b"mat\xe9riau".decode("latin-1")] == ["matériau"]
    assert data.material_libraries == ["bibliothèque.mtl"]
    assert len(messages) == 2 and all("read as Latin-1" in m for m in messages)
    np.testing.assert_array_equal(data.triangle_material, [0])


def test_utf8_names_read_without_warning(tmp_path):
    (tmp_path / "u.obj").write_bytes("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl 材料 α\nf 1 2 3\n".encode())
    data, messages = read_quietly(tmp_path / "u.obj")
    assert data.material_names == ["材料 α"] and messages == []


def triangle_data(**extra):
    return MeshData(vertices=np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]], dtype=float),
                    triangles=[[0, 1, 2], [1, 3, 2]], **extra)


@pytest.mark.parametrize("name, problem", [
    ("a\\", "ends with a backslash"), ("\\", "ends with a backslash"), ("two\nlines", "line break"),
    ("Material #2", "'#'"), (" lead", "white space"), ("trail ", "white space"), ("tab\t", "white space"),
    ("", "empty"), ("(null)", "no material"),
])
def test_obj_writer_refuses_material_names_that_would_not_read_back(tmp_path, name, problem):
    data = triangle_data(triangle_material=[0, 0], material_names=[name])
    with pytest.raises(ValueError, match=f"material name .* cannot be written to OBJ: .*{problem}"):
        write_mesh(tmp_path / "m.obj", data)
    assert not (tmp_path / "m.obj").exists()


@pytest.mark.parametrize("name", ["lib\\", "x.mtl #", " x.mtl", ""])
def test_obj_writer_refuses_library_names_that_would_not_read_back(tmp_path, name):
    with pytest.raises(ValueError, match="material library name .* cannot be written to OBJ"):
        write_mesh(tmp_path / "m.obj", triangle_data(material_libraries=[name]))


def test_reproducer_with_trailing_backslash_is_refused_not_corrupted(tmp_path):
    data = read_mesh(REGRESSIONS / "obj_roundtrip_min.obj", allow_empty=True)
    assert data.material_libraries == ["\\"]
    with pytest.raises(ValueError, match="ends with a backslash"):
        write_mesh(tmp_path / "copy.obj", data)


# --- numbers a format cannot carry ----------------------------------------------------------------

def test_stl_writer_refuses_coordinates_past_float32(tmp_path):
    # binary STL is float32: 1e39 was written as inf
    data = triangle_data()
    data.vertices[3] = [1.0, 1e39, 0.5]
    with pytest.raises(ValueError, match=r"s.stl: vertex 3 cannot be written to binary STL: coordinate 1e\+39 is "
                                         r"beyond float32's range \(\+-3.40282e\+38\); scale the mesh, or write PLY"):
        write_mesh(tmp_path / "s.stl", data)
    assert not (tmp_path / "s.stl").exists()
    for suffix in (".ply", ".obj", ".off"):  # doubles: written and read back exactly
        write_mesh(tmp_path / f"s{suffix}", data)
        np.testing.assert_array_equal(read_mesh(tmp_path / f"s{suffix}").vertices, data.vertices)


def test_stl_keeps_the_largest_float32_and_rounds_below_its_precision(tmp_path):
    data = triangle_data()
    big = float(np.finfo(np.float32).max)
    data.vertices[1] = [big, -big, 1e-50]
    write_mesh(tmp_path / "s.stl", data)
    back = read_mesh(tmp_path / "s.stl")
    corner = back.vertices[back.triangles[0, 1]]
    assert corner.tolist() == [big, -big, 0.0]  # 1e-50 is below float32's smallest step: 0


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off", ".stl"])
def test_writers_refuse_non_finite_positions_by_vertex(tmp_path, suffix):
    for bad in (np.nan, np.inf, -np.inf):
        data = triangle_data()
        data.vertices[2, 1] = bad
        with pytest.raises(ValueError, match=f"vertex 2 cannot be written: coordinate {bad} is not finite"):
            write_mesh(tmp_path / f"n{suffix}", data)
        assert not (tmp_path / f"n{suffix}").exists()


def test_writers_refuse_non_finite_colours_and_infinite_uvs_where_the_format_carries_them(tmp_path):
    colours = np.full((4, 3), 0.5)
    colours[1, 2] = np.nan
    for suffix in (".obj", ".ply", ".off"):
        with pytest.raises(ValueError, match="vertex 1 cannot be written: colour nan is not finite"):
            write_mesh(tmp_path / f"c{suffix}", triangle_data(vertex_colors=colours))
    write_mesh(tmp_path / "c.stl", triangle_data(vertex_colors=colours))  # STL drops colours
    uvs = np.full((2, 3, 2), np.nan)  # NaN: corners without a UV (allowed)
    uvs[0] = [[0, 0], [1, 0], [0, 1]]
    write_mesh(tmp_path / "u.obj", triangle_data(corner_uvs=uvs))
    uvs[1, 2, 0] = np.inf
    for suffix in (".obj", ".ply"):
        with pytest.raises(ValueError, match=r"triangle 1 corner 2 cannot be written: UV inf is infinite "
                                             r"\(NaN marks a corner without a UV\)"):
            write_mesh(tmp_path / f"u{suffix}", triangle_data(corner_uvs=uvs))
    write_mesh(tmp_path / "u.off", triangle_data(corner_uvs=uvs))  # OFF drops UVs


def test_write_errors_are_topstoc_errors(tmp_path):
    import topstoc
    data = triangle_data()
    data.vertices[0, 0] = np.inf
    with pytest.raises(topstoc.TopStocError, match="vertex 0 cannot be written"):
        write_mesh(tmp_path / "e.ply", data)


def test_a_file_with_nan_reads_but_is_not_written_on(tmp_path):
    (tmp_path / "nan.obj").write_text("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    data = read_mesh(tmp_path / "nan.obj")  # read as it is (topstoc.Mesh refuses it by vertex)
    assert np.isnan(data.vertices[0, 2])
    with pytest.raises(ValueError, match="vertex 0 cannot be written: coordinate nan is not finite"):
        write_mesh(tmp_path / "copy.ply", data)


@pytest.mark.parametrize("name", ["with spaces inside", "a\rb", "unicodé 材料", "back\\slash inside", "(nul)",
                                  "semi;colon/slash", "x" * 300])
def test_names_that_can_be_written_read_back_exactly(tmp_path, name):
    data = triangle_data(triangle_material=[0, -1], material_names=[name], material_libraries=[name + ".mtl"])
    write_mesh(tmp_path / "m.obj", data)
    back, messages = read_quietly(tmp_path / "m.obj")
    assert back.material_names == [name] and back.material_libraries == [name + ".mtl"] and messages == []
    np.testing.assert_array_equal(back.triangle_material, [0, -1])


# --- every write round-trips --------------------------------------------------------------------

def random_mesh(rng, with_colors, with_uvs, with_materials, channels=3):
    """Polygons of 3 to 6 corners over n vertices, fan-triangulated as the readers do, with
    some corners without UV (NaN) and some faces without material."""
    n = int(rng.integers(4, 40))
    vertices = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 4)
    triangles, polygon, uvs, material = [], [], [], []
    names = ["skin", "metal plate", "glass"]
    for face in range(int(rng.integers(1, 30))):
        corners = rng.choice(n, size=int(rng.integers(3, 7)), replace=False)
        corner_uv = rng.random((len(corners), 2))
        corner_uv[rng.random(len(corners)) < 0.2] = np.nan
        mat = int(rng.integers(-1, len(names)))
        for i in range(1, len(corners) - 1):
            triangles.append([corners[0], corners[i], corners[i + 1]])
            uvs.append([corner_uv[0], corner_uv[i], corner_uv[i + 1]])
            polygon.append(face)
            material.append(mat)
    return MeshData(vertices=vertices, triangles=triangles, triangle_polygon=polygon,
                    corner_uvs=np.array(uvs) if with_uvs else None,
                    vertex_colors=rng.integers(0, 256, size=(n, channels)) / 255.0 if with_colors else None,
                    triangle_material=material if with_materials else None,
                    material_names=names if with_materials else [])


def assert_same_polygons(a, b):
    starts = lambda p: np.r_[True, np.diff(p) != 0]  # noqa: E731
    np.testing.assert_array_equal(starts(a.triangle_polygon), starts(b.triangle_polygon))


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("suffix", [".obj", ".ply", ".off", ".stl", ".obj.gz", ".ply.bz2"])
def test_every_write_round_trips(tmp_path, seed, suffix):
    rng = np.random.default_rng(seed)
    data = random_mesh(rng, with_colors=seed % 2 == 0, with_uvs=seed % 3 != 0, with_materials=seed % 4 != 1,
                       channels=3 + seed % 2)
    path = tmp_path / f"mesh{suffix}"
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshFileWarning)
        write_mesh(path, data)
        back = read_mesh(path)
    kind, _ = io.mesh_format(path)
    if kind == "stl":  # a float32 triangle soup: compare corner positions
        np.testing.assert_array_equal(back.vertices[back.triangles], data.vertices[data.triangles].astype(np.float32))
        return
    np.testing.assert_array_equal(back.vertices, data.vertices)
    np.testing.assert_array_equal(back.triangles, data.triangles)
    assert_same_polygons(data, back)
    if "vertex_colors" in io.CARRIES[kind] and data.vertex_colors is not None:
        np.testing.assert_array_equal(back.vertex_colors, data.vertex_colors)
    if "corner_uvs" in io.CARRIES[kind] and data.corner_uvs is not None:
        np.testing.assert_array_equal(back.corner_uvs, data.corner_uvs)  # NaN where a corner had none
    if "triangle_material" in io.CARRIES[kind] and data.triangle_material is not None:
        names = lambda d: [d.material_names[i] if i >= 0 else None for i in d.triangle_material]  # noqa: E731
        assert names(back) == names(data)


def test_fuzz_seeds_and_found_inputs_read_or_fail_cleanly_and_round_trip(tmp_path):
    """Every kept fuzz input (tests/fuzz) through the Python API: read or a ValueError; what
    reads writes back (or is refused: an OBJ name, a number no file should carry) and reads
    back the same."""
    files = sorted(p for folder in (FUZZ_SEEDS, FUZZ_REGRESSIONS) if folder.exists()
                   for p in folder.rglob("*") if p.is_file())
    assert len(files) >= 15
    kinds = {"obj": "obj", "ply": "ply", "off": "off", "stl": "stl"}
    for path in files:
        kind = kinds.get(path.parent.name)
        if kind is None:
            continue
        copy = tmp_path / f"input.{kind}"
        copy.write_bytes(path.read_bytes())
        try:
            data, _ = read_quietly(copy)
        except ValueError:
            continue
        out = tmp_path / f"output.{kind}"
        try:
            write_mesh(out, data)
        except ValueError as error:
            names = kind == "obj" and "cannot be written to OBJ" in str(error)
            unwritable = (not np.isfinite(data.vertices).all()  # a reader hands "nan" through
                          or (data.vertex_colors is not None and not np.isfinite(data.vertex_colors).all())
                          or (data.corner_uvs is not None and np.isinf(data.corner_uvs).any()))
            numbers = "cannot be written: " in str(error) and unwritable
            assert names or numbers, (path, error)
            continue
        back, messages = read_quietly(out)
        assert messages == [], path
        if kind != "stl":
            np.testing.assert_array_equal(back.triangles, data.triangles, err_msg=str(path))


def test_round_trip_fuzz_inputs_cross_formats(tmp_path):
    """tests/fuzz's round_trip inputs (first byte: the reader) through the Python API: what reads
    is written in each other format and reads back with the same counts and, where both formats
    hold them, the same positions (float32 in STL), colours and UVs."""
    files = sorted(p for folder in (FUZZ_SEEDS / "round_trip", FUZZ_REGRESSIONS / "round_trip")
                   if folder.exists() for p in folder.iterdir() if p.is_file())
    assert len(files) >= 19
    kinds = ("obj", "ply", "off", "stl")
    checked = 0
    for path in files:
        raw = path.read_bytes()
        source = kinds[raw[0] % 4]
        (tmp_path / f"in.{source}").write_bytes(raw[1:])
        try:
            data, _ = read_quietly(tmp_path / f"in.{source}")
        except ValueError:
            continue
        for kind in kinds:
            if kind == source:
                continue
            out = tmp_path / f"out.{kind}"
            try:
                write_mesh(out, data)
            except ValueError as error:
                assert "cannot be written" in str(error), (path, kind, error)
                continue
            back, messages = read_quietly(out)
            assert messages == [], (path, kind)
            assert len(back.triangles) == len(data.triangles), (path, kind)
            if kind == "stl":
                np.testing.assert_array_equal(back.vertices[back.triangles].astype(np.float32),
                                              data.vertices[data.triangles].astype(np.float32), err_msg=str(path))
                continue
            np.testing.assert_array_equal(back.vertices, data.vertices, err_msg=f"{path} -> {kind}")
            np.testing.assert_array_equal(back.triangles, data.triangles, err_msg=f"{path} -> {kind}")
            if data.vertex_colors is not None and len(data.vertices):
                np.testing.assert_array_equal(back.vertex_colors, data.vertex_colors, err_msg=f"{path} -> {kind}")
            if kind in ("obj", "ply") and data.corner_uvs is not None and not np.isnan(data.corner_uvs).all():
                np.testing.assert_array_equal(back.corner_uvs, data.corner_uvs, err_msg=f"{path} -> {kind}")
            checked += 1
    assert checked >= 29  # crash-1b6e44df has 60 bytes after its rows: refused since issue 37


# --- compressed input ---------------------------------------------------------------------------

def bomb(size):
    """An OBJ of `size` bytes that compresses to almost nothing (one comment line)."""
    return b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n#" + b" " * size + b"\n"


@pytest.mark.parametrize("suffix, compress", [(".obj.gz", gzip.compress), (".obj.bz2", bz2.compress)])
def test_decompressed_size_is_capped(tmp_path, suffix, compress):
    path = tmp_path / f"bomb{suffix}"
    path.write_bytes(compress(bomb(20_000_000)))
    assert path.stat().st_size < 100_000
    with pytest.raises(ValueError, match=r"decompresses to more than 1000000 bytes \(the limit, max_decompressed_bytes"):
        read_mesh(path, max_decompressed_bytes=1_000_000)
    assert read_mesh(path, max_decompressed_bytes=None).num_triangles == 1
    assert read_mesh(path).num_triangles == 1  # the default (2 GiB) lets it through
    assert io.MAX_DECOMPRESSED_BYTES == 2 << 30


def test_cap_is_exact_and_checked(tmp_path):
    raw = bomb(10_000)
    path = tmp_path / "m.obj.gz"
    path.write_bytes(gzip.compress(raw))
    assert read_mesh(path, max_decompressed_bytes=len(raw)).num_triangles == 1
    with pytest.raises(ValueError, match="more than"):
        read_mesh(path, max_decompressed_bytes=len(raw) - 1)
    for bad in (-1, 1.5, True, "10"):
        with pytest.raises(ValueError, match="max_decompressed_bytes"):
            read_mesh(path, max_decompressed_bytes=bad)


def test_concatenated_truncated_and_corrupt_gzip(tmp_path):
    raw = bomb(100)
    half = raw.index(b"f ")
    path = tmp_path / "m.obj.gz"
    path.write_bytes(gzip.compress(raw[:half]) + gzip.compress(raw[half:]))  # two members, as gzip(1) reads
    assert read_mesh(path).num_triangles == 1
    whole = gzip.compress(raw)
    path.write_bytes(whole[:-12])
    with pytest.raises(ValueError, match="cannot decompress"):
        read_mesh(path)
    path.write_bytes(whole[:10] + b"\xff" * 8 + whole[18:])
    with pytest.raises(ValueError, match="cannot decompress"):
        read_mesh(path)


# --- self_intersections on a triangle with a repeated index -------------------------------------

def test_self_intersections_with_a_repeated_index():
    d = np.load(REGRESSIONS / "self_intersections_oob.npz")
    vertices, triangles = d["vertices"], d["triangles"]
    repeated = [t for t, tri in enumerate(triangles) if len(set(tri)) < 3]
    assert repeated
    pairs = topstoc.self_intersections(vertices, triangles)
    # Reported as zero-area, paired with nothing else.
    for t in repeated:
        assert [t, t] in pairs.tolist()
        assert not any((a == t) != (b == t) for a, b in pairs)
    # The other pairs are those of the mesh without the repeated triangles (ids mapped back).
    keep = [t for t in range(len(triangles)) if t not in repeated]
    rest = topstoc.self_intersections(vertices, triangles[keep])
    expected = sorted([[keep[a], keep[b]] for a, b in rest] + [[t, t] for t in repeated])
    assert sorted(pairs.tolist()) == expected


def test_self_intersections_repeated_index_against_a_crossing_triangle():
    # (0, 1, 0) is a segment through triangle 1; a triangle (0, 2, 3) with distinct ids that
    # pokes through triangle 1 is still found.
    v = np.array([[0, 0, -1], [0, 0, 1], [-1, -1, 0], [1, -1, 0], [0, 1, 0], [0.2, 0.2, 1]], dtype=float)
    t = np.array([[0, 1, 0], [2, 3, 4], [0, 5, 1]])
    pairs = topstoc.self_intersections(v, t).tolist()
    assert [0, 0] in pairs and [1, 2] in pairs and [0, 1] not in pairs
