"""Mesh files: OBJ, PLY, OFF and STL, plain or gzip-compressed (reading also bzip2).

>>> data = read_mesh("bunny.ply.gz")
>>> data.vertices.shape, data.triangles.shape
>>> write_mesh("bunny.obj", data)

Reading keeps the file's raw complex: the file's vertices in the file's order, every face
(polygons fan-triangulated, degenerate and non-manifold faces included). STL files, which
store three positions per facet, are welded by exact position first (vertex ids then follow
the order of first appearance). The parsers are native (topstoc._topstoc); compressed files
are decompressed here and parsed from memory.

What each format carries, reading and writing: OBJ positions, polygons, UVs (vt), materials
(usemtl names, mtllib) and vertex colours (``v x y z r g b``); PLY positions, polygons, vertex
colours and UVs (per vertex, or MeshLab's per-face ``texcoord`` list); OFF positions, polygons
and vertex colours (COFF); STL positions and triangles.

Sloppy files that Blender, MeshLab and assimp read are read too, with a ``MeshFileWarning``
saying what was skipped: faces with fewer than three corners (points, lines), PLY header lines
that are no keyword (old Blender wrote "Created by Blender3D ..."), names (usemtl, mtllib) that
are not UTF-8 (decoded as Latin-1, which never fails). Layouts that cannot be read
unambiguously are errors (two PLY ``vertex`` elements), and so is data that disagrees with the
counts the file declares, or a file that does not end where its format says (a binary STL of
the wrong size, an ascii STL without ``endsolid``, rows past a PLY or OFF header's counts, an
OBJ whose unterminated last line ends in an incomplete face): docs/robustness.md, "Mesh files".
A file without triangles is an error too, unless ``allow_empty``.

Compressed files are decompressed in pieces and refused once the output passes
``max_decompressed_bytes`` (default ``MAX_DECOMPRESSED_BYTES`` = 2 GiB; ``None`` = no limit):
a small .gz made to expand to many gigabytes stops with a ValueError instead of filling
memory. Raise the limit for larger files.

Writing refuses OBJ material or library names that would read back differently (a line
break, '#', a trailing backslash, white space at either end, ``(null)``): OBJ has no escapes.
"""

from __future__ import annotations

import bz2
import gzip
import os
import re
import warnings
import zlib
from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

from ..support import atomic
from ..support.counts import MeshCounts
from ..support.native import engine
from ..support.errors import TopStocError

FORMATS = ("obj", "ply", "off", "stl")
COMPRESSIONS = ("gz", "bz2")
#: Optional MeshData attributes each format stores (besides positions and faces).
CARRIES = {"obj": ("corner_uvs", "vertex_colors", "triangle_material"),
           "ply": ("corner_uvs", "vertex_colors"), "off": ("vertex_colors",), "stl": ()}


