"""Numeric parameters of the public API (addon/core/support/params.py): NumPy scalars accepted like
Python numbers, booleans refused, ranges checked before any conversion, messages that name
the parameter, its range and the value."""

import math
import pathlib

import numpy as np
import pytest

import topstoc
from topstoc.core.support import params
from topstoc.core.api.io import read_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


@pytest.fixture(scope="module")
def mesh():
    # A closed torus-like test mesh small enough to decimate many times.
    data = read_mesh(DATA / "genus_positive" / "cgal_torus_quad.off")
    return topstoc.Mesh(data.vertices, data.triangles)


# --- the checker itself --------------------------------------------------------------------------

@pytest.mark.parametrize("value", [3, np.int8(3), np.int64(3), np.uint64(3)])
def test_integer_accepts_python_and_numpy_integers(value):
    assert params.integer("n", value, 0, 10) == 3 and type(params.integer("n", value)) is int


@pytest.mark.parametrize("value", [True, np.bool_(False), 3.0, np.float32(3), "3", None, [3]])
def test_integer_refuses_everything_else(value):
    with pytest.raises(ValueError, match="n must be an integer, got"):
        params.integer("n", value)


def test_integer_range_is_checked_on_the_exact_value():
    assert params.integer("seed", 2**64 - 1, 0, 2**64 - 1) == 2**64 - 1
    with pytest.raises(ValueError, match=r"seed must lie in \[0, 18446744073709551615\], got 18446744073709551616"):
        params.integer("seed", 2**64, 0, 2**64 - 1)
    with pytest.raises(ValueError, match=r"got -1 \(int64\)"):
        params.integer("seed", np.int64(-1), 0)


@pytest.mark.parametrize("value", [0.5, np.float32(0.5), np.float16(0.5), np.float64(0.5)])
def test_number_accepts_numpy_floats(value):
    assert params.number("ratio", value, 0, 1, low_open=True) == 0.5


@pytest.mark.parametrize("value, message", [
    (True, "must be a number, got True"), (np.bool_(True), "must be a number"),
    (float("nan"), r"must lie in \(0, 1\], got nan"), (0, r"must lie in \(0, 1\], got 0"),
    (np.float32(1.5), r"must lie in \(0, 1\], got 1.5 \(float32\)"), ("0.5", "must be a number"),
    (complex(0.5, 0), "must be a number"),
])
def test_number_refusals_name_range_and_value(value, message):
    with pytest.raises(ValueError, match=f"ratio {message}"):
        params.number("ratio", value, 0, 1, low_open=True)


def test_number_infinity_and_huge_integers():
    with pytest.raises(ValueError, match=r"step must lie in \(0, inf\), got inf"):
        params.number("step", math.inf, 0, low_open=True)
    assert params.number("limit", math.inf, 0, finite=False) == math.inf
    with pytest.raises(ValueError, match="step is too large"):
        params.number("step", 10**400, 0)


# --- the public API ------------------------------------------------------------------------------

def test_seed_out_of_range_is_a_clear_error(mesh):
    with pytest.raises(ValueError, match=r"seed must lie in \[0, 18446744073709551615\], got 18446744073709551616"):
        mesh.decimate(ratio=0.5, seed=2**64)
    # The largest seed works and is deterministic.
    a = mesh.decimate(ratio=0.5, seed=2**64 - 1)
    b = mesh.decimate(ratio=0.5, seed=np.uint64(2**64 - 1))
    np.testing.assert_array_equal(a.triangles, b.triangles)


def test_numpy_ratio_gives_the_same_result_as_python_float(mesh):
    expected = mesh.decimate(ratio=0.5, seed=3)
    for ratio in (np.float32(0.5), np.float64(0.5)):
        got = mesh.decimate(ratio=ratio, seed=np.int32(3))
        np.testing.assert_array_equal(got.triangles, expected.triangles)
        np.testing.assert_array_equal(got.vertices, expected.vertices)


def test_numpy_counts_are_accepted(mesh):
    n = mesh.decimate(vertices=np.int64(12)).num_vertices
    assert n == mesh.decimate(vertices=12).num_vertices
    t = mesh.decimate(triangles=np.uint32(30)).num_triangles
    assert t == mesh.decimate(triangles=30).num_triangles


