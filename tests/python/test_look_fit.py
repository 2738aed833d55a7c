"""The look fitted to the source's after a decimation (topstoc.core.carry.look_fit): where the look
was in the cost, a result's UVs, colours and normals are the least-squares fit to the source's
over both meshes' matched points instead of the source's values at the kept vertices.

UVs are measured against the UV cylinder's closed-form mapping (tests/uv_cylinder.py); colours
and normals with tests/attribute_error.py (the bench's definition, random points independent
of the fit's quadrature points); a linear field is recovered from nothing (closed form).
"""

import numpy as np

from attribute_error import attribute_errors
from capped_cylinder import capped_cylinder
from meshgen import torus
from topstoc.core import Mesh
from topstoc.core.api.decimate import ATTRIBUTE_WEIGHT
from topstoc.core.api.hausdorff import closest_points
from topstoc.core.api.io import MeshData
from topstoc.core.carry.appearance import appearance_attributes
from topstoc.core.carry.attributes import (corner_values, hard_normal_edges, moved_vertices, transfer_attributes,
                                           uv_seam_edges)
from topstoc.core.carry.look_fit import LookFit, fit_look
from uv_cylinder import uv_cylinder, uv_distortion


def _grid(n=30):
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    vertices = np.c_[x.ravel(), y.ravel(), 0.05 * np.sin(3 * x.ravel()) * np.cos(2 * y.ravel())]
    ids = np.arange(n * n).reshape(n, n)
    a, b, c, d = ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel(), ids[1:, 1:].ravel(), ids[1:, :-1].ravel()
    return vertices, np.concatenate([np.c_[a, b, c], np.c_[a, c, d]]).astype(np.int64)


def test_a_linear_field_is_recovered_from_nothing():
    """Values linear in x and y on a gently curved sheet: whatever the carried values (zeros
    here), the fit's optimum is the field itself at the output's vertices (its pull towards the
    carried values costs a thousandth)."""
    vertices, triangles = _grid()
    result = Mesh(vertices, triangles).decimate(target_vertices=80)
    field = lambda p: np.c_[0.2 + 0.5 * p[:, 0], 0.7 - 0.4 * p[:, 1]]  # noqa: E731
    out_t = np.asarray(result.triangles, dtype=np.int64)
    fitted = LookFit(vertices, triangles, result.vertices, out_t).fit(
        field(vertices)[triangles], np.zeros((3 * len(out_t), 2)), "color")
    expected = field(np.asarray(result.vertices))[out_t].reshape(-1, 2)
    assert np.abs(fitted - expected).max() < 5e-3, np.abs(fitted - expected).max()


def _cylinder(weight):
    vertices, triangles, uvs = uv_cylinder()
    data = MeshData(vertices=vertices, triangles=triangles, corner_uvs=uvs)
    kwargs = appearance_attributes(triangles, uvs).decimate_kwargs(weight)
    result = Mesh(vertices, triangles).decimate(target_vertices=150, borders=uv_seam_edges(triangles, uvs), **kwargs)
    return data, result


def test_uvs_fit_the_mapping_better_and_the_seam_keeps_its_uvs():
    """On the cylinder stretched along its axis, the fitted UVs are closer to the closed-form
    mapping than the carried ones (at the default weight and with UVs out of the cost), and
    every corner of a vertex on the seam keeps the input's UV there, so both sides still meet."""
    for weight in (ATTRIBUTE_WEIGHT, 0.0):
        data, result = _cylinder(weight)
        carried, fitted = transfer_attributes(data, result), transfer_attributes(data, result, fit=True)
        before = uv_distortion(carried.vertices, carried.triangles, carried.corner_uvs)
        after = uv_distortion(fitted.vertices, fitted.triangles, fitted.corner_uvs)
        assert after["rms"] < 0.85 * before["rms"], (weight, before, after)
        v = np.asarray(fitted.vertices)
        on_seam = (np.abs(v[:, 1]) < 1e-9) & (v[:, 0] > 0.99)
        corners = on_seam[np.asarray(fitted.triangles)]
        assert corners.sum() >= 4
        np.testing.assert_array_equal(fitted.corner_uvs[corners], carried.corner_uvs[corners])
        assert not np.array_equal(fitted.corner_uvs, carried.corner_uvs)


