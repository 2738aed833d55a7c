"""Topology clean-up in one step: small handles, tunnels and holes (docs/design.md §4.6).

Scans, sculpts and CAD exports carry many tiny handles and holes. :func:`clean` removes every
handle or tunnel whose shortest loop is shorter than ``max_handle`` and fills every hole whose
border is shorter than ``max_hole``, with refined and faired patches, and touches nothing else:
a triangle away from a cut loop and a patch keeps its vertices and their positions bit for bit.

Per handle the cheaper of its two cuts is taken by loop length: cutting along the handle loop
cuts the handle off, cutting along the tunnel loop fills the tunnel; the shorter loop has the
shorter cut and, for the small defects this is for, the smaller patches (both are reported).
Handles are removed in rounds: a round computes the loops of the current surface
(topstoc.core.api.loops) and removes the shortest loops below the size that share no vertex with
one removed before in the round. The 2g handle and tunnel loops of a component are independent
in its homology, so disjoint ones do not separate the surface together, and each removal drops
the genus by one (remove_handle checks anyway that each cut leaves its component in one
piece, on the surface as it is then). After a round that removed anything the next round
recomputes the loops of what is left: a removal changes the shortest loops of the others (a
loop that depended on removed ones can now be the shortest of its handle, and below the size).
A removal runs on the loop's neighbourhood
(local_edit.py). Holes are filled first; a patch that would cross the surface is replaced by a
flat one or its hole left open and reported.

>>> result = clean(vertices, triangles, max_handle="1%", max_hole="1%")
>>> result.vertices, result.triangles, result.removed, result.left
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import List, Optional, Union

import numpy as np

from . import edit
from .edit import EditResult, Patch
from ..support.errors import TopStocError
from .local_edit import LocalEditor, through
from .mesh import as_vertices

#: Default size of a small handle or hole, as a fraction of the bounding box's diagonal.
DEFAULT_SIZE = "1%"

Size = Union[float, str, None]


@dataclass(frozen=True)
class Removed:
    """One thing the clean-up removed.

    ``kind`` is "handle" (cut along a handle loop), "tunnel" (cut along a tunnel loop) or
    "hole" (a border filled). ``loop_length`` is the loop's (or border's) length, ``edges`` its
    edge count, ``patch_area`` the area of the patches that closed it, ``patch_aspect`` their
    worst aspect ratio (R / 2r, 1 for an equilateral triangle). ``vertices`` are the loop's
    vertices in the input's ids (a vertex the clean-up created has none: -1). ``patch`` says
    how the patches were made: "faired" (refined and faired), "refined" (refined, flat) or
    "flat" (the border's vertices only), the first of these free of self-intersections; or
    "welded" for a hole closed by welding its border's twin vertices (a crack), without patch.
    """

    kind: str
    loop_length: float
    edges: int
    patch_area: float
    patch_aspect: float
    vertices: np.ndarray
    patch: str = "faired"

    def as_json(self) -> dict:
        return {"kind": self.kind, "loop_length": self.loop_length, "edges": self.edges,
                "patch_area": self.patch_area, "patch_aspect": self.patch_aspect, "patch": self.patch,
                "vertices": self.vertices.tolist()}


@dataclass(frozen=True)
class Left:
    """Something the clean-up left, and why.

    ``kind`` is "handle", "tunnel" or "hole" for a loop (``loop_length`` > 0) or "component"
    for a component whose loops are not defined (open, not manifold, not orientable).
    """

    kind: str
    loop_length: float
    reason: str
    vertices: np.ndarray

    def as_json(self) -> dict:
        return {"kind": self.kind, "loop_length": self.loop_length, "reason": self.reason,
                "vertices": self.vertices.tolist()}


@dataclass(frozen=True)
class CleanResult:
    """The cleaned mesh (``edit``: arrays and maps to the input, like any edit) and the report.

    ``seconds``: "holes" (filling), "handles" (removing, of which "loops" computing loops), "total".
    """

    edit: EditResult
    removed: List[Removed]
    left: List[Left]
    max_handle: float
    max_hole: float
    keep_largest: Optional[int]
    genus_before: int
    genus_after: int
    rounds: int
    seconds: dict = field(default_factory=dict)

    @property
    def vertices(self) -> np.ndarray:
        return self.edit.vertices

    @property
    def triangles(self) -> np.ndarray:
        return self.edit.triangles

    def count(self, kind: str) -> int:
        """How many of ``kind`` ("handle", "tunnel", "hole") were removed."""
        return sum(1 for item in self.removed if item.kind == kind)

    @property
    def patch_aspect(self) -> float:
        """Worst aspect ratio over every patch (1 without patches)."""
        return max([item.patch_aspect for item in self.removed], default=1.0)

    def as_json(self) -> dict:
        return {"max_handle": self.max_handle, "max_hole": self.max_hole, "keep_largest": self.keep_largest,
                "genus_before": self.genus_before, "genus_after": self.genus_after, "rounds": self.rounds,
                "handles_removed": self.count("handle") + self.count("tunnel"),
                "holes_filled": self.count("hole"), "patch_aspect": self.patch_aspect,
                "removed": [item.as_json() for item in self.removed],
                "left": [item.as_json() for item in self.left], "seconds": dict(self.seconds)}


def size_value(size: Size, diagonal: float, name: str) -> float:
    """A size given as a length (number) or as "P%" of the bounding box's diagonal."""
    if size is None:
        size = DEFAULT_SIZE
    if isinstance(size, str):
        text = size.strip()
        try:
            value = float(text[:-1]) * diagonal / 100 if text.endswith("%") else float(text)
        except ValueError:
            raise TopStocError(f"{name} must be a length or a percentage of the diagonal like '1%', "
                               f"got {size!r}") from None
    elif isinstance(size, (int, float, np.integer, np.floating)) and not isinstance(size, bool):
        value = float(size)
    else:
        raise TopStocError(f"{name} must be a length or a percentage like '1%', got {type(size).__name__}")
    if not value >= 0:
        raise TopStocError(f"{name} must be a length of 0 or more, got {size!r}")
    return value


def loop_length(vertices: np.ndarray, loop: np.ndarray) -> float:
    """Length of the closed polygon through ``loop``'s vertices."""
    p = vertices[np.asarray(loop, dtype=np.int64)]
    return float(np.linalg.norm(p - np.roll(p, -1, axis=0), axis=1).sum())


def patch_quality(vertices: np.ndarray, triangles: np.ndarray, patches: List[Patch]) -> tuple:
    """(area, worst aspect ratio R / 2r) over the patches' triangles (thesis eq. 4.2)."""
    rows = np.concatenate([np.arange(p.triangles.start, p.triangles.stop) for p in patches]) if patches else []
    if len(rows) == 0:
        return 0.0, 1.0
    q = vertices[triangles[rows].astype(np.int64)]
    e = np.stack([np.linalg.norm(q[:, 1] - q[:, 2], axis=1), np.linalg.norm(q[:, 2] - q[:, 0], axis=1),
                  np.linalg.norm(q[:, 0] - q[:, 1], axis=1)], axis=1)
    area = 0.5 * np.linalg.norm(np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]), axis=1)
    s = e.sum(axis=1) / 2
    denominator = 8 * (s - e[:, 0]) * (s - e[:, 1]) * (s - e[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        aspect = np.where(denominator > 0, e.prod(axis=1) / np.maximum(denominator, 1e-300), np.inf)
    return float(area.sum()), float(aspect.max())


def identity(vertices: np.ndarray, triangles: np.ndarray) -> EditResult:
    """The edit that changes nothing (the start of a chain of edits)."""
    n, m = len(vertices), len(triangles)
    return EditResult(vertices=vertices.copy(), triangles=np.array(triangles, dtype=np.int32).reshape(-1, 3),
                      vertex_source=np.arange(n, dtype=np.int32), face_source=np.arange(m, dtype=np.int32),
                      corner_source=np.arange(3 * m, dtype=np.int32).reshape(m, 3),
                      input_vertices=n, input_triangles=m)


def compose(first: EditResult, second: EditResult, tag: Optional[int] = None) -> EditResult:
    """``second`` (an edit of ``first``'s result) with its maps taken back to ``first``'s input.

    Cuts and fills keep every vertex and triangle id and append new ones, so ``first``'s patches
    keep their places; ``second``'s patches get ``hole=tag`` (their entry in the report), or
    keep theirs with None.
    """
    n = first.num_vertices
    if second.num_vertices < n or not np.array_equal(second.vertex_source[:n], np.arange(n)):
        raise TopStocError("internal: a clean-up step renumbered the vertices")
    patches = list(first.patches) + [p if tag is None else dataclasses.replace(p, hole=tag) for p in second.patches]
    return EditResult(vertices=second.vertices, triangles=second.triangles,
                      vertex_source=through(first.vertex_source, second.vertex_source),
                      face_source=through(first.face_source, second.face_source),
                      corner_source=through(first.corner_source.reshape(-1), second.corner_source),
                      input_vertices=first.input_vertices, input_triangles=first.input_triangles,
                      patches=patches)


def clean(vertices, triangles, *, max_handle: Size = None, max_hole: Size = None,
          keep_largest: Optional[int] = None, fair: bool = True, max_rounds: int = 64) -> CleanResult:
    """Removes small handles and tunnels and fills small holes; see the module's docstring.

    max_handle: a handle goes when its shortest loop is shorter: a length, or "P%" of the
    bounding box's diagonal (default "1%"); 0 removes none, ``float("inf")`` all.
    max_hole: a hole is filled when its border is shorter (same units; default "1%").
    keep_largest: keep at least this many handles over the whole mesh (the largest: each round
    takes the shortest loops first); with it and no max_handle, every other handle goes.
    fair: refine the patches to the surrounding edge length and fair them (else flat, coarse).
    max_rounds: bound on the rounds (``CleanResult.rounds`` counts those that removed something).
    """
    from .topology import topology  # imported here: clean is importable without topology's cost

    vertices = as_vertices(vertices)
    triangles = np.asarray(triangles)
    if triangles.ndim != 2 or triangles.shape[1] != 3:
        raise TopStocError(f"triangles must be shaped (m, 3), got {triangles.shape}")
    if keep_largest is not None and (isinstance(keep_largest, bool) or int(keep_largest) != keep_largest
                                     or keep_largest < 0):
        raise TopStocError(f"keep_largest must be a count of 0 or more, got {keep_largest!r}")
    diagonal = float(np.linalg.norm(np.ptp(vertices, axis=0))) if len(vertices) else 0.0
    if keep_largest is not None and max_handle is None:
        max_handle = float("inf")
    handle_size = size_value(max_handle, diagonal, "max_handle")
    hole_size = size_value(max_hole, diagonal, "max_hole")
    started = time.perf_counter()
    genus_before = _genus(topology(vertices, triangles))
    removed: List[Removed] = []
    left: List[Left] = []
    state = _fill_small_holes(vertices, triangles, hole_size, fair, removed, left)
    seconds = {"holes": time.perf_counter() - started}
    state, rounds = _remove_small_handles(state, handle_size, keep_largest, fair, max_rounds, removed,
                                                       left, seconds)
    seconds["handles"] = time.perf_counter() - started - seconds["holes"]
    genus_after = _genus(topology(state.vertices, state.triangles))
    seconds["total"] = time.perf_counter() - started
    return CleanResult(edit=state, removed=removed, left=left, max_handle=handle_size, max_hole=hole_size,
                       keep_largest=None if keep_largest is None else int(keep_largest),
                       genus_before=genus_before, genus_after=genus_after, rounds=rounds, seconds=seconds)


def _genus(info) -> int:
    return sum(c.genus or 0 for c in info.components if c.kind == "surface")


def _fill_small_holes(vertices, triangles, size: float, fair: bool, removed: list, left: list) -> EditResult:
    """Fills every fillable hole whose border is shorter than ``size``; reports the others.

    Patches that would cross the surface are not kept (fill_holes does not look): their holes
    are tried again with flat patches, then left open and reported."""
    holes = edit.boundary_loops(vertices, triangles)
    chosen = []
    for index, hole in enumerate(holes):
        length = loop_length(vertices, hole.vertices)
        if not hole.fillable:
            why = ("its border touches a non-manifold vertex" if hole.nonmanifold_vertex is not None
                   else "it borders a lone triangle")
            left.append(Left("hole", length, f"not fillable: {why}", hole.vertices.astype(np.int32)))
        elif length >= size:
            left.append(Left("hole", length, f"border {length:.6g} is not below the size {size:.6g}",
                             hole.vertices.astype(np.int32)))
        else:
            chosen.append(index)
    state = None  # None: the input, untouched
    for style in ("faired", "flat") if fair else ("flat",):
        if not chosen:
            break
        step, kept, chosen = _fill_without_crossings(vertices, triangles, state, holes, chosen, style)
        if kept:
            step = _tagged(step, kept, holes, vertices, style, removed)
            state = step if state is None else compose(state, step)
    for index in chosen:
        left.append(Left("hole", loop_length(vertices, holes[index].vertices),
                         "every patch tried crosses the surface", holes[index].vertices.astype(np.int32)))
    return identity(vertices, triangles) if state is None else state


def _fill_without_crossings(vertices, triangles, state: Optional[EditResult], holes: list, chosen: list,
                            style: str) -> tuple:
    """Fills the ``chosen`` holes, dropping (and filling again without) those whose patches cross
    the surface, a few times. Returns (the fill, the holes it filled, the holes left)."""
    dropped = []
    for _ in range(3):
        step = _fill(vertices, triangles, state, holes, chosen, style)
        bad = crossing_patches(step)
        if not bad:
            return step, chosen, dropped
        dropped += sorted(bad)
        chosen = [index for index in chosen if index not in bad]
        if not chosen:
            break
    return None, [], dropped + chosen


def _fill(vertices, triangles, state: Optional[EditResult], holes: list, chosen: list, style: str) -> EditResult:
    """The ``chosen`` holes filled, patches tagged with their index into ``holes``. On the input,
    a border through two vertices at one position (a pinch) is filled lobe by lobe, the twins
    welded (a crack whose sides coincide closes without a patch): the clean-up's one
    renumbering, done first so that later steps only append."""
    refine = style == "faired"
    if state is None:
        return edit.fill_holes(vertices, triangles, holes=chosen, refine=refine, fair=refine)
    ids = state.vertex_map()
    step = edit.fill_loops(state.vertices, state.triangles, [ids[holes[index].vertices] for index in chosen],
                           refine=refine, fair=refine)
    return dataclasses.replace(step, patches=[dataclasses.replace(p, hole=chosen[p.hole]) for p in step.patches])


def crossing_patches(result: EditResult) -> set:
    """The ``Patch.hole`` values of the patches that cross another triangle of ``result``.

    Only triangles whose bounding boxes meet a patch's box can cross it: those are tested
    (exact tests, topstoc.core.api.loops.self_intersections), not the whole mesh."""
    from .loops import self_intersections

    if not result.patches:
        return set()
    corners = result.vertices[result.triangles]
    low, high = corners.min(axis=1), corners.max(axis=1)
    order = np.argsort(low[:, 0], kind="stable")
    sorted_low = low[order, 0]
    reach = float((high[:, 0] - low[:, 0]).max())
    near = [np.arange(p.triangles.start, p.triangles.stop) for p in result.patches]
    for p in result.patches:
        box_low, box_high = low[p.triangles].min(axis=0), high[p.triangles].max(axis=0)
        span = order[np.searchsorted(sorted_low, box_low[0] - reach):np.searchsorted(sorted_low, box_high[0], "right")]
        near.append(span[np.all(high[span] >= box_low, axis=1) & np.all(low[span] <= box_high, axis=1)])
    rows = np.unique(np.concatenate(near))
    owner = np.full(result.num_triangles, -1)
    for p in result.patches:
        owner[p.triangles] = p.hole
    pairs = np.asarray(self_intersections(result.vertices, result.triangles[rows]), dtype=np.int64).reshape(-1)
    return set(owner[rows[pairs]].tolist()) - {-1}


def _tagged(filled: EditResult, chosen: list, holes: list, vertices, style: str, removed: list) -> EditResult:
    """``filled`` with a report entry per hole, its patches tagged with that entry. A hole with
    no patch was closed by welding its twin vertices."""
    by_hole = {}
    for patch in filled.patches:
        by_hole.setdefault(patch.hole, []).append(patch)
    patches = []
    for index in chosen:
        hole = holes[index]
        own = by_hole.get(index, [])
        area, aspect = patch_quality(filled.vertices, filled.triangles, own)
        tag = len(removed)
        removed.append(Removed("hole", loop_length(vertices, hole.vertices), len(hole), area, aspect,
                               hole.vertices.astype(np.int32), style if own else "welded"))
        patches += [dataclasses.replace(p, hole=tag) for p in own]
    return dataclasses.replace(filled, patches=patches)


def _remove_small_handles(state: EditResult, size: float, keep_largest: Optional[int], fair: bool,
                          max_rounds: int, removed: list, left: list, seconds: dict) -> tuple:
    """Rounds of loop computation and removal (module docstring); returns (state, rounds).
    Adds the time spent computing loops to ``seconds["loops"]``."""
    from .component_loops import loops_by_component

    if state.num_triangles == 0:
        return state, 0
    failed = {}  # frozenset of vertex ids (stable: edits only append) -> why the removal failed
    rounds = 0
    while True:
        started = time.perf_counter()
        try:
            found = loops_by_component(state.vertices, state.triangles)  # a bad component spoils no other
        except ValueError as error:
            left.append(Left("component", 0.0, f"handle and tunnel loops not computed: {error}",
                             np.zeros(0, np.int32)))
            return state, rounds
        finally:
            seconds["loops"] = seconds.get("loops", 0.0) + time.perf_counter() - started
        budget = found.genus - keep_largest if keep_largest is not None else found.genus
        if rounds >= max_rounds or budget <= 0:
            break
        state, count = _removal_round(state, found, size, budget, fair, failed, removed)
        if count == 0:
            break
        rounds += 1
    _report_left(state, found, size, keep_largest, failed, left)
    return state, rounds


def _removal_round(state: EditResult, found, size: float, budget: int, fair: bool, failed: dict,
                   removed: list) -> tuple:
    """Removes up to ``budget`` loops below ``size``, shortest first, no two sharing a vertex.
    Returns (state, count removed)."""
    candidates = sorted((loop for c in found.components if c.status == "ok" for loop in c.loops),
                        key=lambda loop: (loop.length, loop.kind))
    used = np.zeros(state.num_vertices, dtype=bool)  # loops are in the round's first ids, kept by every edit
    count, stale = 0, {}
    editor = LocalEditor(state.vertices, state.triangles)
    for loop in candidates:
        if count >= budget or loop.length >= size:
            break
        ids = np.asarray(loop.vertices, dtype=np.int64)
        key = frozenset(ids.tolist())
        if used[ids].any() or key in failed:  # most often the other loop of a handle removed
            continue
        tag = len(removed)
        try:
            patches, style = _remove_one(editor, ids, tag, fair)
        except ValueError as error:
            # A loop that now separates was made redundant by a removal earlier in this round;
            # the next round's loops settle it. Anything else is this loop's own failure.
            (stale if "separates" in str(error) else failed)[key] = str(error).splitlines()[0]
            continue
        used[ids] = True
        area, aspect = patch_quality(editor.vertices.view(), editor.triangles.view(), patches)
        removed.append(Removed(loop.kind, float(loop.length), len(ids), area, aspect,
                               state.vertex_source[ids].astype(np.int32), style))
        count += 1
    if count:
        state = compose(state, editor.result())
    if count == 0:
        failed.update(stale)  # nothing else changed: these loops separate on their own
    return state, count


def _remove_one(editor: LocalEditor, ids: np.ndarray, tag: int, fair: bool) -> tuple:
    """remove_handle with the best patches that do not make the surface cross itself: faired,
    else refined but flat, else flat (remove_handle's step_down). A faired cap continues the
    tube it closes, so the two caps of a thick handle bulge towards each other and can cross;
    flat ones do not. Returns (patches, their style)."""
    patches = editor.remove_handle(ids, tag, refine=fair, fair=fair, step_down=fair)
    return patches, "faired" if patches[0].faired else "refined" if patches[0].refined else "flat"


def _report_left(state: EditResult, found, size: float, keep_largest: Optional[int], failed: dict,
                 left: list) -> None:
    """One entry per loop still there (each handle has a handle and a tunnel loop) saying why."""
    from .component_loops import REFUSED

    for number, component in enumerate(found.components):
        if component.status != "ok":
            why = component.detail if component.status == REFUSED else \
                f"loops undefined ({component.status}): {component.detail}"
            left.append(Left("component", 0.0, f"component {number} left as is: {why}",
                             np.array([state.vertex_source[component.first_vertex]], np.int32)))
            continue
        for loop in component.loops:
            ids = np.asarray(loop.vertices, dtype=np.int64)
            key = frozenset(ids.tolist())
            if key in failed:
                reason = f"removal failed: {failed[key]}"
            elif loop.length >= size:
                reason = f"loop {loop.length:.6g} is not below the size {size:.6g}"
            elif keep_largest is not None:
                reason = f"kept: one of the {keep_largest} largest handles asked for"
            else:
                reason = "not reached: the round limit (max_rounds) was hit"
            left.append(Left(loop.kind, float(loop.length), reason, state.vertex_source[ids].astype(np.int32)))
