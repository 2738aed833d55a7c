"""The batch manifest: what a rerun may skip.

A JSON-lines file next to the outputs (``topstoc-manifest.jsonl``; ``topstoc-manifest-chunkIofN.jsonl``
for a chunk of a farm job, so chunks never append to one file), one record per finished asset,
appended by the one process that drives the batch (never by workers) as results come in:

    {"key": ..., "input": ..., "sha256": ..., "settings": ..., "status": "done"|"failed",
     "outputs": [...], "entry": {...}}

``key`` = SHA-256 of the input's absolute path, its content hash and the settings fingerprint,
so an edited input or other settings make the asset run again. Content alone cannot tell an
input from a LOD an earlier run wrote (a LOD is new content, so it would be decimated again):
outputs never go where inputs are read (topstoc.core.support.output_guard), and an input that is one of
the outputs the manifest lists (the same file, under any name) is refused (``check_inputs``).
An asset is skipped when its last record in any of the folder's manifests is "done" and every
output it lists still exists. Each record is written with one ``write`` and flushed to disk, so
a batch killed mid-write loses at most that last line, which a rerun ignores (and redoes the
asset).
"""

from __future__ import annotations

import hashlib
import json
import os

from ..support.errors import TopStocError, shown_path
from ..support.output_guard import file_identity, identities

MANIFEST_NAME = "topstoc-manifest.jsonl"


def content_hash(path: str) -> str:
    """SHA-256 of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def task_key(path: str, sha256: str, settings_digest: str) -> str:
    text = "\0".join((os.path.abspath(path), sha256, settings_digest))
    return hashlib.sha256(text.encode()).hexdigest()


class Manifest:
    """The manifest of an output folder: records read at start, appended as assets finish."""

    def __init__(self, out_dir: str, suffix: str = ""):
        self.path = os.path.join(out_dir, MANIFEST_NAME.replace(".jsonl", suffix + ".jsonl"))
        self.records = {}
        stem = MANIFEST_NAME[:-len(".jsonl")]
        names = sorted(name for name in os.listdir(out_dir) if name.startswith(stem) and name.endswith(".jsonl"))
        for name in names:
            with open(os.path.join(out_dir, name), "r", encoding="utf-8", errors="replace") as stream:
                for line in stream:
                    try:
                        record = json.loads(line)
                        key = record["key"]
                    except (ValueError, KeyError, TypeError):
                        continue  # a line cut by a killed run: that asset simply runs again
                    if record.get("status") == "done" or key not in self.records:
                        self.records[key] = record

    def finished(self, key: str):
        """The record of an asset done earlier whose outputs all still exist, else None."""
        record = self.records.get(key)
        if record is None or record.get("status") != "done":
            return None
        if not all(os.path.exists(path) for path in record.get("outputs", [])):
            return None
        return record

    def check_inputs(self, inputs) -> None:
        """TopStocError when one of ``inputs`` is a file an earlier run into this folder wrote."""
        written = identities(output for record in self.records.values() for output in record.get("outputs") or [])
        for path in inputs:
            output = written.get(file_identity(path))
            if output is not None:
                raise TopStocError(f"{shown_path(path)}: is {shown_path(output)}, an output of an earlier batch "
                                   f"({self.path}); it would be decimated again")

    def append(self, record: dict) -> None:
        line = json.dumps(record, sort_keys=True, default=_plain) + "\n"
        if _ends_mid_line(self.path):  # a killed run's cut line must not swallow this record
            line = "\n" + line
        with open(self.path, "a", encoding="utf-8") as stream:
            stream.write(line)
            stream.flush()
            os.fsync(stream.fileno())
        self.records[record["key"]] = record


def _ends_mid_line(path: str) -> bool:
    try:
        with open(path, "rb") as stream:
            stream.seek(-1, os.SEEK_END)
            return stream.read(1) != b"\n"
    except OSError:  # missing or empty
        return False


def _plain(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"cannot write {type(value).__name__} as JSON")