def _stripes(vertices):
    """RGB per vertex: a smooth band and a sharp stripe across the torus."""
    rgb = 0.5 + 0.5 * np.sin(np.c_[3 * vertices[:, 0], 5 * vertices[:, 1], 2 * vertices[:, 2]])
    rgb[(vertices[:, 0] > 0.2) & (vertices[:, 0] < 0.5)] = (0.9, 0.1, 0.1)
    return rgb


def test_colours_fit_the_source_better_and_stay_colours():
    vertices, triangles = torus(60, 30)
    triangles = np.asarray(triangles, dtype=np.int64)
    colors = _stripes(np.asarray(vertices))
    data = MeshData(vertices=vertices, triangles=triangles, vertex_colors=colors)
    kwargs = appearance_attributes(triangles, None, colors).decimate_kwargs(ATTRIBUTE_WEIGHT)
    result = Mesh(vertices, triangles).decimate(ratio=0.1, **kwargs)
    source = {"vertices": vertices, "triangles": triangles, "color": colors[triangles]}
    errors = {}
    for fit in (False, True):
        out = transfer_attributes(data, result, fit=fit)
        assert out.vertex_colors.min() >= colors.min() and out.vertex_colors.max() <= colors.max()
        t = np.asarray(out.triangles, dtype=np.int64)
        errors[fit] = attribute_errors(source, {"vertices": out.vertices, "triangles": t,
                                                "color": out.vertex_colors[t]}, closest_points, 20_000)["color"]
    assert errors[True] < 0.9 * errors[False], errors


def test_normals_fit_the_shading_better_and_stay_unit():
    """The capped cylinder's faked bevel (tests/capped_cylinder.py), its hard rims as borders:
    fitted normals are unit, differ across the rims as the input's do, and shade closer."""
    vertices, triangles, normals = capped_cylinder()
    look = appearance_attributes(triangles, None, None, normals)
    result = Mesh(vertices, triangles).decimate(target_vertices=60, borders=hard_normal_edges(triangles, normals),
                                                **look.decimate_kwargs(ATTRIBUTE_WEIGHT))
    m, out_t = len(triangles), np.asarray(result.triangles, dtype=np.int64)
    carried = corner_values(normals.reshape(-1, 3), result.corner_source, out_t,
                            moved_vertices(vertices, triangles, result), np.arange(3 * m).reshape(m, 3))
    carried /= np.linalg.norm(carried, axis=1, keepdims=True)
    fitted = fit_look(vertices, triangles, result.vertices, out_t, {"n": (normals, carried, "normal")})["n"]
    np.testing.assert_allclose(np.linalg.norm(fitted, axis=1), 1.0, atol=1e-12)
    source = {"vertices": vertices, "triangles": triangles, "normal": normals}
    error = {name: attribute_errors(source, {"vertices": result.vertices, "triangles": out_t,
                                             "normal": values.reshape(-1, 3, 3)}, closest_points, 20_000)["normal"]
             for name, values in (("carried", carried), ("fitted", fitted))}
    assert error["fitted"] < 0.9 * error["carried"], error
    # a rim vertex still has two normals (cap and side) far apart
    rim = np.flatnonzero(np.abs(np.abs(np.asarray(result.vertices)[:, 2] - 1.0) - 1.0) < 1e-9)
    corner_vertex = out_t.ravel()
    spread = [np.ptp(fitted[corner_vertex == v] @ np.array([0, 0, 1.0])) for v in rim[:5]]
    assert min(spread) > 0.5, spread


def test_a_mesh_file_is_written_with_its_look_fitted_only_where_the_look_was_in_the_cost(tmp_path):
    """The mesh-file recipe (topstoc decimate, the batch) writes the fitted UVs when the look was
    in the cost and the carried ones when it was not (weight 0)."""
    from topstoc.core.api.io import read_mesh
    from topstoc.core.api.mesh_file_job import prepare_file

    vertices, triangles, uvs = uv_cylinder()
    data = MeshData(vertices=vertices, triangles=triangles, corner_uvs=uvs)
    for weight, fit in ((ATTRIBUTE_WEIGHT, True), (0.0, False)):
        job = prepare_file(str(tmp_path / "in.obj"), data, weight=weight)
        result = job.decimate({"target_vertices": 150}, {})
        job.write(result, str(tmp_path / "out.obj"))
        written = read_mesh(tmp_path / "out.obj").corner_uvs
        expected = transfer_attributes(data, result, fit=fit).corner_uvs
        other = transfer_attributes(data, result, fit=not fit).corner_uvs
        np.testing.assert_allclose(written, expected, atol=1e-6)
        assert np.abs(written - other).max() > 1e-3
