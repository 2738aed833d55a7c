"""Range images as meshes (tests/bench/range_grid.py, which the quality benchmark's Stanford scans
go through): a small range grid written here, its triangles counted by hand."""

import pathlib
import sys

import numpy as np

import reference

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "bench"))
from range_grid import range_grid_off, read_range_grid, triangulate  # noqa: E402


def range_grid_ply(depth: np.ndarray) -> bytes:
    """An ASCII range-grid PLY with CRLF line ends (as the Stanford files are stored): one
    sample per finite depth, x and y its column and row."""
    rows, cols = depth.shape
    cells, points = [], []
    for r in range(rows):
        for c in range(cols):
            if np.isfinite(depth[r, c]):
                cells.append(f"1 {len(points)}")
                points.append(f"{c} {r} {depth[r, c]}")
            else:
                cells.append("0")
    header = ["ply", "format ascii 1.0", f"obj_info num_cols {cols}", f"obj_info num_rows {rows}",
              f"element vertex {len(points)}", "property float x", "property float y", "property float z",
              f"element range_grid {rows * cols}", "property list uchar int vertex_indices", "end_header"]
    return "\r\n".join(header + points + cells).encode() + b"\r\n"


def test_blocks_become_triangles_and_depth_jumps_stay_open():
    depth = np.zeros((5, 7))
    depth[2, 2] = np.nan      # one missing sample: its four blocks keep one triangle each
    depth[:, 5:] = 50.0       # a step far deeper than the spacing: no triangle across it
    vertices, grid = read_range_grid(range_grid_ply(depth))
    assert len(vertices) == 34 and (grid >= 0).sum() == 34
    triangles = triangulate(vertices, grid)
    # left part: 4 x 4 blocks, 4 of them lose a corner (one triangle), 12 keep two; right part 4 x 1 blocks
    assert len(triangles) == 4 * 1 + 12 * 2 + 4 * 2
    p = vertices[triangles]
    assert np.all(np.abs(p[:, :, 2].max(axis=1) - p[:, :, 2].min(axis=1)) < 1)  # none spans the step
    # one orientation throughout: every inner edge is run both ways
    t = np.asarray(triangles)
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    assert len(np.unique(directed, axis=0)) == len(directed)
    assert reference.degenerate_or_duplicate(triangles) == (0, 0)
    # two pieces: the left one with a hole (Euler characteristic 0, two boundary loops), the right a disk
    assert sorted(reference.invariants(len(vertices), triangles)) == [(0, 2, True, True), (1, 1, True, True)]


def test_off_output_keeps_only_used_vertices():
    depth = np.zeros((3, 3))
    depth[0, 0] = np.nan
    text = range_grid_off(range_grid_ply(depth))
    lines = text.splitlines()
    assert lines[0] == "OFF" and lines[1] == "8 7 0"  # 8 samples; 1 + 2 + 2 + 2 triangles