@pytest.mark.parametrize("options, message", [
    (dict(ratio=True), "ratio must be a number, got True"),
    (dict(ratio=np.bool_(True)), "ratio must be a number"),
    (dict(ratio=0.0), r"ratio must lie in \(0, 1\]"),
    (dict(ratio=float("nan")), r"ratio must lie in \(0, 1\], got nan"),
    (dict(vertices=True), "vertices must be an integer, got True"),
    (dict(vertices=10.0), "must be an integer, got 10.0"),
    (dict(vertices=10**30), r"vertex target 10{30} is outside \[1, 25\]"),
    (dict(triangles=np.int64(0)), r"triangle target 0 is outside \[1, 50\]"),
    (dict(triangles=False), "triangles must be an integer, got False"),
    (dict(ratio=0.5, seed=-1), r"seed must lie in \[0,"),
    (dict(ratio=0.5, seed=1.0), "seed must be an integer"),
    (dict(ratio=0.5, adaptivity=np.float32(1.5)), r"adaptivity must lie in \[0, 1\], got 1.5 \(float32\)"),
    (dict(ratio=0.5, flat_floor=-0.1), r"flat_floor must lie in \[0, 1\]"),
    (dict(ratio=0.5, feature_angle=4.0), r"feature_angle \(radians\) must lie in \[0, 3.14159"),
    (dict(ratio=0.5, density_rings=2**40), r"density_rings must lie in \[0, 2147483647\]"),
    (dict(ratio=0.5, density_ratio=0.5), r"density_ratio must lie in \[1, inf\)"),
    (dict(ratio=0.5, density_epsilon=math.inf), "density_epsilon must lie in"),
    (dict(ratio=0.5, max_repair_rounds=-1), r"max_repair_rounds must lie in \[0,"),
    (dict(ratio=0.5, refine=0.5), "refine must be 0 .off. or a factor of at least 1"),
    (dict(ratio=0.5, refine=math.inf), r"refine must be 0 \(off\) or a factor of at least 1, got inf"),
    (dict(ratio=0.5, refine=np.float32(2)), None),
    (dict(max_error=-1.0), r"max_error must lie in \[0, inf\)"),
    (dict(max_error=True), "max_error must be a number"),
])
def test_decimate_parameter_errors(mesh, options, message):
    if message is None:  # accepted
        assert mesh.decimate(**options).num_vertices > 0
        return
    with pytest.raises(ValueError, match=message):
        mesh.decimate(**options)


def test_hausdorff_tiny_step_is_refused_with_a_readable_count(mesh):
    v, t = mesh.vertices, mesh.triangles
    with pytest.raises(ValueError) as caught:
        topstoc.hausdorff((v, t), (v, t), step=1e-9)
    message = str(caught.value)
    assert "sample step 1e-09 would need" in message and "use a larger step" in message
    assert "-9223372036854775808" not in message
    # The count in the message is the real order of magnitude (area / step^2, well above 1e12).
    count = float(message.split("would need ")[1].split(" samples")[0])
    assert count > 1e12


@pytest.mark.parametrize("options, message", [
    (dict(step=0.0), r"step must lie in \(0, inf\)"), (dict(step=True), "step must be a number"),
    (dict(step=float("nan")), "step must lie in"), (dict(samples=0), r"samples must lie in \[1,"),
    (dict(samples=1.5), "samples must be an integer"), (dict(percentile=101), r"percentile .* must lie in \[0, 100\]"),
    (dict(percentile=True), "percentile .* must be a number"),
])
def test_hausdorff_parameter_errors(mesh, options, message):
    with pytest.raises(ValueError, match=message):
        topstoc.hausdorff((mesh.vertices, mesh.triangles), (mesh.vertices, mesh.triangles), **options)


def test_hausdorff_accepts_numpy_scalars(mesh):
    surface = (mesh.vertices, mesh.triangles)
    a = topstoc.hausdorff(surface, surface, samples=np.int64(2000), percentile=np.float32(90))
    b = topstoc.hausdorff(surface, surface, samples=2000, percentile=90.0)
    assert a.step == b.step and a.symmetric == b.symmetric and a.symmetric.max < 1e-12


