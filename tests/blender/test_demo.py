"""The README's demo command writes a decimated .blend, .obj and a PNG a person can look at."""

import shutil
import struct
import subprocess

import pytest

from conftest import PACKAGE

BLENDER = shutil.which("blender")


@pytest.mark.skipif(BLENDER is None, reason="no blender executable on PATH")
def test_demo_writes_blend_obj_png(ts, tmp_path):
    done = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                           str(PACKAGE / "demo.py"), "--", "--output", str(tmp_path), "--samples", "1",
                           "--resolution", "20"], capture_output=True, text=True, timeout=600)
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
