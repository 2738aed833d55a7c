"""Scans at their topology's floor (issue 40): a disc goes down to one triangle. The floors are
counted here from Euler's formula."""

import numpy as np
import pytest

from topstoc.core import Mesh, topology


def grid_disc(n: int, origin=(0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """An n x n grid of quads, each split in two: a disc (one boundary loop, genus 0)."""
    ii, jj = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    x, y = ii.ravel() / n + origin[0], jj.ravel() / n + origin[1]
    vertices = np.column_stack([x, y, 0.05 * np.sin(3 * x) * np.cos(2 * y)])
    quads = [(i * (n + 1) + j, (i + 1) * (n + 1) + j, (i + 1) * (n + 1) + j + 1, i * (n + 1) + j + 1)
             for i in range(n) for j in range(n)]
    triangles = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], dtype=np.int32)
    return vertices, triangles


def several_discs(count: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` disjoint grid discs side by side (the loose pieces of a range scan)."""
    parts = [grid_disc(n, (2.0 * k, 0.0)) for k in range(count)]
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    return (np.vstack([v for v, _ in parts]),
            np.vstack([t + o for (_, t), o in zip(parts, offsets)]).astype(np.int32))


def euler_floor(components: int) -> int:
    """Fewest triangles of ``components`` discs: V - E + F = 1 with a boundary of at least three
    edges gives F = 1 (three vertices, three edges)."""
    return components


@pytest.mark.parametrize("mode", ["quality", "fast"])
def test_discs_go_down_to_one_triangle_each(mode):
    vertices, triangles = several_discs(5, 6)
    result = Mesh(vertices, triangles).decimate(target_triangles=1, mode=mode, seed=0)
    assert len(result.triangles) == euler_floor(5)  # was 2 each: the last quad could not close
    parts = topology(result.vertices, result.triangles).components
    assert [(c.genus, len(c.boundary_loops), c.manifold) for c in parts] == [(0, 1, True)] * 5
    assert result.stats.target_missed.reason == "topology"
    assert result.stats.target_missed.asked == 1
    # every triangle keeps its area and three distinct corners
    tri = np.asarray(result.vertices)[np.asarray(result.triangles)]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    assert (area > 1e-6).all()