def test_loops_and_edit_parameter_errors(mesh):
    with pytest.raises(ValueError, match=r"seed must lie in \[0,"):
        topstoc.handle_tunnel_loops(mesh, seed=2**64)
    with pytest.raises(ValueError, match="coarse_vertices must be an integer, got True"):
        topstoc.handle_tunnel_loops(mesh, coarse_vertices=True)
    from topstoc.core.api import edit
    with pytest.raises(ValueError, match=r"max_edges must lie in \[3,"):
        edit.fill_holes(mesh.vertices, mesh.triangles, max_edges=2)
    with pytest.raises(ValueError, match=r"max_dp_corners must lie in \[3,"):
        edit.fill_holes(mesh.vertices, mesh.triangles, max_dp_corners=np.int64(1))
    with pytest.raises(ValueError, match=r"separation must lie in \[0, 1\), got 1.0"):
        edit.remove_handle(mesh.vertices, mesh.triangles, [0, 1, 2], separation=1.0)


def test_sampling_probabilities_rate(mesh):
    from topstoc.core.api.decimate import sampling_probabilities
    p32 = sampling_probabilities(mesh, np.float32(0.25))
    np.testing.assert_array_equal(p32, sampling_probabilities(mesh, 0.25))
    with pytest.raises(ValueError, match="rate must be a number, got True"):
        sampling_probabilities(mesh, True)


# --- View and Box guidance (decimate.View / decimate.Box) ----------------------------------------

@pytest.mark.parametrize("fields, message", [
    (dict(eye=[0, 0]), r"view eye must be 3 numbers, got shape \(2,\)"),
    (dict(eye=[0, 0, float("nan")]), r"view eye must hold finite numbers, got nan at \[2\]"),
    (dict(eye=[[0, 0], [1]]), "view eye must be 3 numbers, got"),
    (dict(eye="abc"), "view eye must be 3 numbers, got <U3 values"),
    (dict(direction=[0, 0, 0]), "view direction must not be zero"),
    (dict(direction=[True, False, True]), "view direction must be 3 numbers, got booleans"),
    (dict(direction=[0, np.inf, 1]), r"view direction must hold finite numbers, got inf at \[1\]"),
    (dict(eye=[0, 0, 5], direction=[0, 0, 1]), "exactly one of eye .* or direction"),
    (dict(), "exactly one of eye .* or direction"),
    (dict(eye=[0, 0, 5], back_ratio=True), "view back_ratio must be a number, got True"),
    (dict(eye=[0, 0, 5], back_ratio=1.5), r"view back_ratio must lie in \[0, 1\], got 1.5"),
    (dict(eye=[0, 0, 5], silhouette_angle=4), r"view silhouette_angle \(radians\) must lie in \[0, 3.14159"),
    (dict(eye=[0, 0, 5], silhouette_falloff=float("inf")), r"view silhouette_falloff must lie in \[0, inf\), got inf"),
    (dict(eye=[0, 0, 5], silhouette_falloff=-0.1), r"view silhouette_falloff must lie in \[0, inf\)"),
    (dict(eye=[0, 0, 5], outside_probability=np.float32(1.5)), r"outside_probability must lie in \[0, 1\], got 1.5 \(float32\)"),
    (dict(eye=[0, 0, 5], view_projection=np.eye(3)), r"view view_projection must be a 4 x 4 matrix, got shape \(3, 3\)"),
    (dict(eye=[0, 0, 5], view_projection=np.full((4, 4), np.nan)), r"view_projection must hold finite numbers, got nan at \[0, 0\]"),
])
def test_view_fields_are_checked(fields, message):
    with pytest.raises(topstoc.TopStocError, match=message):
        topstoc.View(**fields)