@dataclass
class MeshData(MeshCounts):
    """A mesh as stored in a file, in the file's vertex and face order.

    vertices: (n, 3) float64. triangles: (m, 3) int32, polygons fan-triangulated as
    (v0, vi, vi+1). triangle_polygon: (m,) int32, the index of each triangle's face in the file
    (faces with fewer than three corners produce no triangle but keep their index).
    corner_uvs: (m, 3, 2) float64 per triangle corner, NaN where a corner has none.
    vertex_colors: (n, 3) or (n, 4) float64, in [0, 1] when the file stores bytes.
    triangle_material: (m,) int32 index into material_names, -1 for faces without one.
    material_libraries: OBJ mtllib arguments as written (the .mtl files are not read).
    skipped_faces: faces with fewer than three corners (points, lines) in the file.
    file_normals: the file stored normals (OBJ vn, PLY nx, NOFF), which are not read: a
    written copy has none (dropped_attributes reports them).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    triangle_polygon: Optional[np.ndarray] = None
    corner_uvs: Optional[np.ndarray] = None
    vertex_colors: Optional[np.ndarray] = None
    triangle_material: Optional[np.ndarray] = None
    material_names: List[str] = field(default_factory=list)
    material_libraries: List[str] = field(default_factory=list)
    skipped_faces: int = 0
    file_normals: bool = False

    def __post_init__(self):
        self.vertices = np.asarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        triangles = np.asarray(self.triangles, dtype=np.int64).reshape(-1, 3)
        if triangles.size and (triangles.min() < 0 or triangles.max() > np.iinfo(np.int32).max):
            raise TopStocError(f"triangle indices must lie in [0, 2**31), got "
                             f"[{triangles.min()}, {triangles.max()}]")
        self.triangles = triangles.astype(np.int32)
        m = len(self.triangles)
        if self.triangle_polygon is None:
            self.triangle_polygon = np.arange(m, dtype=np.int32)
        self.triangle_polygon = np.asarray(self.triangle_polygon, dtype=np.int32)
        if self.corner_uvs is not None:
            self.corner_uvs = np.asarray(self.corner_uvs, dtype=np.float64).reshape(m, 3, 2)
        if self.vertex_colors is not None:
            self.vertex_colors = np.asarray(self.vertex_colors, dtype=np.float64)
        if self.triangle_material is not None:
            self.triangle_material = np.asarray(self.triangle_material, dtype=np.int32)
        self.material_names = list(self.material_names)
        self.material_libraries = list(self.material_libraries)

    def attributes(self) -> List[str]:
        """Names of the optional attributes this mesh carries."""
        return [name for name in ("corner_uvs", "vertex_colors", "triangle_material")
                if getattr(self, name) is not None]

    def summary(self) -> str:
        """One line: counts and which attributes the mesh carries."""
        parts = [f"{self.num_vertices} vertices", f"{self.num_triangles} triangles"]
        if self.corner_uvs is not None:
            parts.append("UVs")
        if self.vertex_colors is not None:
            parts.append(f"{self.vertex_colors.shape[1]}-channel vertex colours")
        if self.triangle_material is not None:
            parts.append(f"{len(self.material_names)} materials")
        if self.skipped_faces:
            parts.append(f"{self.skipped_faces} faces with fewer than 3 corners skipped")
        return ", ".join(parts)


def mesh_format(path) -> tuple:
    """(format, compression) from a file name: e.g. ("ply", "gz"), ("obj", None).

    Raises ValueError for extensions other than .obj .ply .off .stl (optionally + .gz/.bz2).
    """
    name = os.fspath(path)
    stem, ext = os.path.splitext(name.lower())
    compression = None
    if ext[1:] in COMPRESSIONS:
        compression = ext[1:]
        stem, ext = os.path.splitext(stem)
    if ext[1:] not in FORMATS:
        raise TopStocError(f"{name}: unknown mesh file extension {ext or '(none)'!r}; expected one of "
                           f"{', '.join('.' + f for f in FORMATS)} (optionally followed by .gz or .bz2)")
    return ext[1:], compression


#: Default cap on a compressed file's decompressed size (read_mesh's max_decompressed_bytes).
MAX_DECOMPRESSED_BYTES = 2 << 30
_CHUNK = 1 << 20


class MeshFileWarning(UserWarning):
    """A mesh file was read, but something in it was skipped or reinterpreted (the message says what)."""


def _new_decompressor(compression: str):
    if compression == "gz":
        return zlib.decompressobj(wbits=16 + zlib.MAX_WBITS)  # gzip header and trailer checked
    return bz2.BZ2Decompressor()


def _decompress(name: str, raw: bytes, compression: Optional[str], limit: Optional[int]) -> bytes:
    """raw decompressed in pieces, never past ``limit`` bytes; concatenated gzip or bzip2
    members are read one after the other, as gzip and bzip2 themselves do."""
    if compression is None:
        return raw
    parts, total = [], 0
    view = memoryview(raw)
    try:
        while True:
            decompressor = _new_decompressor(compression)
            while True:
                room = _CHUNK if limit is None else min(_CHUNK, limit - total + 1)
                if compression == "gz":
                    piece = decompressor.decompress(view, room)
                    view = memoryview(decompressor.unconsumed_tail)
                    done = decompressor.eof
                else:
                    piece = decompressor.decompress(view, room)
                    view = memoryview(b"")  # BZ2Decompressor keeps what it has not used
                    done = decompressor.eof
                total += len(piece)
                if limit is not None and total > limit:
                    raise TopStocError(f"{name}: decompresses to more than {limit} bytes (the limit, "
                                       f"max_decompressed_bytes; the file has {len(raw)} compressed bytes)")
                parts.append(piece)
                if done:
                    break
                if not piece and (compression == "gz" and not view
                                  or compression == "bz2" and decompressor.needs_input):
                    raise EOFError("the compressed data ends early")
            rest = decompressor.unused_data
            if not rest.strip(b"\0"):  # trailing zero padding, as gzip(1) tolerates
                break
            view = memoryview(rest)
    except (OSError, EOFError, zlib.error) as error:
        raise TopStocError(f"{name}: cannot decompress ({compression}): {error}") from None
    return b"".join(parts)


def _decode_names(name: str, raw_names) -> List[str]:
    """Names from the file's bytes: UTF-8, else Latin-1 (every byte is a Latin-1 character)."""
    names = []
    for raw in raw_names:
        try:
            names.append(raw.decode("utf-8"))
        except UnicodeDecodeError:
            decoded = raw.decode("latin-1")
            warnings.warn(f"{name}: name {decoded!r} is not UTF-8; read as Latin-1", MeshFileWarning, stacklevel=3)
            names.append(decoded)
    return names


