"""Stress test: N decimations of random manifolds, every guarantee checked independently.

    PYTHONPATH=build/python python3 tests/stress/decimate_stress.py N SEED [--save DIR]

Every result's engine-side final check (stats.output_check) must be clean, and the
independent numpy check runs on every K-th result (--check-every, default all).
Meshes come from tests/random_manifolds.py (hulls, tori, grids with holes, icospheres, 1-4 of
them side by side; every PINCHED-th mesh instead 2-4 of them glued at vertices, a spider of
wings or a chain; every FLIPPED-th other one with a patch of its triangles wound the other way,
checked wound back by the sources' flips, and each component as inconsistently oriented as its
input's); each is decimated several times with random ratio, seed, placement,
refinement, feature angle and fast path. Every result with ``topology_kept`` is checked by
random_manifolds.check_decimation, or check_pinched_decimation for glued meshes (numpy/scipy,
no topstoc code). Counts, per outcome:
  ok          topology kept and the independent check agrees
  reported    topology_kept == False (the repair-round limit hit; honest, but counted)
  raised      the engine's final check raised instead of returning
  unreported  topology_kept == True but the independent check found a violation (a lie)
  draft_differs  a draft (decimate(draft=True), one in ten, fast mode) whose samples, vertices
              or triangles differ from the full decimation's (made after it and checked as above),
              or, where the full decimation collapsed its plain pass further (the draft's
              collapses_skipped), whose samples differ or whose vertices lack one of the result's
  crashed     any other exception
Exit code 1 when anything but `ok` happened. Failing cases are written to --save as .npz
(vertices, triangles) + .json (parameters), ready for tests/data/regressions.
"""

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import random_manifolds  # noqa: E402
import topstoc  # noqa: E402

DECIMATIONS_PER_MESH = 8
PINCHED = 4  # every 4th mesh is a pinched surface (mesh index 3, 7, 11, ...)


FLIPPED = 5  # every 5th mesh that is not pinched has a patch of its triangles wound the other way


def generated_mesh(mesh_seed):
    """The mesh for (seed, index), whether it is a pinched surface, and which of its triangles
    were flipped (None: none)."""
    if mesh_seed[1] % PINCHED == PINCHED - 1:
        return random_manifolds.pinched_surface(list(mesh_seed)), True, None
    vertices, triangles = random_manifolds.random_manifold(list(mesh_seed))
    if mesh_seed[1] % FLIPPED != FLIPPED - 3:
        return (vertices, triangles), False, None
    triangles, flip = random_manifolds.flip_patch(len(vertices), triangles, list(mesh_seed))
    return (vertices, triangles), False, flip


def random_parameters(rng, drafts=False):
    """Random decimation parameters; with ``drafts``, one set in ten asks for a fast-mode draft
    (the same draws either way)."""
    params = dict(ratio=float(rng.uniform(0.02, 0.95)), seed=int(rng.integers(0, 2**31)))
    if rng.random() < 0.3:
        params["placement"] = "filtered"
    if rng.random() < 0.25:
        params["refine"] = float(rng.choice([1.5, 2.0, 3.0]))
    if rng.random() < 0.25:
        params["feature_angle"] = float(rng.uniform(0.2, 1.2))
    if rng.random() < 0.2:
        params["fast_path"] = bool(rng.random() < 0.5)
    if rng.random() < 0.1:
        params["density"] = "uniform"
    if rng.random() < 0.1 and drafts:
        params.pop("refine", None)
        params.update(mode="fast", draft=True)
    return params


def draft_differences(draft, full):
    """What differs between a draft and the full decimation it previews (empty: nothing)."""
    if draft.stats.collapses_skipped:  # the plain pass the full decimation collapsed further
        # keeping input positions: fast mode's collapses past the pass, or the zero-area clean-up's
        keeps_positions = full.stats.refine_keeps_positions or full.stats.refine_vertices == 0
        differ = [] if keeps_positions else ["collapses"]
        if not set(full.kept.tolist()) <= set(draft.kept.tolist()):
            differ.append("kept")
        return differ + ([] if np.array_equal(draft.samples, full.samples) else ["samples"])
    return [name for name in ("samples", "vertices", "triangles")
            if not np.array_equal(getattr(draft, name), getattr(full, name))]