def test_view_accepts_numpy_numbers_and_is_checked_again_where_used(mesh):
    view = topstoc.View(eye=np.float32([0, 0, 5]), back_ratio=np.float32(0.5), silhouette_angle=np.float64(0.3))
    engine = view.as_engine()
    assert engine["back_ratio"] == 0.5 and engine["eye"].dtype == np.float64 and engine["eye"].shape == (3,)
    view.back_ratio = 2.0  # changed after it was made: refused where the decimation uses it
    with pytest.raises(topstoc.TopStocError, match=r"view back_ratio must lie in \[0, 1\], got 2.0"):
        mesh.decimate(ratio=0.5, view=view)
    with pytest.raises(topstoc.TopStocError, match="view must be a topstoc View, got dict"):
        mesh.decimate(ratio=0.5, view={"eye": [0, 0, 5]})


@pytest.mark.parametrize("make, message", [
    (lambda: topstoc.Box(np.eye(4), 2.0), r"box value must lie in \[-1, 1\], got 2.0"),
    (lambda: topstoc.Box(np.eye(4), float("nan")), r"box value must lie in \[-1, 1\], got nan"),
    (lambda: topstoc.Box(np.eye(4), True), "box value must be a number, got True"),
    (lambda: topstoc.Box(np.eye(3), 0.5), r"box world_to_box must be a 4 x 4 matrix, got shape \(3, 3\)"),
    (lambda: topstoc.Box(np.diag([1, 1, np.inf, 1]), 0.5), r"world_to_box must hold finite numbers, got inf at \[2, 2\]"),
    (lambda: topstoc.Box.from_center_size([0, 0], [1, 1, 1], 0.5), r"box center must be 3 numbers, got shape \(2,\)"),
    (lambda: topstoc.Box.from_center_size([0, 0, 0], [1, np.nan, 1], 0.5), r"box half_size must hold finite numbers, got nan at \[1\]"),
    (lambda: topstoc.Box.from_center_size([0, 0, 0], [1, 0, 1], 0.5), r"box half sizes must be positive, got \[1.0, 0.0, 1.0\]"),
])
def test_box_fields_are_checked(make, message):
    with pytest.raises(topstoc.TopStocError, match=message):
        make()


def test_boxes_must_be_boxes(mesh):
    box = topstoc.Box.from_center_size([0, 0, 0], [1, 1, 1], np.float32(0.5))
    assert box.as_engine()[1] == 0.5
    with pytest.raises(topstoc.TopStocError, match="boxes must be a list of topstoc Box, got Box"):
        mesh.decimate(ratio=0.5, boxes=box)
    with pytest.raises(topstoc.TopStocError, match="boxes\\[1\\] must be a topstoc Box, got int"):
        mesh.decimate(ratio=0.5, boxes=[box, 3])
    box.value = -3  # changed after it was made
    with pytest.raises(topstoc.TopStocError, match=r"box value must lie in \[-1, 1\], got -3"):
        mesh.decimate(ratio=0.5, boxes=(box,))


def test_parameter_errors_are_topstoc_errors():
    with pytest.raises(topstoc.TopStocError):
        params.number("ratio", True, 0, 1)
    assert issubclass(params.ParameterError, ValueError)


# --- guidance (one number per vertex) ------------------------------------------------------------

def test_guidance_refuses_what_is_not_real_numbers(mesh):
    """Strings and complex numbers were converted by NumPy (complex silently dropping the
    imaginary part) where every other array parameter refuses them."""
    n = len(mesh.vertices)
    for bad, what in ((["0.5"] * n, "<U3 values"), (np.full(n, 0.5 + 0.5j), "complex128 values"),
                      (np.full(n, 0.5 + 0j), "complex128 values"), ([None] * n, "object values")):
        expected = f"guidance must be one number in .-1, 1. per vertex, got {what}"
        with pytest.raises(params.ParameterError, match=expected):
            mesh.decimate(ratio=0.5, guidance=bad)
    u = np.zeros(n)
    u[:10] = 1
    kept = mesh.decimate(mode="fast", ratio=0.5, seed=3, guidance=u)
    for same in (u.astype(np.float32), u.astype(int), u.astype(bool), u.tolist()):  # numbers stay accepted
        np.testing.assert_array_equal(mesh.decimate(mode="fast", ratio=0.5, seed=3, guidance=same).vertices,
                                      kept.vertices)
