"""Frame the active loop: a handle or tunnel loop of three to five edges is a few pixels at the
zoom that shows the whole object; this points the 3D view at it, looking through it."""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Vector

from ..analysis import topology as analysis
from .topology import _loop_ids, _LoopOperator, _mesh_object
from ..ui.overlay_data import positions
from . import polls

#: The view's distance in loop radii: the loop then fills about half of the view's height.
RADII = 4.0


def loop_view(points: np.ndarray, towards_viewer) -> tuple:
    """(centre, view distance, directions) that frame ``points`` (world space, (k, 3)): the
    directions to look from, best first: along the normal of their best-fit plane (through the
    loop) from the side of ``towards_viewer`` (a vector from the scene to the present view), the
    other side, then at 45 degrees to the plane, then the plane's own axes and the present
    direction."""
    centre = points.mean(axis=0)
    offsets = points - centre
    radius = float(np.linalg.norm(offsets, axis=1).max()) if len(points) else 0.0
    viewer = np.asarray(towards_viewer, dtype=np.float64)
    directions = []
    if len(points) >= 3:
        _u, singular, axes = np.linalg.svd(offsets, full_matrices=False)
        if singular[1] > 1e-9 * max(singular[0], 1e-300):  # not a straight run of points
            normal = axes[2] if np.dot(axes[2], viewer) >= 0 else -axes[2]
            # through the loop, then at 45 degrees to its plane (a loop round a thin tube is hidden
            # by the tube along its axis, and edge-on in its plane), then in its plane
            oblique = [(side * normal + sign * axis) / np.sqrt(2.0) for side in (1, -1)
                       for axis in (axes[0], axes[1]) for sign in (1, -1)]
            directions = [normal, -normal] + oblique + [axes[0], -axes[0], axes[1], -axes[1]]
    directions.append(viewer / max(np.linalg.norm(viewer), 1e-300))
    return centre, max(radius, 1e-6) * RADII, directions


def visible_share(obj, camera, points) -> float:
    """Share of ``points`` (world space) seen from ``camera`` past ``obj``'s own faces, and 0 when
    the camera is inside the object (the first face a ray meets is seen from behind)."""
    inverse = obj.matrix_world.inverted()
    eye = inverse @ Vector(camera)
    seen = 0
    for point in points:
        target = inverse @ Vector(point)
        ray = target - eye
        length = ray.length
        hit, location, normal, _index = obj.ray_cast(eye, ray.normalized(), distance=length)
        if hit and normal.dot(ray) > 0 and (location - eye).length < 0.999 * length:
            return 0.0  # the camera is inside the mesh
        if not hit or (location - target).length <= 1e-4 * max(length, 1e-12):
            seen += 1
    return seen / max(1, len(points))


class TOPSTOC_OT_frame_loop(_LoopOperator, bpy.types.Operator):
    """Point the view at the active loop, looking through it (small loops are invisible at the \
zoom that shows the whole object)"""

    bl_idname = "topstoc.frame_loop"
    bl_label = "Frame Loop"

    @classmethod
    def poll(cls, context):
        return polls.refuse(cls, polls.view_3d(context)) and super().poll(context)

    def execute(self, context):
        obj = _mesh_object(context)
        ids = _loop_ids(obj)
        co = positions(obj.data)
        if not len(ids) or ids.max() >= len(co) or not analysis.is_current(obj):
            self.report({"ERROR"}, "TopStoc: the mesh changed since the loops were found; press Find Loops")
            return {"CANCELLED"}
        world = np.asarray(obj.matrix_world, dtype=np.float64)
        points = co[ids].astype(np.float64) @ world[:3, :3].T + world[:3, 3]
        view = context.space_data.region_3d
        towards_viewer = np.asarray(view.view_rotation @ Vector((0.0, 0.0, 1.0)))
        centre, distance, directions = loop_view(points, towards_viewer)
        if obj.mode == "OBJECT":  # ray casts need the object's mesh, which Edit Mode holds elsewhere
            directions.sort(key=lambda d: -visible_share(obj, centre + distance * d, points))  # stable
        view.view_location = Vector(centre)
        view.view_distance = distance
        view.view_rotation = Vector(directions[0]).to_track_quat("Z", "Y")
        return {"FINISHED"}


CLASSES = (TOPSTOC_OT_frame_loop,)
