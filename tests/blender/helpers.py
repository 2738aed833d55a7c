"""Helpers for the Blender tests: build objects from numpy arrays, read them back."""

import threading
import time
from typing import NamedTuple

import bpy
import numpy as np


def make_object(name, vertices, faces, collection=None):
    """A mesh object from vertices (n, 3) and faces (list of vertex-id sequences), selected and active."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(map(float, v)) for v in vertices], [], [tuple(map(int, f)) for f in faces])
    mesh.update()
    drop_mistyped_edge_selection(mesh)
    obj = bpy.data.objects.new(name, mesh)
    (collection or bpy.context.scene.collection).objects.link(obj)
    select_only(obj)
    return obj


def drop_mistyped_edge_selection(mesh):
    """Blender 5.0.x's edge pass (from_pydata) types ``.select_edge`` INT32_2D, and a test writing
    ``MeshEdge.select`` would then crash Blender: remove that layer as a script would have to.
    (The add-on's own guard, edge_flags.mistyped_edge_flags, is tested on unrepaired meshes.)"""
    broken = mesh.attributes.get(".select_edge")
    if broken is not None and broken.data_type != "BOOLEAN":
        mesh.attributes.remove(broken)


def select_only(obj):
    for other in bpy.context.scene.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def positions(mesh):
    co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def polygons(mesh):
    """List of vertex-id tuples per polygon."""
    return [tuple(p.vertices) for p in mesh.polygons]


def kept_ids(source_mesh, output_mesh):
    """Input vertex id of every output vertex, matched by exact position (subsample placement)."""
    lookup = {tuple(p): i for i, p in enumerate(positions(source_mesh).tolist())}
    return np.array([lookup[tuple(p)] for p in positions(output_mesh).tolist()])


def snapshot(mesh):
    """Everything a test needs to prove a mesh unchanged."""
    data = {"co": positions(mesh).tolist(), "polygons": polygons(mesh),
            "materials": [p.material_index for p in mesh.polygons],
            "uv": {uv.name: [tuple(d.uv) for d in uv.data] for uv in mesh.uv_layers},
            "attributes": sorted((a.name, a.domain, a.data_type) for a in mesh.attributes)}
    return data


def vertex_areas(vertices, triangles):
    """One third of the incident triangle areas per vertex."""
    v = np.asarray(vertices, dtype=float)
    t = np.asarray(triangles)
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    out = np.zeros(len(v))
    np.add.at(out, t.ravel(), np.repeat(area / 3, 3))
    return out


class Params:
    """A DecimationParameters holder for calling the pipeline directly."""

    def __init__(self, **kw):
        self.target_mode = "RATIO"
        self.ratio = 0.1
        self.vertices = 100
        self.triangles = 200
        self.max_error = 1.0
        self.max_error_relative = True
        self.seed = 0
        self.adaptivity = 0.5
        self.density = "off"
        self.placement, self.refine = "subsample", 0
        self.quality = "FAST"  # exact input positions; tests that want Quality say so
        self.output = "NEW_OBJECT"
        for key, value in kw.items():
            setattr(self, key, value)


def wait_for(condition, seconds=30.0):
    """Polls ``condition`` every 5 ms for up to ``seconds``; True as soon as it holds."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        if condition():
            return True
        time.sleep(0.005)
    return condition()


class EngineCall(NamedTuple):
    mode: str
    target: object
    draft: bool
    thread: str
    cancel: object = None  # the CancelFlag it was given (a speculation), else None


class EngineCalls:
    """Wraps pipeline.run_engine: records each call (EngineCall); while ``gate`` is clear, calls
    for which ``hold(job)`` is true wait for it (``held`` is set when one does)."""

    def __init__(self, monkeypatch, pipeline, hold=lambda job: job.mode == "quality"):
        self.calls = []
        self.gate, self.held = threading.Event(), threading.Event()
        self.gate.set()
        original = pipeline.run_engine

        def run_engine(mesh, job, progress=None, cancel=None):
            self.calls.append(EngineCall(job.mode, job.target, bool(job.draft), threading.current_thread().name,
                                         cancel))
            if hold(job) and not self.gate.is_set():
                self.held.set()
                self.gate.wait(30)
            return original(mesh, job, progress, cancel)

        monkeypatch.setattr(pipeline, "run_engine", run_engine)

    def count(self, mode=None, draft=None):
        return sum(1 for call in self.calls
                   if (mode is None or call.mode == mode) and (draft is None or call.draft == draft))

    def kinds(self, start=0):
        """(mode, draft) of each call from ``start`` on."""
        return [(call.mode, call.draft) for call in self.calls[start:]]


def pixels_of(image) -> np.ndarray:
    """An image's pixels as one float32 array."""
    out = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(out)
    return out


def reimported(ts, path, images: bool = False):
    """Removes every object (and every image, with ``images``), imports ``path`` through the
    add-on's scene_files and returns the one mesh object it brought."""
    import importlib

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    for image in list(bpy.data.images) if images else ():
        bpy.data.images.remove(image)
    importlib.import_module(f"{ts.__name__}.blender.io.scene_files").import_file(str(path))
    [obj] = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    return obj
