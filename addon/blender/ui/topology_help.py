"""Plain-words help for the Topology panel: one line per figure and per loop kind, shown as the
tooltip of a "?" button beside it (and in the status bar when clicked)."""

HELP = {
    "vertices": "Points of the mesh (Blender's count, loose vertices included)",
    "edges": "Lines between two vertices",
    "faces": "Polygons as Blender stores them; Triangles counts them after triangulation",
    "triangles": "Faces after triangulation: what decimation and 3D-print slicers work on",
    "betti": "β0 = separate pieces, β1 = independent loops that cannot shrink to a point "
             "(2 per handle, 1 per extra hole), β2 = closed shells (watertight pieces)",
    "euler": "χ = V - E + F: 2 for a ball, 0 for a donut; each handle subtracts 2, each hole 1",
    "genus": "Number of handles, like the hole of a donut or a mug's handle (0 = ball-like)",
    "components": "Separate pieces: parts that share no edge",
    "boundary": "Open holes whose rim is a chain of edges with one face; a 3D print needs 0",
    "nonmanifold_edges": "Edges with three or more faces: no inside/outside there; decimators "
                         "and printers choke on them",
    "nonmanifold_vertices": "Vertices where two surfaces touch at one point (a bow-tie)",
    "isolated": "Vertices used by no face: invisible, usually left over from editing",
    "handle": "A handle loop goes around a handle, like a ring on a finger; cutting along it opens the handle",
    "tunnel": "A tunnel loop goes through a handle's hole, like a thread through a ring",
    "boundary_loop": "A boundary loop is the rim of a hole; Fill closes it",
    "cut": "Cut: slit the surface along the loop; the handle becomes two holes with rims",
    "remove": "Remove: cut along the loop and fill both new holes; the genus drops by one "
              "(a tiny unwanted handle from a scan disappears)",
    "why": "Why it matters: decimation keeps every handle and hole, so clean them first; "
           "a 3D print needs one closed, manifold shell per part",
    "repairs": "Topology repairs: samples the decimation added so that no hole closed, no handle "
               "vanished and no piece fell apart; the result keeps the original's topology",
}
