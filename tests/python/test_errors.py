"""Every error TopStoc raises on bad input is a TopStocError (a ValueError): the Python layer's
checks and the engine's (std::invalid_argument, mapped by the bindings) alike, so one
``except TopStocError`` catches them and code that catches ValueError keeps working."""

import numpy as np
import pytest

import meshgen
import topstoc
from topstoc.core import TopStocError, hausdorff, read_mesh


def test_engine_errors_are_topstoc_errors():
    vertices, triangles = meshgen.torus(12, 8)
    mesh = topstoc.Mesh(vertices, triangles)
    # a sample outside the mesh is refused by the engine itself (decimate.cpp)
    with pytest.raises(TopStocError, match="sample 0 is vertex 100000, outside"):
        mesh.decimate_with_samples(np.array([100_000, 1, 2], dtype=np.int32))

def test_binding_and_python_checks_are_topstoc_errors(tmp_path):
    vertices, triangles = meshgen.torus(12, 8)
    with pytest.raises(TopStocError, match="vertices"):   # the bindings' array checks
        topstoc.Mesh(vertices[:, :2], triangles)
    with pytest.raises(TopStocError):                      # the Python parameter checks
        topstoc.Mesh(vertices, triangles).decimate(ratio=2.0)
    with pytest.raises(TopStocError):                      # a reader's error, from the engine
        bad = tmp_path / "bad.off"
        bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
        read_mesh(str(bad))
    with pytest.raises(TopStocError):
        hausdorff((vertices, triangles), (vertices, triangles), step=-1.0)
    assert issubclass(TopStocError, ValueError)
