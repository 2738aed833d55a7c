"""A library of small assets made at run time for the batch tests and bench_batch.py: synthetic
meshes and the test meshes, at several subdivision levels, under different transforms, written
as OBJ / PLY / OFF (numpy and topstoc.core.api.io only)."""

import pathlib

import numpy as np

import meshgen

DATA = pathlib.Path(__file__).resolve().parent / "data"
BASES = ("icosphere", "torus", "fandisk", "elephant", "knot1")
FORMATS = ("obj", "ply", "off")


def _base(name: str):
    if name == "icosphere":
        return meshgen.icosphere(2)
    if name == "torus":
        return meshgen.torus(24, 12)
    from topstoc.core.api.io import read_mesh

    path = {"fandisk": DATA / "genus0" / "cgal_fandisk.off", "elephant": DATA / "genus_positive" / "cgal_elephant.off",
            "knot1": DATA / "genus_positive" / "cgal_knot1.off"}[name]
    data = read_mesh(path)
    return data.vertices, data.triangles


def _rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def make_assets(folder, count: int, *, seed: int = 0, levels=(0, 1), bases=BASES) -> list:
    """Writes ``count`` assets into ``folder``; returns their paths (sorted by name)."""
    from topstoc.core.api.io import MeshData, write_mesh

    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    cache = {}
    paths = []
    for i in range(count):
        base = bases[i % len(bases)]
        level = levels[(i // len(bases)) % len(levels)]
        if (base, level) not in cache:
            v, t = _base(base)
            cache[(base, level)] = meshgen.subdivide(v, t, level) if level else (v, t)
        v, t = cache[(base, level)]
        v = (np.asarray(v) @ _rotation(rng).T) * rng.uniform(0.5, 20.0) + rng.uniform(-50, 50, size=3)
        path = folder / f"asset{i:04d}_{base}_s{level}.{FORMATS[i % len(FORMATS)]}"
        write_mesh(path, MeshData(vertices=v, triangles=t))
        paths.append(path)
    return sorted(paths)
