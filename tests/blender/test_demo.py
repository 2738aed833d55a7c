"""The README's demo command writes a decimated .blend, .obj and a PNG a person can look at."""

import struct

from conftest import PACKAGE
from launch import background


def test_demo_writes_blend_obj_png(ts, tmp_path):
    done = background(PACKAGE / "demo.py", "--output", tmp_path, "--samples", 1, "--resolution", 20,
                      timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    stem = tmp_path / "duck_via_assimp_topstoc"
    png = (stem.with_suffix(".png")).read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png[16:24])
    assert (width, height) == (240, 112)
    obj = stem.with_suffix(".obj").read_text().splitlines()
    vertices = sum(line.startswith("v ") for line in obj)
    faces = sum(line.startswith("f ") for line in obj)
    assert 0 < vertices < 2108 and faces > 0           # decimated from the duck's 2108 vertices
    assert stem.with_suffix(".blend").stat().st_size > 0
    assert "TopStoc demo:" in done.stdout and "painted 'TopStoc Guidance'" in done.stdout
    assert "TopStoc demo:" in (tmp_path / "summary.txt").read_text()
