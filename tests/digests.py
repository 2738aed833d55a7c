"""Digests of decimation outputs on every test mesh: run before and after a change that must
not alter results (a refactor, a speed-up) and compare the printed lines.

    PYTHONPATH=build/python python3 tests/digests.py > before.txt
"""

import hashlib
import pathlib
import sys

import numpy as np

import topstoc

DATA = pathlib.Path(__file__).resolve().parent / "data"
SETTINGS = [
    dict(ratio=0.1, seed=1),
    dict(ratio=0.02, seed=3),
    dict(ratio=0.1, seed=1, placement="filtered"),
    dict(ratio=0.05, seed=2, refine=4, placement="filtered"),
]


def digest(result) -> str:
    h = hashlib.sha256()
    for name in ("vertices", "triangles", "samples"):
        a = getattr(result, name, None)
        if a is not None:
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def main() -> None:
    for path in sorted(DATA.rglob("*")):
        if path.suffix not in (".off", ".obj", ".ply", ".stl", ".gz") or "nonmanifold" in str(path) or "regressions" in path.parts:
            continue
        data = topstoc.read_mesh(str(path))
        mesh = topstoc.Mesh(data.vertices, data.triangles)
        for s in SETTINGS:
            try:
                line = digest(mesh.decimate(**s))
            except Exception as e:  # an error is an outcome too: it must stay the same
                line = f"error {type(e).__name__}: {e}"
            print(f"{path.relative_to(DATA)} {s} {line}")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
