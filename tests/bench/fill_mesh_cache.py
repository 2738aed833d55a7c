#!/usr/bin/python3
"""Fill the benchmark's mesh cache from local git mirrors of the repositories in quality_meshes.json.

    python3 tests/bench/fill_mesh_cache.py [--mirrors /work/.mirror] [--cache ${TOPSTOC_CACHE}/meshes]

The benchmark never downloads: each manifest entry (repo, commit, path, licence, sha256) is read
with `git -C <mirror> show <commit>:<path>` from a mirror of <owner>/<name> found at
<mirrors>/<owner>+<name>/repo (a bare git directory or a clone), checked against its sha256 and
written atomically to <cache>/<owner>+<name>/<path>. An entry marked "range_grid" (a range image
without triangles, as Stanford's raw scans) is cached as the mesh range_grid.py makes of it, at
<path>.triangulated.off. Entries whose mirror or commit is absent are named and left out;
bench_quality.py then skips them by name.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from range_grid import range_grid_off  # noqa: E402

MANIFEST = HERE / "quality_meshes.json"
DEFAULT_CACHE = pathlib.Path(os.environ.get("TOPSTOC_CACHE", "/var/cache/topstoc")) / "meshes"


def cached_path(cache: pathlib.Path, entry: dict) -> pathlib.Path:
    """Where an entry of the manifest lives in the cache (shared with bench_quality.py)."""
    path = cache / entry["repo"].replace("/", "+") / entry["path"]
    return path.with_name(path.name + ".triangulated.off") if entry.get("range_grid") else path


def mirror_of(mirrors: pathlib.Path, repo: str) -> pathlib.Path | None:
    base = mirrors / repo.replace("/", "+") / "repo"
    for candidate in (base / ".git", base):
        if (candidate / "HEAD").exists():
            return candidate
    return None


def fill(entry: dict, mirrors: pathlib.Path, cache: pathlib.Path) -> str:
    """Cache one entry; returns what happened in a few words."""
    target = cached_path(cache, entry)
    if target.exists() and (entry.get("range_grid") or hashlib.sha256(target.read_bytes()).hexdigest() == entry["sha256"]):
        return "cached"  # (a triangulated range grid is written only from bytes that matched)
    mirror = mirror_of(mirrors, entry["repo"])
    if mirror is None:
        return f"no mirror of {entry['repo']} under {mirrors}"
    done = subprocess.run(["git", "--git-dir", str(mirror), "show", f"{entry['commit']}:{entry['path']}"],
                          capture_output=True)
    if done.returncode != 0:
        return f"not in the mirror ({done.stderr.decode().strip()})"
    if hashlib.sha256(done.stdout).hexdigest() != entry["sha256"]:
        return "sha256 differs from the manifest"
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(target.name + ".tmp")
    temporary.write_bytes(range_grid_off(done.stdout).encode() if entry.get("range_grid") else done.stdout)
    temporary.replace(target)  # atomic: never a half-written mesh under the final name
    return "written"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mirrors", type=pathlib.Path, default=pathlib.Path("/work/.mirror"))
    parser.add_argument("--cache", type=pathlib.Path, default=DEFAULT_CACHE)
    args = parser.parse_args()
    missing = 0
    for entry in json.loads(MANIFEST.read_text()):
        state = fill(entry, args.mirrors, args.cache)
        missing += state not in ("cached", "written")
        print(f"{entry['repo']}:{entry['path']}: {state}")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
