"""The README's demo command writes a decimated .blend, .obj and a PNG a person can look at."""

import struct

import bpy

from conftest import DATA, PACKAGE
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
    assert "default settings: Quality" in done.stdout
    assert "TopStoc demo:" in (tmp_path / "summary.txt").read_text()


def test_demo_shows_the_quality_result(ts, tmp_path):
    """The README's main command (scripts/demo.sh: the dragon at 5 %) runs the operator at its
    defaults, Quality, which places vertices anew; the fast mode keeps input vertices where they
    are. So few of the result's vertices are input positions (7 of 500 when written; all of them
    in the fast mode the demo ran before). The saved scene's two meshes are compared in their own
    coordinates."""
    done = background(PACKAGE / "demo.py", "--input", DATA / "genus0" / "cgal_ChineseDragon-10kv.off",
                      "--ratio", 0.05, "--output", tmp_path, "--samples", 1, "--resolution", 10, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    with bpy.data.libraries.load(str(tmp_path / "cgal_ChineseDragon-10kv_topstoc.blend")) as (source, target):
        target.meshes = list(source.meshes)
    try:
        original, result = sorted(target.meshes, key=lambda mesh: len(mesh.vertices), reverse=True)
        assert (len(original.vertices), len(result.vertices)) == (10000, 500)
        inputs = {tuple(v.co) for v in original.vertices}
        kept = sum(tuple(v.co) in inputs for v in result.vertices)
        assert kept < len(result.vertices) / 10, f"{kept} of {len(result.vertices)} vertices are input vertices"
    finally:
        for mesh in target.meshes:
            bpy.data.meshes.remove(mesh)