def engine_check_clean(result):
    """The engine's own final check (verify.hpp) found nothing (zero-area triangles aside)."""
    return not any(v for k, v in result.stats.output_check.items() if k != "zero_area")


def run(count, seed, save=None, quiet=False, check_every=1, progress=0):
    counts = dict(ok=0, reported=0, raised=0, unreported=0, draft_differs=0, crashed=0, independently_checked=0,
                  pinched=0, drafts=0)
    rng = np.random.default_rng(seed)
    start = time.time()
    done = 0
    mesh_index = 0
    while done < count:
        mesh_seed = (seed, mesh_index)
        mesh_index += 1
        (vertices, triangles), pinched, flip = generated_mesh(mesh_seed)
        mesh = topstoc.Mesh(vertices, triangles)
        wound = triangles if flip is None else np.where(flip[:, None], triangles[:, ::-1], triangles)
        before = None if pinched else random_manifolds.surface_facts(len(vertices), wound)
        for _ in range(min(DECIMATIONS_PER_MESH, count - done)):
            params = random_parameters(rng, drafts=True)
            outcome, detail = "ok", ""
            try:
                full_params = {name: value for name, value in params.items() if name != "draft"}
                draft = mesh.decimate(**params) if params.get("draft") else None
                r = mesh.decimate(**full_params)
                if draft is not None:
                    counts["drafts"] += 1
                    differ = draft_differences(draft, r)
                if draft is not None and differ:
                    outcome, detail = "draft_differs", ", ".join(differ)
                elif not r.stats.topology_kept:
                    outcome, detail = "reported", str(r.stats.issues_remaining)
                else:
                    problems = [] if engine_check_clean(r) else [f"engine check: {r.stats.output_check}"]
                    if done % check_every == 0:
                        counts["independently_checked"] += 1
                        if pinched:
                            problems += random_manifolds.check_pinched_decimation(vertices, triangles, r.vertices,
                                                                                  r.triangles, r.kept)
                        elif flip is None:
                            problems += random_manifolds.check_decimation(vertices, triangles, r.vertices,
                                                                          r.triangles, r.kept, before)
                        else:  # wound back by the sources' flips, the input's own winding is consistent
                            back = random_manifolds.unflipped(len(vertices), triangles, flip, r.triangles,
                                                              r.face_source)
                            problems += random_manifolds.check_decimation(vertices, wound, r.vertices, back,
                                                                          r.kept, before)
                            problems += random_manifolds.check_windings(len(vertices), triangles, r.triangles,
                                                                        r.kept)
                    if problems:
                        outcome, detail = "unreported", "; ".join(problems)
            except RuntimeError as error:
                outcome, detail = "raised", str(error)
            except Exception as error:  # noqa: BLE001 - everything else is a crash to report
                outcome, detail = "crashed", f"{type(error).__name__}: {error}"
            counts[outcome] += 1
            counts["pinched"] += pinched
            done += 1
            if progress and done % progress == 0:
                print(json.dumps({**counts, "decimations": done, "seconds": round(time.time() - start, 1)}),
                      flush=True)
            if outcome != "ok":
                if not quiet:
                    print(f"{outcome}: mesh seed {list(mesh_seed)} {params}: {detail}", flush=True)
                if save:
                    os.makedirs(save, exist_ok=True)
                    name = os.path.join(save, f"{outcome}_{mesh_seed[0]}_{mesh_seed[1]}_{done}")
                    np.savez_compressed(name + ".npz", vertices=vertices, triangles=triangles)
                    with open(name + ".json", "w") as f:
                        json.dump(params, f)
    counts["decimations"] = done
    counts["meshes"] = mesh_index
    counts["seconds"] = round(time.time() - start, 1)
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("count", type=int)
    parser.add_argument("seed", type=int)
    parser.add_argument("--save", help="folder for failing cases")
    parser.add_argument("--check-every", type=int, default=1,
                        help="run the independent numpy check on every K-th decimation (the engine's own "
                             "final check runs on all); 1 = all")
    parser.add_argument("--progress", type=int, default=0, help="print the counts every N decimations")
    args = parser.parse_args()
    counts = run(args.count, args.seed, args.save, check_every=args.check_every, progress=args.progress)
    print(json.dumps(counts), flush=True)
    return 0 if counts["ok"] == counts["decimations"] else 1  # any other outcome fails


if __name__ == "__main__":
    sys.exit(main())
