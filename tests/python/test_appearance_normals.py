"""Custom normals in the collapse cost (topstoc.core.carry.appearance) and hard edges as borders
(topstoc.core.carry.attributes.hard_normal_edges): a hard-surface mesh keeps its shading, and weight 0
is the geometry-only result to the bit.

The shading error is measured on the capped cylinder of tests/capped_cylinder.py (hard rims, caps
whose normals fake a bevel the flat shape does not have): area-weighted angle between the input's
shading normal and the result's at the closest point.
"""

import numpy as np
import pytest

from topstoc.core import Mesh
from topstoc.core.carry.appearance import appearance_attributes, unit_corner_normals
from topstoc.core.carry.attributes import corner_values, hard_normal_edges, moved_vertices
from topstoc.core.api.decimate import ATTRIBUTE_WEIGHT
from topstoc.core.support.errors import TopStocError
from topstoc.core.api.hausdorff import closest_points
from capped_cylinder import AROUND, capped_cylinder, shading_error

TARGET = 120  # vertices, of 834


def carried_normals(vertices, triangles, corner_normals, result) -> np.ndarray:
    """(m', 3, 3) the result's corner normals as the add-on carries them (mesh_write): the source
    corner's, interpolated for moved vertices and renormalised."""
    m = len(triangles)
    moved = moved_vertices(vertices, triangles, result)
    flat = corner_values(np.asarray(corner_normals).reshape(-1, 3), result.corner_source, result.triangles, moved,
                         np.arange(3 * m).reshape(m, 3))
    return (flat / np.linalg.norm(flat, axis=1, keepdims=True)).reshape(-1, 3, 3)


def _decimate(weight=None, borders=True):
    """(result, shading error) of the cylinder in quality mode, hard edges as borders."""
    vertices, triangles, normals = capped_cylinder()
    kwargs = {} if weight is None else appearance_attributes(triangles, corner_normals=normals).decimate_kwargs(weight)
    hard = hard_normal_edges(triangles, normals) if borders else None
    result = Mesh(vertices, triangles).decimate(target_vertices=TARGET, borders=hard, **kwargs)
    out = carried_normals(vertices, triangles, normals, result)
    return result, shading_error(vertices, triangles, normals, result.vertices, result.triangles, out, closest_points)


def test_the_hard_edges_are_the_rims():
    vertices, triangles, normals = capped_cylinder()
    hard = hard_normal_edges(triangles, normals)
    assert len(hard) == 2 * AROUND
    ends = vertices[hard.ravel()]
    np.testing.assert_allclose(np.hypot(ends[:, 0], ends[:, 1]), 1.0)
    assert np.all(np.isin(ends[:, 2], (0.0, 2.0)))
    assert shading_error(vertices, triangles, normals, vertices, triangles, normals, closest_points)["mean"] < 1e-5
    # a tilt below the angle is not a hard edge
    tilted = normals.copy()
    tilted[0, 0] = unit_corner_normals(triangles[:1], normals[:1] + [0, 0, 0.01])[0, 0]
    assert len(hard_normal_edges(triangles, tilted)) == 2 * AROUND


def test_normals_in_the_cost_keep_the_shading():
    plain, without = _decimate(0.0)
    kept, with_normals = _decimate(ATTRIBUTE_WEIGHT)
    assert kept.num_vertices == plain.num_vertices == TARGET
    print(f"shading error at {TARGET} vertices: {with_normals} with normals, {without} without")
    assert with_normals["mean"] < 0.3 * without["mean"], (with_normals, without)
    assert with_normals["rms"] < 0.3 * without["rms"], (with_normals, without)


def test_hard_edges_as_borders_keep_the_corners_apart():
    """Without the rims as borders a rim vertex's output corners take any of its input corners,
    so a side triangle may shade with a cap's normal."""
    _, loose = _decimate(ATTRIBUTE_WEIGHT, borders=False)
    _, bordered = _decimate(ATTRIBUTE_WEIGHT)
    assert bordered["mean"] < 0.2 * loose["mean"], (bordered, loose)


def test_weight_zero_is_the_geometry_only_result_to_the_bit():
    plain, _ = _decimate(None)
    zero, _ = _decimate(0.0)
    assert zero.parameters["attribute_channels"] == 0
    np.testing.assert_array_equal(zero.vertices, plain.vertices)
    np.testing.assert_array_equal(zero.triangles, plain.triangles)
    np.testing.assert_array_equal(zero.kept, plain.kept)


def test_fast_mode_ignores_the_normals():
    vertices, triangles, normals = capped_cylinder()
    mesh = Mesh(vertices, triangles)
    kwargs = appearance_attributes(triangles, corner_normals=normals).decimate_kwargs(ATTRIBUTE_WEIGHT)
    plain = mesh.decimate(target_vertices=TARGET, mode="fast")
    kept = mesh.decimate(target_vertices=TARGET, mode="fast", **kwargs)
    np.testing.assert_array_equal(kept.vertices, plain.vertices)
    np.testing.assert_array_equal(kept.triangles, plain.triangles)


def test_normals_follow_uvs_and_colours_as_unit_vectors():
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    uvs = np.zeros((2, 3, 2))
    colors = np.ones((4, 3))
    normals = np.array([[(0, 0, 2), (0, 3, 0), (4, 0, 0)], [(0, 0, 1), (1, 1, 0), (0, 0, -1)]], dtype=float)
    found = appearance_attributes(triangles, uvs, colors, normals)
    assert found.channels == ["uv.u", "uv.v", "color.r", "color.g", "color.b", "normal.x", "normal.y", "normal.z"]
    assert found.used == ["uv", "color", "normal"]
    np.testing.assert_allclose(found.values[:, :, 5:], normals / np.linalg.norm(normals, axis=2, keepdims=True))
    only = appearance_attributes(triangles, corner_normals=normals)
    assert only.channels == ["normal.x", "normal.y", "normal.z"]


def test_missing_normals_take_their_vertex_mean():
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    normals = np.array([[(0, 0, 1), (0, 1, 0), (1, 0, 0)], [(0, 0, 0), (np.nan, 0, 0), (0, 0, 5)]])
    filled = unit_corner_normals(triangles, normals)
    np.testing.assert_allclose(filled[1, 0], (0, 0, 1))   # vertex 0: its other corner
    np.testing.assert_allclose(filled[1, 1], (1, 0, 0))   # vertex 2: its other corner
    np.testing.assert_allclose(filled[1, 2], (0, 0, 1))   # known corners: unit length
    np.testing.assert_allclose(np.linalg.norm(filled, axis=2), 1.0)
    assert unit_corner_normals(triangles, np.zeros((2, 3, 3))) is None
    assert appearance_attributes(triangles, corner_normals=np.zeros((2, 3, 3))).values is None


@pytest.mark.parametrize("normals, fragment", [
    (np.zeros((2, 3, 3)), "normals must be numbers of shape"),
    (np.zeros((1, 3, 2)), "normals must be numbers of shape"),
    (np.full((1, 3, 3), "x"), "normals must be numbers of shape"),
])
def test_bad_normals_are_a_clear_error(normals, fragment):
    with pytest.raises(TopStocError, match=fragment):
        appearance_attributes([[0, 1, 2]], corner_normals=normals)
