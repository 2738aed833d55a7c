"""``topstoc measure``: % of A's bounding-box diagonal by default, like the rest of TopStoc,
the meshes' own units with --absolute, and the directions explained. Run as a subprocess."""

import functools
import json
import pathlib

import numpy as np
import pytest

import cli
from topstoc.core import Mesh
from topstoc.core.api.io import MeshData, read_mesh, write_mesh

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
measure = functools.partial(cli.run, "measure", timeout=120)


def _rows(text: str) -> dict:
    """{'forward': [max, mean, rms, p95], ...} read from the printed table."""
    rows = {}
    for line in text.splitlines():
        words = line.split()
        if words and words[0] in ("forward", "backward", "symmetric") and len(words) > 4:
            rows[words[0]] = [float(w) for w in words[1:] if w != "%"]
    return rows


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    folder = tmp_path_factory.mktemp("measure")
    a = DATA / "genus_positive" / "cgal_eight.off"
    data = read_mesh(a)
    result = Mesh(data.vertices, data.triangles).decimate(ratio=0.3, seed=1, mode="fast")
    write_mesh(folder / "b.off", MeshData(vertices=result.vertices, triangles=result.triangles))
    return a, folder / "b.off"


def test_percent_by_default_absolute_on_request(pair):
    a, b = pair
    document = json.loads(measure(a, b, "--json", "--samples", 20000).stdout)
    assert document["units"] == "absolute"
    vertices = read_mesh(a).vertices
    diagonal = np.linalg.norm(vertices.max(0) - vertices.min(0))
    assert document["diagonal"] == pytest.approx(diagonal)
    keys = ("max", "mean", "rms", "percentile")
    for name in ("forward", "backward", "symmetric"):
        assert document[name]["max"] > 0
        for key in keys:
            assert document["percent_of_diagonal"][name][key] == pytest.approx(100 * document[name][key] / diagonal)

    default = measure(a, b, "--samples", 20000)
    assert default.returncode == 0 and default.stderr == ""
    assert "in % of A's bounding-box diagonal" in default.stdout
    rows = _rows(default.stdout)
    absolute = _rows(measure(a, b, "--samples", 20000, "--absolute").stdout)
    for name in ("forward", "backward", "symmetric"):
        expected = [100 * document[name][key] / diagonal for key in keys]
        assert rows[name] == pytest.approx(expected, rel=1e-3)
        assert absolute[name] == pytest.approx([document[name][key] for key in keys], rel=1e-3)
    # the printed percentages really are percent: the eight's error at 30 % lies between 0.1 % and 10 %
    assert 0.1 < rows["symmetric"][0] < 10


def test_directions_are_explained(pair):
    a, b = pair
    text = measure(a, b, "--samples", 20000).stdout
    assert "A (original)" in text and "B (approximation)" in text
    assert "forward:   A -> B, how far A's surface lies from B's" in text
    assert "backward:  B -> A, how far B's surface lies from A's" in text
    assert "symmetric: the larger of the two (the Hausdorff distance)" in text
    shown = cli.run("measure", "--help").stdout
    assert "--absolute" in shown and "Forward (A -> B)" in shown.replace("\n", " ").replace("  ", " ")
