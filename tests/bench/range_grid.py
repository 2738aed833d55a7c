#!/usr/bin/python3
"""Triangle meshes from range images stored as PLY range grids (Stanford's 3D Scanning Repository:
`element range_grid`, one cell per scanner sample holding 0 or 1 vertex index, row by row).

    python3 tests/bench/range_grid.py SCAN.ply OUT.off

Each 2 x 2 block of cells with four samples becomes two triangles split along the shorter
diagonal, one with three samples one triangle; a triangle with an edge longer than MAX_EDGE
times the median distance between neighbouring samples spans a depth jump and is left out. The
result is what a scanner's own meshing gives: one sheet with holes, ragged boundaries, islands
and pinched vertices, consistently oriented. fill_mesh_cache.py uses it for manifest entries
marked "range_grid".
"""

from __future__ import annotations

import sys

import numpy as np

MAX_EDGE = 4.0  # a depth jump: longer than this many median sample spacings


def read_range_grid(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3), grid (rows, cols) of vertex ids, -1 where no sample) of an ASCII range-grid PLY."""
    text = data.decode("ascii").replace("\r\n", "\n")
    header, _, body = text.partition("end_header\n")
    lines = header.splitlines()
    if not lines or lines[0] != "ply" or "format ascii 1.0" not in header:
        raise ValueError("not an ASCII PLY")
    info = {ln.split()[1]: ln.split()[2] for ln in lines if ln.startswith("obj_info ") and len(ln.split()) == 3}
    counts = {ln.split()[1]: int(ln.split()[2]) for ln in lines if ln.startswith("element ")}
    properties = [ln for ln in lines if ln.startswith("property ")]
    vertex_properties = len([p for p in properties if p.split()[1] != "list"])
    if "range_grid" not in counts or vertex_properties != 3:
        raise ValueError("expected a range grid and x, y, z vertices")
    rows, cols = int(info["num_rows"]), int(info["num_cols"])
    if counts["range_grid"] != rows * cols:
        raise ValueError(f"range grid of {counts['range_grid']} cells for {rows} x {cols}")
    body_lines = body.splitlines()
    n = counts["vertex"]
    vertices = np.array([ln.split() for ln in body_lines[:n]], dtype=np.float64)
    grid = np.full(rows * cols, -1, dtype=np.int64)
    for cell, ln in enumerate(body_lines[n:n + rows * cols]):
        if ln[0] != "0":
            grid[cell] = int(ln.split()[1])
    return vertices, grid.reshape(rows, cols)


def triangulate(vertices: np.ndarray, grid: np.ndarray, max_edge: float = MAX_EDGE) -> np.ndarray:
    """Triangles (m, 3) over the grid's 2 x 2 blocks, as the module docs say."""
    a, b, c, d = grid[:-1, :-1], grid[:-1, 1:], grid[1:, :-1], grid[1:, 1:]  # a b / c d
    near = []
    for p, q in ((a, b), (a, c)):  # neighbouring samples along a row and along a column
        both = (p >= 0) & (q >= 0)
        near.append(np.linalg.norm(vertices[p[both]] - vertices[q[both]], axis=1))
    limit = max_edge * float(np.median(np.concatenate(near)))
    candidates = []
    full = (a >= 0) & (b >= 0) & (c >= 0) & (d >= 0)
    ad = np.linalg.norm(vertices[a[full]] - vertices[d[full]], axis=1)
    bc = np.linalg.norm(vertices[b[full]] - vertices[c[full]], axis=1)
    split_ad = ad <= bc
    fa, fb, fc, fd = a[full], b[full], c[full], d[full]
    candidates += [np.column_stack(t) for t in (
        (fa[split_ad], fc[split_ad], fd[split_ad]), (fa[split_ad], fd[split_ad], fb[split_ad]),
        (fa[~split_ad], fc[~split_ad], fb[~split_ad]), (fb[~split_ad], fc[~split_ad], fd[~split_ad]))]
    # blocks with exactly three samples: the triangle of those three, in the same turning sense
    three = ((a >= 0).astype(int) + (b >= 0) + (c >= 0) + (d >= 0)) == 3
    for missing, corners in ((a, (b, c, d)), (b, (a, c, d)), (c, (a, d, b)), (d, (a, c, b))):
        m = three & (missing < 0)
        p, q, r = corners
        candidates.append(np.column_stack([p[m], q[m], r[m]]))
    triangles = np.concatenate(candidates)
    p = vertices[triangles]
    longest = np.max(np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2), axis=1)
    return triangles[longest <= limit]


def off_text(vertices: np.ndarray, triangles: np.ndarray) -> str:
    """The mesh as OFF, only the vertices the triangles use (renumbered in order)."""
    used, inverse = np.unique(triangles, return_inverse=True)
    lines = ["OFF", f"{len(used)} {len(triangles)} 0"]
    lines += [f"{x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices[used]]
    lines += [f"3 {i} {j} {k}" for i, j, k in inverse.reshape(-1, 3)]
    return "\n".join(lines) + "\n"


def range_grid_off(data: bytes) -> str:
    vertices, grid = read_range_grid(data)
    return off_text(vertices, triangulate(vertices, grid))


if __name__ == "__main__":
    with open(sys.argv[2], "w") as handle:
        handle.write(range_grid_off(open(sys.argv[1], "rb").read()))
