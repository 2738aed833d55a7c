"""A missed target, told the same way everywhere: command line, ``--json``, batch line and report,
the add-on's status bar and panel (docs/design.md §2.3).

A decimation misses its vertex target when it lands more than BUDGET_TOLERANCE (at least one
vertex) away from it. Why, in the words every channel uses:

- "control points": the vertices painted to stay (u = 1) outnumber the target;
- "borders": corners of borders (seams, materials, sharp or hard-normal edges), always kept,
  outnumber the target, or the result's vertices on the borders given outnumber the target or
  its excess over it (each border keeps its course: many small UV islands or material patches),
  which the detail counts;
- "non-manifold edges": at least half of the result's vertices lie on non-manifold edges (edges
  of three or more triangles): each such curve keeps its course and at least one edge, each
  sheet along it its triangles, so the topology stays; the detail says how many vertices that is;
- "topology": samples the topology needs (each loose piece keeps at least a triangle, each
  hole and handle its loops), first where the target is below what the pieces and loops need
  (topology_floor) and forced vertices do not outnumber that; where loose triangles (pieces of
  one triangle, as in an unwelded mesh) or holes (boundary loops, each kept with three vertices or more) make up much of the
  result, the detail says how many and what to do first; where the result's loose triangles are
  separate pieces of several triangles in the input (leaf cards, hair strips), or the boundary
  loops are about one a piece (their outlines, not holes), it says that instead; where the
  input's pieces alone hold most of the result (many small closed parts), it counts them;
- "needle triangles": the input is made mostly of slivers (needles), and the result's triangles
  may be no thinner than the input's own: the target needs thinner ones (a strip of needles
  one or two cells wide);
- "folds": the result stands at twice its target or more, and only collapses that would flip,
  fold or thin triangles are left (a thin part curving more than the budget can follow: a
  spring, a cable); the topology alone would let it go at least halfway to the target;
- "error guard": quality mode's last collapses toward a target of at most 400 triangles may not
  lay a triangle farther from the input than twice the error where they began (or 3 % of the
  diagonal): the collapses past this count would have covered an opening or cut across a part;
- "symmetry": the mirrored sample set is larger (or, where partners of absorbed samples were
  dropped, smaller) than the plain draw (core/api/symmetry.py);
- "absorbed clusters": clusters that neighbours absorbed were not all made up for;
- "zero-area input": the input's triangles have no area in double precision (coordinates so
  small that their squared lengths underflow), so the clean-up of zero-area triangles removes
  vertices below the target.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

#: how far from the target a result may land before it counts as missing it
BUDGET_TOLERANCE = 0.01


def tolerance(target: int) -> float:
    """Vertices a result may lie off ``target`` and still meet it."""
    return max(1, BUDGET_TOLERANCE * target)


@dataclass(frozen=True)
class MissedTarget:
    """A result that missed its target: ``got`` vertices (or triangles) for ``asked``, and why."""

    asked: int
    got: int
    reason: str
    unit: str = "vertices"
    detail: str = ""  #: what the reason costs, in words ("" when the reason says it all)

    @property
    def off(self) -> int:
        """Vertices over (> 0) or under (< 0) the target."""
        return self.got - self.asked

    @property
    def fraction(self) -> float:
        """How far off, as a fraction of the target (+0.09: 9 % over)."""
        return self.off / self.asked if self.asked else 0.0

    def as_dict(self) -> dict:
        """The ``target_missed`` object of the JSON reports."""
        return {"asked": self.asked, "got": self.got, "unit": self.unit, "off": self.off,
                "fraction": self.fraction, "reason": self.reason, "detail": self.detail}

    def text(self) -> str:
        """One phrase for a report line: "target missed: 871 vertices for 796 (75 over, +9.4 %; symmetry)"."""
        side = "over" if self.off > 0 else "under"
        detail = f": {self.detail}" if self.detail else ""
        return (f"target missed: {self.got:,} {self.unit} for {self.asked:,} ({abs(self.off):,} {side}, "
                f"{100 * self.fraction:+.1f} %; {self.reason}{detail})")


def topology_floor(stats) -> int:
    """Vertices the result's pieces and boundary loops need at the least: 4 for a closed piece, 3
    for each boundary loop (an open piece's outline or a hole); handles need more."""
    pieces, open_pieces, loops = (getattr(stats, k, 0) for k in ("pieces", "open_pieces", "holes"))
    if not loops:  # the loops are counted only where they may hold the result: any piece needs 3
        return 3 * pieces
    return 4 * max(0, pieces - open_pieces) + 3 * max(loops, open_pieces)


def over_reason(stats) -> str:
    """Why a result with these DecimateStats landed over its target (see the module docs)."""
    if stats.forced >= stats.target_vertices and stats.control_points:
        return "control points"
    if stats.nonmanifold_vertices >= stats.output_vertices / 2:
        return "non-manifold edges"
    if getattr(stats, "shape_floor", False):
        return "needle triangles"
    # (The draw forces loose triangles' corners too: where they alone fill the target, the
    # topology holds the result, each piece keeping its triangle.)
    # It forces three vertices of each short boundary loop too, where those are many: the holes',
    # which the topology keeps, and the corners of each component's winding seam; they are not
    # the borders' corners.
    corners = stats.forced - getattr(stats, "loop_forced", 0)
    floor = topology_floor(stats)
    if floor > stats.target_vertices and corners <= floor:
        return "topology"  # the pieces and loops alone need more than the target (the detail counts)
    if corners >= stats.target_vertices and 3 * getattr(stats, "loose_triangles", 0) < stats.target_vertices:
        return "borders"
    on_borders = getattr(stats, "border_vertices", 0)
    if on_borders and (on_borders >= stats.target_vertices or on_borders >= stats.output_vertices - stats.target_vertices):
        return "borders"  # the borders' courses hold more vertices than the target, or than the excess
    if stats.mirrored_from and stats.mirrored_from - stats.target_vertices <= tolerance(stats.target_vertices):
        return "symmetry"  # the plain draw met the target, its mirrored set did not
    if getattr(stats, "far_guard", False):
        return "error guard"
    if getattr(stats, "fold_floor", False):
        return "folds"
    return "topology"


def _over_detail(stats, reason: str) -> str:
    """What the reason of a result over its target costs, in words (see the module docs)."""
    if reason == "non-manifold edges":
        return f"{stats.nonmanifold_vertices:,} of the result's {stats.output_vertices:,} vertices lie on them"
    if reason == "error guard":
        return "the collapses left would lay triangles far from the surface (over its openings)"
    if reason == "needle triangles":
        return "the result's triangles stay no thinner than the input's own needles; the target needs thinner ones"
    if reason == "folds":
        return "the collapses left would flip, fold or thin triangles: a thin or tightly curved part needs more"
    loose = getattr(stats, "loose_triangles", 0)
    if reason == "topology" and 3 * loose >= stats.output_vertices / 4:
        if 3 * getattr(stats, "loose_input", loose) < stats.output_vertices / 4:  # pieces of several triangles
            return (f"{loose:,} of the result's {stats.output_triangles:,} triangles are separate pieces of the "
                    "input (cards, leaves, parts), each down to the one triangle it keeps")
        return (f"{loose:,} of the result's {stats.output_triangles:,} triangles are loose pieces, each kept whole; "
                "weld the mesh first (Blender: Merge by Distance)")
    holes = getattr(stats, "holes", 0)
    on_borders = getattr(stats, "border_vertices", 0)
    if reason == "borders" and on_borders >= stats.target_vertices:
        return (f"{on_borders:,} of the result's {stats.output_vertices:,} vertices lie on the borders given "
                "(materials, UV seams, sharp or marked edges), each kept on its course")
    open_pieces = getattr(stats, "open_pieces", 0)
    if reason in ("topology", "borders") and 3 * holes >= stats.output_vertices / 4 and 2 * open_pieces >= holes:
        return f"the input's {open_pieces:,} separate open pieces (strips, cards, parts) keep at least a triangle each"
    pieces = getattr(stats, "pieces", 0)
    if reason == "topology" and 4 * pieces >= 3 * stats.output_vertices / 4 and 3 * holes < stats.output_vertices / 4:
        return (f"the input's {pieces:,} separate pieces keep at least a few vertices each "
                "(4 for a closed one, 3 for an open one)")
    if reason in ("topology", "borders") and 3 * holes >= stats.output_vertices / 4:
        return (f"the input's {holes:,} holes keep at least 3 vertices each; fill the small ones first "
                "(topstoc clean --max-hole; Blender: Clean Up Small Handles and Holes)")
    if reason == "borders" and on_borders:
        return (f"{on_borders:,} of the result's {stats.output_vertices:,} vertices lie on the borders given "
                "(materials, UV seams, sharp or marked edges), each kept on its course")
    floor = topology_floor(stats)
    if reason == "topology" and pieces and floor >= stats.target_vertices:
        return (f"the input's {pieces:,} pieces and {holes:,} boundary loops need at least {floor:,} vertices "
                "(4 a closed piece, 3 a loop)")
    return ""


def missed_target(stats) -> Optional[MissedTarget]:
    """The MissedTarget of a result's DecimateStats, or None when it met its target (a triangle
    target counts triangles, any other vertices; a replay of samples asked for none)."""
    if stats.replayed:
        return None
    unit = "triangles" if stats.target_triangles else "vertices"
    asked, got = ((stats.target_triangles, stats.output_triangles) if stats.target_triangles
                  else (stats.target_vertices, stats.output_vertices))
    if abs(got - asked) <= tolerance(asked):
        return None
    if got > asked:
        reason = over_reason(stats)
        return MissedTarget(asked, got, reason, unit, _over_detail(stats, reason))
    if stats.zero_area_input:
        return MissedTarget(asked, got, "zero-area input", unit)
    return MissedTarget(asked, got, "symmetry" if stats.mirrored_from else "absorbed clusters", unit)


def missed_text(stats) -> str:
    """``"; target missed: ..."`` for a report line, or "" when the target was met."""
    missed = missed_target(stats)
    return "" if missed is None else "; " + missed.text()


def missed_dict(stats) -> Optional[dict]:
    """The ``target_missed`` object of a JSON report, or None when the target was met."""
    missed = missed_target(stats)
    return None if missed is None else missed.as_dict()


def _lods(entry: dict):
    """(owner, LOD) of each LOD of a batch report entry: its own (a mesh file) or its objects' (a
    scene file)."""
    for obj in [entry] + list(entry.get("objects") or []):
        for lod in obj.get("lods") or []:
            yield obj, lod


def _lod_name(obj: dict, lod: dict) -> str:
    """"Chair LOD1 " for a phrase; empty for the single LOD of a mesh file."""
    return (f"{obj['object']} " if "object" in obj else "") + (f"LOD{lod['lod']} " if len(obj["lods"]) > 1 else "")


def report_missed(entry: dict) -> list:
    """The missed targets of a batch report entry, one phrase each: its LODs' (a mesh file) or
    its objects' LODs' (a scene file), named when there are several."""
    return [_lod_name(obj, lod) + MissedTarget(missed["asked"], missed["got"], missed["reason"], missed["unit"],
                                               missed.get("detail", "")).text()
            for obj, lod in _lods(entry) if (missed := lod.get("target_missed"))]


def report_topology(entry: dict) -> list:
    """The LODs of a batch report entry whose topology was not kept ("topology NOT kept: ...",
    DecimateStats.topology_warning), one phrase each, named like report_missed's."""
    return [_lod_name(obj, lod) + lod["topology_warning"] for obj, lod in _lods(entry) if lod.get("topology_warning")]