def read_mesh(path, max_decompressed_bytes: Optional[int] = MAX_DECOMPRESSED_BYTES,
              allow_empty: bool = False) -> MeshData:
    """Reads a mesh file (see the module docs for formats and conventions).

    Raises FileNotFoundError / OSError when the file cannot be read, ValueError (naming the
    file, and the line or byte) for an unknown extension, unparseable content, data that does
    not match the file's counts, a file cut short, indices out of range, a compressed file
    expanding past ``max_decompressed_bytes`` (None: no limit), or a mesh without triangles
    (an empty file included) unless ``allow_empty``. What was skipped in a sloppy file (faces
    with fewer than 3 corners, ...) is reported as a MeshFileWarning, one line each.
    """
    name = os.fspath(path)
    kind, compression = mesh_format(name)
    if max_decompressed_bytes is not None and (isinstance(max_decompressed_bytes, bool) or
                                               not isinstance(max_decompressed_bytes, int) or
                                               max_decompressed_bytes < 0):
        raise TopStocError(f"max_decompressed_bytes must be a non-negative int or None, "
                           f"got {max_decompressed_bytes!r}")
    with open(name, "rb") as stream:
        raw = stream.read()
    data = _decompress(name, raw, compression, max_decompressed_bytes)
    if not allow_empty and not data.strip():
        raise TopStocError(f"{name}: the mesh has no triangles: the file is empty")
    # A UTF-16 byte-order mark (a binary STL's header may hold any bytes): the text would parse as nothing.
    if kind != "stl" and data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise TopStocError(f"{name}: the file is UTF-16 text, which mesh readers do not take; "
                           "save it as UTF-8 or ASCII")
    try:
        parsed = engine.read_mesh(data, kind)
    except ValueError as error:
        raise TopStocError(f"{name}: {error}") from None
    m = len(parsed["triangles"])
    if m == 0 and not allow_empty:
        n, skipped = len(parsed["vertices"]), int(parsed["skipped_faces"])
        held = f"{n} vertices" if n != 1 else "1 vertex"
        held += f", {skipped} faces with fewer than 3 corners" if skipped else ", no faces"
        raise TopStocError(f"{name}: the mesh has no triangles (the file holds {held})")
    for message in parsed["warnings"]:
        warnings.warn(f"{name}: {message}", MeshFileWarning, stacklevel=2)
    uvs = parsed["corner_uvs"]
    return MeshData(vertices=parsed["vertices"], triangles=parsed["triangles"],
                    triangle_polygon=parsed["triangle_polygon"],
                    corner_uvs=None if uvs is None else uvs.reshape(m, 3, 2),
                    vertex_colors=parsed["vertex_colors"],
                    triangle_material=parsed["triangle_material"],
                    material_names=_decode_names(name, parsed["material_names"]),
                    material_libraries=_decode_names(name, parsed["material_libraries"]),
                    skipped_faces=int(parsed["skipped_faces"]), file_normals=_stores_normals(kind, data))


def encode_mesh(data: MeshData, kind: str) -> bytes:
    """The bytes of ``data`` written as ``kind`` ("obj", "ply", "off" or "stl"), uncompressed."""
    if kind not in FORMATS:
        raise TopStocError(f"format must be one of {FORMATS}, got {kind!r}")
    m = data.num_triangles
    uvs = None if data.corner_uvs is None else np.asarray(data.corner_uvs, dtype=np.float64)
    if uvs is not None and uvs.shape != (m, 3, 2):
        raise TopStocError(f"corner_uvs must have shape ({m}, 3, 2), got {uvs.shape}")
    return engine.write_mesh(kind, data.vertices, data.triangles,
                             triangle_polygon=data.triangle_polygon,
                             corner_uvs=None if uvs is None else uvs.reshape(m, 6),
                             vertex_colors=data.vertex_colors,
                             triangle_material=data.triangle_material,
                             material_names=[str(n) for n in data.material_names],
                             material_libraries=[str(n) for n in data.material_libraries])


def dropped_attributes(data: MeshData, path) -> List[str]:
    """The attributes of ``data`` that writing it to ``path`` would lose (see CARRIES); "normals"
    when its file had normals (never written: shading follows the written shape)."""
    kind, _ = mesh_format(path)
    lost = [name for name in data.attributes() if name not in CARRIES[kind]]
    return lost + ["normals"] if data.file_normals else lost


def _stores_normals(kind: str, data: bytes) -> bool:
    """Whether a file's bytes hold normals: OBJ ``vn`` lines, PLY ``nx`` properties, NOFF."""
    if kind == "obj":
        return re.search(rb"(?m)^[ \t]*vn[ \t]", data) is not None
    if kind == "ply":
        header = data[:data.find(b"end_header")]
        return re.search(rb"property\s+\w+\s+nx\b", header) is not None
    if kind == "off":
        words = data[:32].split()
        return bool(words) and words[0].endswith(b"OFF") and b"N" in words[0][:-3]
    return False


def write_mesh(path, data: MeshData) -> None:
    """Writes ``data`` in the format the extension names; .gz (or .bz2) compresses.

    Formats carry what they can (CARRIES, dropped_attributes); PLY is written binary little-endian, STL
    binary. The file is written atomically (topstoc.core.support.atomic): a failed or interrupted write
    never leaves a half-written file at ``path``, and a symlink at ``path`` is written through.
    """
    name = os.fspath(path)
    kind, compression = mesh_format(name)
    try:
        payload = encode_mesh(data, kind)
    except ValueError as error:
        raise TopStocError(f"{name}: {error}") from None
    if compression == "gz":
        payload = gzip.compress(payload, compresslevel=6, mtime=0)
    elif compression == "bz2":
        payload = bz2.compress(payload)
    atomic.write_bytes(name, payload)
