"""Handle and tunnel loops on every generated family of tests/loop_families.py (issue 39):
perforated plates (voxel and elliptic holes), Swiss-cheese balls, strut lattices, Schwarz-P
and gyroid surfaces, knotted and linked tubes. Each result is checked as test_loops checks the
shipped meshes: GUDHI Betti numbers of the inside and outside with the loops coned off, simple
edge cycles, lengths recomputed here; the genus against the Euler characteristic counted here.
"""

import numpy as np
import pytest

import homology_check as hc
import loop_families
import meshgen
import reference
import topstoc
from test_loops import check_component

pytestmark = pytest.mark.skipif(hc.gudhi is None, reason="python3-gudhi is not installed")

# Small members of each family (a few thousand triangles: the GUDHI checks are the cost).
SMALL = {
    "voxel plate, 30 random holes": lambda: loop_families.random_slab(30, seed=5),
    "elliptic plate, 6 holes": lambda: loop_families.perforated_plate(6, seed=2),
    "swiss cheese, 6 tunnels": lambda: loop_families.swiss_cheese(6, seed=3, resolution=7),
    "strut lattice 2": lambda: loop_families.strut_lattice(2, resolution=4),
    "schwarz-p 2": lambda: loop_families.schwarz_p(2, resolution=5),
    "gyroid 1.5": lambda: loop_families.gyroid(1.5, resolution=6),
    "trefoil": lambda: loop_families.torus_knot(2, 3, samples=120, around=8),
    "linked rings 3": lambda: loop_families.linked_rings(3, samples=24, around=8),
}


def euler_genus(vertices, triangles):
    """Genus of each component from V - E + F counted here (closed orientable components)."""
    label = reference.components(len(vertices), triangles)
    edges = np.unique(np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), 1), axis=0)
    genus = {}
    for c in np.unique(label[triangles[:, 0]]):
        v = len(np.unique(triangles[label[triangles[:, 0]] == c]))
        e = int((label[edges[:, 0]] == c).sum())
        f = int((label[triangles[:, 0]] == c).sum())
        genus[int(c)] = (2 - (v - e + f)) // 2
    return genus


@pytest.mark.parametrize("name", list(SMALL))
@pytest.mark.heavy
def test_each_family_gets_a_verified_basis(name):
    vertices, triangles = SMALL[name]()
    result = topstoc.handle_tunnel_loops(vertices, triangles)
    expected = sorted(g for g in euler_genus(vertices, triangles).values())
    assert sorted(c.genus for c in result.components) == expected
    assert sum(expected) >= 1
    for component in result.components:
        if component.genus:
            check_component(vertices, triangles, component)


def test_families_are_deterministic_and_closed():
    """Same seed, same mesh; every directed edge once (closed, consistently oriented)."""
    for name, make in SMALL.items():
        (v1, t1), (v2, t2) = make(), make()
        assert np.array_equal(v1, v2) and np.array_equal(t1, t2), name
        directed = np.concatenate([t1[:, [0, 1]], t1[:, [1, 2]], t1[:, [2, 0]]])
        assert len(np.unique(directed, axis=0)) == len(directed), name
        assert len(np.unique(np.sort(directed, 1), axis=0)) * 2 == len(directed), name


def test_coarse_route_on_a_family_member():
    """The coarse route (decimate, loops on the coarse surface, mapped back) on a plate of
    irregular holes gives loops that pass the same checks on the full mesh."""
    vertices, triangles = loop_families.random_slab(12, seed=9)
    vertices, triangles = meshgen.subdivide(vertices, triangles, 1)
    (component,) = topstoc.handle_tunnel_loops(vertices, triangles, coarse_vertices=600).components
    assert component.route == "coarse" and component.genus == 12
    check_component(vertices, triangles, component)
