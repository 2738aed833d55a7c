"""Readers take the data a file holds exactly as its counts say, and the file ends where its format
says (issue 37, "data dropped without a word"): a count smaller or larger than the data, trailing
data and files cut short are errors naming the line or byte; faces with fewer than 3 corners are
skipped with a MeshFileWarning, which the CLI prints as one line. Each case in plain, .gz and .bz2
form; what real files contain (CRLF, comments, names, extra PLY elements) still reads."""

import bz2
import gzip
import pathlib
import re
import struct
import warnings

import numpy as np
import pytest

import cli
from topstoc.core.api.io import MeshFileWarning, encode_mesh, read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
ELEPHANT = DATA / "genus_positive" / "cgal_elephant.off"  # 2,775 vertices, 5,558 triangles
FORMS = ["", ".gz", ".bz2"]


def write(tmp_path, name, raw: bytes, form="") -> pathlib.Path:
    path = tmp_path / (name + form)
    path.write_bytes(gzip.compress(raw) if form == ".gz" else bz2.compress(raw) if form == ".bz2" else raw)
    return path


def refused(path, pattern):
    """read_mesh refuses `path` with one line: the path, then a message matching `pattern`."""
    with pytest.raises(ValueError) as caught:
        read_mesh(path)
    message = str(caught.value)
    assert "\n" not in message
    assert re.fullmatch(re.escape(str(path)) + ": " + pattern, message), message


