"""Topology on every mesh under ../shared/meshes (issue 4): Betti numbers equal GUDHI's and the
genus of each component equals ../shared/tools/meshstat.py. Skips without ../shared."""

import importlib.util
import os

import numpy as np
import pytest

from conftest import SHARED_MESHES
from topstoc.core.api.topology import generators, topology

pytest.importorskip("gudhi")
io = pytest.importorskip("topstoc.core.api.io")
from topology_checks import check_generators, gudhi_betti  # noqa: E402

MESH_SUFFIXES = (".off", ".obj", ".ply", ".stl", ".gz", ".bz2")
FILES = sorted(str(p.relative_to(SHARED_MESHES)) for p in SHARED_MESHES.rglob("*")
               if p.is_file() and p.name.endswith(MESH_SUFFIXES)) if SHARED_MESHES.is_dir() else []
# The references need 10-40 s each on the million-triangle meshes under big/ (GUDHI, meshstat):
# run them with TOPSTOC_BIG_TESTS=1 (the topology benchmark compares Betti numbers there too).
BIG = os.environ.get("TOPSTOC_BIG_TESTS") == "1"


def skip_big(name):
    if name.startswith("big/") and not BIG:
        pytest.skip("million-triangle mesh: set TOPSTOC_BIG_TESTS=1 to compare it with GUDHI and meshstat")


def load_meshstat():
    path = SHARED_MESHES.parent / "tools" / "meshstat.py"
    if not path.exists():
        pytest.skip("../shared/tools/meshstat.py is not available")
    spec = importlib.util.spec_from_file_location("meshstat", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def read_or_skip(path):
    try:
        return io.read_mesh(str(path))
    except ValueError as error:  # e.g. openscad_unparseable.stl: not a mesh
        pytest.skip(f"{path.name} does not load: {error}")


@pytest.mark.parametrize("name", FILES)
def test_betti_numbers_equal_gudhi(shared_meshes, name):
    skip_big(name)
    data = read_or_skip(shared_meshes / name)
    info = topology(data.vertices, data.triangles)
    assert info.betti == gudhi_betti(len(data.vertices), data.triangles)


@pytest.mark.parametrize("name", FILES)
def test_genus_per_component_equals_meshstat(shared_meshes, name):
    skip_big(name)
    meshstat = load_meshstat()
    data = read_or_skip(shared_meshes / name)
    raw = meshstat.load(str(shared_meshes / name))
    stats = meshstat.analyse(raw, weld=meshstat.base_ext(name) == "stl")
    surfaces = [c for c in topology(data.vertices, data.triangles).components if c.kind == "surface"]
    assert len(surfaces) == stats["components"]
    # meshstat lists (faces, euler, boundary loops, manifold, genus) for the 12 largest components;
    # it counts polygons where we count triangles, so compare without the face count.
    undefined = lambda genus: -1 if genus is None else genus  # noqa: E731
    ours = sorted(((c.faces, c.euler, len(c.boundary_loops), c.manifold, undefined(c.genus)) for c in surfaces),
                  reverse=True)
    theirs = [(f, chi, loops, manifold, undefined(genus)) for f, chi, loops, manifold, genus in stats["comp_summary"]]
    if stats["duplicate_faces"] or stats["degenerate_faces_topo"]:
        # meshstat counts a repeated triangle twice (its edges then look interior) where the
        # simplicial complex has it once: euler and boundaries differ, genus must not.
        ours = [(x[0], None, None) + x[3:] for x in ours]
        theirs = [(x[0], None, None) + x[3:] for x in theirs]
    if len(surfaces) <= 12 or stats["polys"].keys() == {3}:
        assert sorted(x[1:] for x in ours[:len(theirs)]) == sorted(x[1:] for x in theirs)
    genus_sum = sum(c.genus for c in surfaces) if all(c.genus is not None for c in surfaces) else None
    assert genus_sum == stats["genus_sum"]


@pytest.mark.parametrize("name", [f for f in FILES if f.startswith("genus_positive/")])
def test_generators_on_genus_meshes(shared_meshes, name):
    data = read_or_skip(shared_meshes / name)
    info = topology(data.vertices, data.triangles)
    gens = generators(data.vertices, data.triangles)
    assert [(g.component, g.genus) for g in gens] == [(c.index, c.genus) for c in info.components]
    if len(data.triangles) <= 8000:  # the brute-force checks are quadratic in Python
        check_generators(data.vertices, data.triangles, gens, [(c.index, c.genus) for c in info.components])
    else:
        assert all(len(g.edges) == 2 * g.genus == len(g.loops) for g in gens)
        assert all(np.array_equal(loop[:2], edge) for g in gens for loop, edge in zip(g.loops, g.edges))
