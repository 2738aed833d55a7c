"""topstoc.core.api.box_index: the triangles whose boxes meet a query box, against a scan of
every triangle's box, on a mesh the clean-up's LocalEditor edits in place."""

import numpy as np

import cleanup_meshes
from topstoc.core.api.box_index import BoxIndex, sorted_unique
from topstoc.core.api.local_edit import LocalEditor
from topstoc.core.api.loops import handle_tunnel_loops


def scan(editor, low, high):
    """The answer by brute force: every current triangle's box against [low, high]."""
    corners = editor.vertices.view()[editor.triangles.view()]
    return np.flatnonzero(np.all(corners.max(axis=1) >= low, axis=1) & np.all(corners.min(axis=1) <= high, axis=1))


def queries(rng, vertices, count):
    """Boxes of several sizes around random points of the mesh, and some beyond it."""
    centres = vertices[rng.integers(0, len(vertices), count)] + rng.normal(0, 0.5, (count, 3))
    half = rng.uniform(0.05, 4.0, (count, 3))
    far = np.array([[-50.0, -50.0, -50.0], [80.0, 2.0, 3.0], [1.0, 1.0, 60.0]])
    return np.concatenate([centres - half, far]), np.concatenate([centres + half, far + 1.0])


def test_the_index_finds_what_a_scan_finds_while_handles_are_removed():
    vertices, triangles = cleanup_meshes.block_with_arches(12, 1, jitter=0.05, seed=5)
    loops, used = [], np.zeros(len(vertices), dtype=bool)
    for loop in sorted(handle_tunnel_loops(vertices, triangles).handles, key=lambda loop: loop.length):
        if loop.length < 6 and not used[loop.vertices].any():
            loops.append(loop.vertices)
            used[loop.vertices] = True
    assert len(loops) >= 6
    editor = LocalEditor(vertices, triangles)
    rng = np.random.default_rng(3)
    for tag, loop in enumerate(loops):
        editor.remove_handle(loop, tag, refine=True, fair=True)
        corners = editor.vertices.view()[editor.triangles.view()]
        low, high = editor.boxes()  # updated only where the edit moved or renumbered corners
        assert np.array_equal(low, corners.min(axis=1)) and np.array_equal(high, corners.max(axis=1))
        lows, highs = queries(rng, editor.vertices.view(), 40)
        for low, high in zip(lows, highs):
            assert np.array_equal(editor._near(low, high), scan(editor, low, high))
    assert editor.triangles.count > len(triangles)  # the edits appended patches the queries met


def test_candidates_cover_boxes_of_any_size_and_recorded_edits():
    rng = np.random.default_rng(8)
    low = rng.uniform(-10, 10, (500, 3))
    high = low + rng.exponential(0.3, (500, 3))
    high[7] = low[7] + 15.0  # one large box sets the cell size
    index = BoxIndex(low, high)
    # Moved boxes and added ones, each inside the box its edit recorded.
    moved = np.array([3, 4, 5])
    low[moved] += 0.2
    high[moved] += 0.2
    added_low, added_high = np.array([[1.0, 1.0, 1.0]]), np.array([[1.5, 1.2, 1.1]])
    low, high = np.concatenate([low, added_low]), np.concatenate([high, added_high])
    index.record(low[[3, 4, 5, 500]].min(axis=0), high[[3, 4, 5, 500]].max(axis=0), np.array([3, 4, 5, 500]))
    for centre in rng.uniform(-12, 12, (200, 3)):
        q_low, q_high = centre - rng.uniform(0, 3, 3), centre + rng.uniform(0, 3, 3)
        meet = np.flatnonzero(np.all(high >= q_low, axis=1) & np.all(low <= q_high, axis=1))
        found = index.candidates(q_low, q_high, len(low))
        assert np.all(np.diff(found) > 0) and set(meet) <= set(found.tolist())
    assert len(index.candidates(np.full(3, -1.0), np.full(3, 1.0), len(low))) < len(low) / 2  # it does prune


def test_sorted_unique_is_numpys_unique():
    rng = np.random.default_rng(4)
    for values in (rng.integers(0, 50, 300), rng.integers(-5, 10**6, 7000).astype(np.int32),
                   np.zeros(0, np.int64), np.array([3])):
        found = sorted_unique(values)
        assert np.array_equal(found, np.unique(values)) and found.dtype == values.dtype