def read_quietly(path):
    """(data, MeshFileWarning messages)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = read_mesh(path)
    return data, [str(w.message) for w in caught if issubclass(w.category, MeshFileWarning)]


@pytest.fixture(scope="module")
def elephant():
    return read_mesh(ELEPHANT)


# --- binary STL ----------------------------------------------------------------------------------

def stl_with_count(raw: bytes, count: int, header: bytes = b"") -> bytes:
    return (header or raw[:80]).ljust(80, b" ")[:80] + struct.pack("<I", count) + raw[84:]


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("count", [5558 // 2, 0, 1])
def test_binary_stl_with_a_count_below_its_triangles_is_refused(tmp_path, elephant, form, count):
    raw = encode_mesh(elephant, "stl")
    assert len(raw) == 84 + 50 * 5558
    path = write(tmp_path, "x.stl", stl_with_count(raw, count), form)
    end = 84 + 50 * count
    refused(path, re.escape(f"binary STL: the header says {count} triangles (byte 80), the file holds 5558 "
                            f"({len(raw) - end} more bytes from byte {end})"))


@pytest.mark.parametrize("form", FORMS)
def test_binary_stl_with_bytes_after_its_triangles_or_cut_short_is_refused(tmp_path, elephant, form):
    raw = encode_mesh(elephant, "stl")
    refused(write(tmp_path, "t.stl", raw + b"\0" * 7, form),
            re.escape(f"binary STL: the header says 5558 triangles (byte 80), but the file goes on for 7 bytes "
                      f"after them (byte {len(raw)})"))
    refused(write(tmp_path, "c.stl", raw[:-20], form),
            re.escape(f"binary STL: the header says 5558 triangles (byte 80), but the file ends at byte "
                      f"{len(raw) - 20}, inside triangle 5557 (20 bytes missing)"))


def test_binary_stl_whose_header_starts_with_solid(tmp_path, elephant):
    raw = encode_mesh(elephant, "stl")
    header = b"solid exported by a CAD tool"
    # The right count: binary, whatever the header says.
    data = read_mesh(write(tmp_path, "ok.stl", stl_with_count(raw, 5558, header)))
    assert data.num_triangles == 5558
    np.testing.assert_array_equal(data.vertices[data.triangles],
                                  elephant.vertices[elephant.triangles].astype(np.float32))
    # A wrong count: a binary error (the NUL bytes), not an ascii parse error.
    refused(write(tmp_path, "half.stl", stl_with_count(raw, 2779, header)),
            r"binary STL: the header says 2779 triangles \(byte 80\), the file holds 5558 .*")


# --- ascii STL -----------------------------------------------------------------------------------

def ascii_stl(vertices, triangles, name="part", newline="\n") -> str:
    lines = [f"solid {name}"]
    for t in triangles:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += [f"      vertex {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in vertices[t]]
        lines += ["    endloop", "  endfacet"]
    return newline.join(lines + [f"endsolid {name}", ""])


@pytest.mark.parametrize("form", FORMS)
def test_ascii_stl_cut_after_a_facet_is_refused(tmp_path, elephant, form):
    text = ascii_stl(elephant.vertices, elephant.triangles[:94])
    lines = text.splitlines(keepends=True)
    cut = "".join(lines[:1 + 38 * 7])  # "solid", then 38 whole facets of 7 lines
    refused(write(tmp_path, "cut.stl", cut.encode(), form),
            re.escape("line 267: the file ends without the 'endsolid' of the solid at line 1 (cut after facet 38?)"))
    data = read_mesh(write(tmp_path, "whole.stl", text.encode(), form))
    assert data.num_triangles == 94


@pytest.mark.parametrize("corners", [2, 4])
def test_ascii_stl_facets_need_three_vertices(tmp_path, corners):
    facet = "facet normal 0 0 1\nouter loop\n" + "".join(f"vertex {i} 0 {i * i}\n" for i in range(corners))
    text = "solid s\n" + facet + "endloop\nendfacet\nendsolid s\n"
    line = 7  # endfacet after 2 vertices; the 4th vertex
    message = "a facet with more than 3 vertices" if corners == 4 else "a facet with 2 vertices (STL facets have 3)"
    refused(write(tmp_path, "f.stl", text.encode()), f"line {line}: " + re.escape(message))


def test_ascii_stl_as_real_files_write_it_still_reads(tmp_path, elephant):
    """CRLF, solid names, several solids, white space and blank lines after endsolid."""
    first, second = elephant.triangles[:94], elephant.triangles[94:200]
    text = ascii_stl(elephant.vertices, first, "Mesh 1", "\r\n") + ascii_stl(elephant.vertices, second, "b") + "\n \n\t"
    data = read_mesh(write(tmp_path, "two.stl", text.encode()))
    np.testing.assert_array_equal(data.vertices[data.triangles], elephant.vertices[elephant.triangles[:200]])


# --- PLY -----------------------------------------------------------------------------------------

def ply_bytes(vertices, triangles, encoding, faces_declared=None, extra=False, crlf=False) -> bytes:
    """A PLY file of xyz (double) and triangle lists; `extra` adds per-vertex normals and an edge
    element, as scanners and MeshLab write."""
    n, m = len(vertices), len(triangles)
    lines = ["ply", f"format {encoding} 1.0", "comment made by test_io_counts", "obj_info scanner 1",
             f"element vertex {n}", "property double x", "property double y", "property double z"]
    if extra:
        lines += ["property float nx", "property float ny", "property float nz", "property uchar quality"]
    lines += [f"element face {m if faces_declared is None else faces_declared}",
              "property list uchar int vertex_indices"]
    if extra:
        lines += ["element edge 2", "property int vertex1", "property int vertex2"]
    lines += ["end_header"]
    header = ("\r\n" if crlf else "\n").join(lines) + ("\r\n" if crlf else "\n")
    if encoding == "ascii":
        rows = [" ".join(repr(float(x)) for x in v) + (" 0 0 1 7" if extra else "") for v in vertices]
        rows += ["3 " + " ".join(str(i) for i in t) for t in triangles]
        rows += ["0 1", "1 2"] if extra else []
        return (header + ("\r\n" if crlf else "\n").join(rows) + "\n").encode()
    end = "<" if encoding == "binary_little_endian" else ">"
    body = b"".join(struct.pack(end + "3d", *v) + (struct.pack(end + "3fB", 0, 0, 1, 7) if extra else b"")
                    for v in vertices)
    body += b"".join(struct.pack(end + "B3i", 3, *t) for t in triangles)
    body += struct.pack(end + "4i", 0, 1, 1, 2) if extra else b""
    return header.encode() + body


ENCODINGS = ["ascii", "binary_little_endian", "binary_big_endian"]


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("encoding", ENCODINGS)
def test_ply_with_a_face_count_below_its_faces_is_refused(tmp_path, elephant, encoding, form):
    raw = ply_bytes(elephant.vertices, elephant.triangles, encoding, faces_declared=1000)
    header = raw[:raw.index(b"end_header\n") + 11]
    counts = "line 5: element vertex 2775, line 9: element face 1000"
    if encoding == "ascii":
        first = header.count(b"\n") + 2775 + 1000 + 1
        rest = f"4558 more lines of data from line {first}"
    else:
        first = len(header) + 2775 * 24 + 1000 * 13
        rest = f"{4558 * 13} more bytes from byte {first}"
    refused(write(tmp_path, "f.ply", raw, form),
            re.escape(f"the file goes on after the rows its header declares ({counts}): {rest}"))


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("encoding", ENCODINGS)
def test_ply_with_data_after_its_rows_or_cut_short_is_refused(tmp_path, elephant, encoding, form):
    vertices, triangles = elephant.vertices[:10], np.array([[0, 1, 2], [2, 3, 4]])
    raw = ply_bytes(vertices, triangles, encoding)
    trailing = raw + (b"9 9 9\n" if encoding == "ascii" else b"\x01\x02\x03")
    what = "1 more line of data from line 24" if encoding == "ascii" else f"3 more bytes from byte {len(raw)}"
    refused(write(tmp_path, "t.ply", trailing, form),
            re.escape("the file goes on after the rows its header declares "
                      f"(line 5: element vertex 10, line 9: element face 2): {what}"))
    cut = raw[:-3] if encoding != "ascii" else raw[:raw.rindex(b"3 2 3 4")]
    refused(write(tmp_path, "c.ply", cut, form), r".*element 'face' row 1: the file ends in the middle of the data")


def test_ply_data_on_the_end_header_line_is_refused(tmp_path):
    # found by fuzz_read_ply: bytes after "end_header" on its own line were skipped unread
    raw = b"ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty float x\nend_header\x0b\x03\x00\x01"
    refused(write(tmp_path, "h.ply", raw), r"line 5: unexpected '\\x03\\x00\\x01' after end_header")


@pytest.mark.parametrize("encoding", ENCODINGS)
def test_ply_as_real_files_write_it_still_reads(tmp_path, elephant, encoding):
    """Comments, obj_info, extra vertex properties, an extra element, CRLF, one line end (binary)
    or blank lines (ascii) after the body."""
    raw = ply_bytes(elephant.vertices, elephant.triangles, encoding, extra=True, crlf=encoding == "ascii")
    raw += b"\n\n  \n" if encoding == "ascii" else b"\r\n"
    data, messages = read_quietly(write(tmp_path, "ok.ply", raw, ".gz"))
    assert messages == []
    np.testing.assert_array_equal(data.vertices, elephant.vertices)
    np.testing.assert_array_equal(data.triangles, elephant.triangles)


# --- OFF -----------------------------------------------------------------------------------------

def off_with_counts(text: str, counts: str) -> str:
    lines = text.split("\n")
    index = next(i for i, line in enumerate(lines) if re.fullmatch(r"\s*\d+\s+\d+\s+\d+\s*", line))
    lines[index] = counts
    return "\n".join(lines), index + 1


@pytest.mark.parametrize("form", FORMS)
def test_off_with_a_face_count_below_its_faces_is_refused(tmp_path, form):
    text, counts_line = off_with_counts(ELEPHANT.read_text(), "2775 100 0")
    data_lines = [i for i, line in enumerate(text.split("\n"), 1) if i > counts_line and line.strip()]
    first = data_lines[2775 + 100]  # the first line past the counts (the file has a blank line)
    refused(write(tmp_path, "f.off", text.encode(), form),
            re.escape(f"line {first}: the header (line {counts_line}) says 2775 vertices and 100 faces, "
                      f"but 5458 more lines of data follow them"))


def test_off_with_a_vertex_count_below_its_vertices_is_refused(tmp_path):
    # "OFF 299 100" in the issue: vertex rows then read as faces, and data is left over.
    text = "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n"
    refused(write(tmp_path, "v.off", text.encode()),
            re.escape("line 8: the header (line 2) says 4 vertices and 1 faces, but 1 more line of data follow them"))


def test_off_cut_short_and_off_as_real_files_write_it(tmp_path, elephant):
    text = ELEPHANT.read_text()
    cut = text[:text.rstrip().rindex("\n")]  # the last face line gone
    refused(write(tmp_path, "c.off", cut.encode(), ".gz"), re.escape("the file ends after 5557 of 5558 faces"))
    # comments, blank lines, CRLF and white space after the last face still read
    data = read_mesh(write(tmp_path, "ok.off", (text.replace("\n", "\r\n") + "# the end\n\n  \t\n").encode()))
    np.testing.assert_array_equal(data.triangles, elephant.triangles)


@pytest.mark.parametrize("name, text, message", [
    ("c.off", "OFF\n+-3 1 0\n", r"line 2: expected the vertex, face and edge counts, got '\+-3'"),
    ("v.obj", "v +-1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", r"line 1: vertex coordinate '\+-1' is not a number"),
])
def test_numbers_take_one_sign(tmp_path, name, text, message):
    # found by fuzz_read_off: "+-0" read as a count of 0 (the '+' dropped, then "-0" parsed)
    refused(write(tmp_path, name, text.encode()), message)


# --- OBJ: skipped faces warn; a cut last line is refused --------------------------------------------

@pytest.mark.parametrize("form", FORMS)
def test_obj_faces_with_fewer_than_three_corners_warn(tmp_path, form):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2\n# a point\nf 4\nf 1 3 4\n"
    data, messages = read_quietly(write(tmp_path, "p.obj", text.encode(), form))
    assert data.num_triangles == 2 and data.skipped_faces == 2
    assert messages == [f"{tmp_path / ('p.obj' + form)}: skipped 2 faces with fewer than 3 corners (the first at line 6)"]


@pytest.mark.parametrize("name, text, line", [
    ("p.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n",
     "face 0"),
    ("p.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 1 2\n", "line 7"),
])
def test_ply_and_off_faces_with_fewer_than_three_corners_warn(tmp_path, name, text, line):
    data, messages = read_quietly(write(tmp_path, name, text.encode()))
    assert data.num_triangles == 1
    assert messages == [f"{tmp_path / name}: skipped 1 face with fewer than 3 corners (the first at {line})"]


def cut_positions(text: str, line_number: int):
    """(cut text, the cut line as it is left, the whole line) for every cut inside line
    `line_number` (1-based) after its 'f' keyword, before its '\\n'."""
    start = sum(len(line) for line in text.splitlines(keepends=True)[:line_number - 1])
    end = text.index("\n", start)
    for cut in range(start + 1, end):
        yield text[:cut], text[start:cut], text[start:end].rstrip()


def looks_cut(corners) -> bool:
    """The rule, restated: fewer than 3 corners, a last corner ending in '/', or with fewer '/'
    than the corner before it."""
    return len(corners) < 3 or corners[-1].endswith("/") or corners[-1].count("/") < corners[-2].count("/")


@pytest.mark.parametrize("name, line", [("uv_materials/spider/spider.obj", 2000),
                                        ("open_boundary/kivy_suzanne_monkey.obj", 6030),
                                        ("open_boundary/npm_teapot.obj", 1000)])
def test_obj_cut_in_a_face_line_is_refused_unless_the_cut_is_in_its_last_number(tmp_path, name, line):
    """The rule (docs/robustness.md): an OBJ whose last line has no line end and holds a face of
    fewer than 3 corners, or whose last corner ends in '/' or has fewer '/' parts than the corner
    before it, is cut short. A cut inside the last number of the last corner leaves a face that
    looks whole: that cut alone cannot be seen."""
    text = (DATA / name).read_text()
    assert text.splitlines()[line - 1].startswith("f ")
    path = tmp_path / "cut.obj.gz"
    seen = unseen = 0
    for cut, left, whole in cut_positions(text, line):
        path.write_bytes(gzip.compress(cut.encode()))
        corners = left.split()[1:]
        if looks_cut(corners):
            refused(path, rf"line {line}: the file ends without a line end in (a face of [0-2] corners|the face "
                          r"corner '[^']*'): it looks cut short")
            seen += 1
            continue
        # Undetectable: the cut lies in the last '/'-part of the last corner.
        last, full = corners[-1], whole.split()[-1]
        assert len(corners) == len(whole.split()) - 1 and full.startswith(last) and "/" not in full[len(last):]
        data = read_mesh(path)
        assert data.triangle_polygon.max() + 1 == sum(1 for s in cut.splitlines() if s.startswith("f "))
        unseen += 1
    assert seen >= 10 and 1 <= unseen <= 4


def test_obj_as_real_files_write_it_still_reads(tmp_path):
    """vt, vn, usemtl, mtllib, g, s, o, CRLF, no line end after a whole last face, mixed v and v/vt
    corners (as the writer writes a corner without a UV)."""
    text = ("mtllib m.mtl\r\no part\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 1 1 0\r\nvt 0 0\r\nvt 1 0\r\nvt 0 1\r\n"
            "vn 0 0 1\r\ng body\r\ns 1\r\nusemtl skin\r\nf 1/1/1 2/2/1 3/3/1\r\ns off\r\nf 2/2 4 3/3")
    data, messages = read_quietly(write(tmp_path, "ok.obj", text.encode(), ".gz"))
    assert messages == [] and data.num_triangles == 2
    assert data.material_names == ["skin"] and data.material_libraries == ["m.mtl"]


# --- the command line shows the warning and refuses empty files ---------------------------------

def test_cli_prints_a_skipped_face_warning_as_one_line(tmp_path, elephant):
    lines = ["v " + " ".join(repr(float(x)) for x in v) for v in elephant.vertices]
    lines += ["f " + " ".join(str(i + 1) for i in t) for t in elephant.triangles[:-1]]
    lines += ["f 1 2", "f " + " ".join(str(i + 1) for i in elephant.triangles[-1])]
    # the elephant as OBJ, with one 2-corner face before its last triangle
    path = write(tmp_path, "e.obj", ("\n".join(lines) + "\n").encode(), ".gz")
    done = cli.run("decimate", path, tmp_path / "out.obj", "--ratio", 0.5)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == [f"topstoc: warning: {path}: skipped 1 face with fewer than 3 "
                                        f"corners (the first at line {2775 + 5558})"]
    assert read_mesh(tmp_path / "out.obj").num_vertices < 2775


@pytest.mark.parametrize("command, extra", [("topology", []), ("decimate", ["out.stl", "--ratio", "0.5"]),
                                            ("loops", []), ("measure", [str(ELEPHANT)]),
                                            ("fill-holes", ["out.stl"]), ("remove-handle", ["out.stl", "--index", "0"])])
def test_every_command_refuses_an_empty_file_by_name(tmp_path, command, extra):
    path = write(tmp_path, "empty.stl", b"")
    done = cli.run(command, path, *[tmp_path / e if e == "out.stl" else e for e in extra])
    cli.assert_one_error_line(command, done, f"{path}: the mesh has no triangles: the file is empty")
    assert not (tmp_path / "out.stl").exists()
