"""``topstoc batch``: many assets, one task each, on a Dask cluster, a local one, or serially.

    topstoc batch --input FILE_OR_DIR... --output DIR (--ratio R... | --screen-pixels N... | ...)
                  [--workers N | --scheduler tcp://HOST:PORT] [--blender PATH] [--json REPORT]

Mesh files need no Blender; .blend, glTF/GLB, FBX and USD run one Blender per asset. A rerun
into the same DIR skips the assets the manifest (DIR/topstoc-manifest.jsonl) lists as done
with the same content and settings. Exit code 0 when every asset is done, 1 when any failed.
"""

from __future__ import annotations

import os
import sys
import time

from ..batch import settings as batch_settings
from . import messages, progress, subcommand
from ..batch.run import (find_inputs, misnamed_failure, remove_orphaned_scratch, remove_stale_temporaries,
                         run_dask, run_serial, utf8_name, write_report)
from ..api.budget import report_missed, report_topology
from ..batch.manifest import Manifest, content_hash, task_key
from ..support.errors import TopStocError
from ..support.output_guard import check_folders, prepare_output, check_outputs, output_folder

REPORT_NAME = "topstoc-report.json"


def add_parser(subparsers) -> None:
    parser = subcommand(
        subparsers, "batch", "decimate many assets (Dask cluster, local workers or serial)",
        "Decimate many assets into DIR, one task per asset, with resume. Mesh files "
        "(OBJ, PLY, OFF, STL) need no Blender; .blend, glTF/GLB, FBX and USD run a Blender "
        "per asset. Give one target value per output, or several for a LOD chain.")
    batch_settings.add_io_arguments(parser)
    batch_settings.add_arguments(parser)
    runner = parser.add_mutually_exclusive_group()
    runner.add_argument("--workers", type=int, metavar="N",
                        help="local cluster of N worker processes (default: one per core); 0 runs serially "
                             "in this process, without Dask")
    runner.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="a running Dask scheduler")
    parser.add_argument("--blender", metavar="PATH",
                        help="Blender executable, or a Python with PyPI's bpy, for Blender formats "
                             "(default: $TOPSTOC_BLENDER or blender on PATH)")
    parser.add_argument("--chunk", metavar="I/N",
                        help="run only the I-th of N chunks of the inputs (1-based, every N-th file of the "
                             "sorted list), for farm managers; manifest and report get a -chunkIofN suffix")
    parser.add_argument("--json", metavar="REPORT.json", help=f"report file (default DIR/{REPORT_NAME})")
    parser.add_argument("--no-resume", action="store_true", help="redo assets the manifest lists as done")
    parser.add_argument("--progress", choices=("auto", "bar", "lines"), default="auto",
                        help="auto (default): a progress bar on a terminal, plain lines when the output goes to a "
                             "file or pipe")
    parser.add_argument("--quiet", "-q", action="store_true",
                        help="print only errors and the final summary line (no progress, no warnings)")
    parser.set_defaults(run=run)


class Progress:
    """A tqdm bar (on standard error) when standard output and error are both a terminal, else one
    line per asset on standard output: ``topstoc batch > log`` gets the lines in its log. The bar
    is redrawn every second (its clock runs while a long asset works) and cleared before a
    warning prints (topstoc.core.cli.progress). quiet: nothing but failures."""

    def __init__(self, total: int, mode: str, quiet: bool = False):
        self.total, self.count, self.bar, self.quiet = total, 0, None, quiet
        on_terminal = sys.stdout.isatty() and sys.stderr.isatty()  # `| tee log`: lines only, no bar
        if not quiet and (mode == "bar" or (mode == "auto" and on_terminal)):
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit="asset", desc="topstoc batch", file=sys.stderr)
            except ImportError:
                self.bar = None
        if self.bar is not None:
            progress.attach(self.bar.clear, self.bar.refresh)
        elif not quiet and mode == "auto" and on_terminal:
            progress.start("topstoc batch")  # a terminal without tqdm: a ticker line
            progress.stage(f"0 of {total} assets done")

    def line(self, text: str) -> None:
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.write(text, file=sys.stderr)
        else:
            progress.print_line(text, sys.stdout)

    def advance(self, path: str, text: str, failed: bool = False) -> None:
        self.count += 1
        if self.bar is not None:
            self.bar.update(1)
            if failed:
                self.bar.write(f"topstoc batch: {path}: {text}", file=sys.stderr)
        elif failed or not self.quiet:
            progress.stage(f"{self.count} of {self.total} assets done")
            progress.print_line(f"topstoc batch [{self.count}/{self.total}] {path}: {text}",
                                sys.stderr if failed else sys.stdout)

    def close(self) -> None:
        progress.stop()
        if self.bar is not None:
            self.bar.close()


def _check_names(tasks, out_dir, settings, inputs) -> None:
    """Two inputs must not write the same output file, nor any output be an input."""
    from ..batch.mesh_asset import output_paths
    from ..batch.run import asset_kind

    owners = {}
    for _, path in tasks:
        if asset_kind(path) == "mesh":
            names = output_paths(path, out_dir, settings)
        else:
            stem, ext = os.path.splitext(os.path.basename(path))
            names = [os.path.join(out_dir, stem + ("." + settings["format"] if settings["format"] else ext.lower()))]
        for name in names:
            if name in owners:
                raise TopStocError(f"{owners[name]} and {path} would both write {name}; "
                                   "batch them into different output folders")
            owners[name] = path
    check_outputs(owners, inputs)


def _lod_vertices(entry: dict) -> list:
    """Vertices per LOD: a mesh file's ``lods``, or summed over a scene's objects."""
    if entry.get("lods"):
        return [lod["vertices"] for lod in entry["lods"]]
    per_object = [obj.get("lods") or [] for obj in entry.get("objects") or []]
    if not per_object:
        return []
    return [sum(lods[i]["vertices"] for lods in per_object if i < len(lods))
            for i in range(max(len(lods) for lods in per_object))]


def _summary(entry: dict) -> str:
    lods = _lod_vertices(entry)
    if len(lods) > 1:
        text = f"{entry['vertices_in']} -> {' / '.join(map(str, lods))} vertices ({len(lods)} LODs)"
    else:
        text = f"{entry['vertices_in']} -> {entry['vertices_out']} vertices, {entry['triangles_out']} triangles"
    return text + "".join("; " + phrase for phrase in _cleaned(entry) + report_missed(entry) + report_topology(entry))


def _cleaned(entry: dict) -> list:
    """'cleaned: …' for an asset cleaned with --clean (a mesh file, or summed over a scene's meshes)."""
    reports = [entry["clean"]] if "clean" in entry else [o["clean"] for o in entry.get("objects") or [] if "clean" in o]
    if not reports:
        return []
    handles, holes = (sum(r[key] for r in reports) for key in ("handles_removed", "holes_filled"))
    left = sum(len(r["left"]) for r in reports)
    return [f"cleaned: {handles} handles removed, {holes} holes filled, {left} left (see the report)"]


def parse_chunk(text: str) -> tuple:
    """'2/8' -> (2, 8); ValueError unless 1 <= I <= N."""
    try:
        index, count = (int(part) for part in text.split("/"))
    except ValueError:
        raise TopStocError(f"--chunk must look like I/N (e.g. 2/8), got {text!r}") from None
    if not 1 <= index <= count:
        raise TopStocError(f"--chunk I/N needs 1 <= I <= N, got {text!r}")
    return index, count


def run(args) -> int:
    settings = batch_settings.from_args(args)
    started = time.perf_counter()
    inputs = find_inputs(args.input)
    suffix = ""
    if args.chunk:
        index, count = parse_chunk(args.chunk)
        inputs = inputs[index - 1::count]
        suffix = f"-chunk{index}of{count}"
    if not inputs:
        if args.chunk:  # more chunks than files: an empty chunk is not an error
            print(f"topstoc batch: chunk {args.chunk} has no inputs", flush=True)
            return 0
        raise TopStocError("no input assets found")
    report_path = args.json or os.path.join(args.output, REPORT_NAME.replace(".json", suffix + ".json"))
    check_folders(args.input, args.output)
    prepare_output(report_path, inputs)
    output_folder(args.output)
    manifest = Manifest(args.output, suffix)
    manifest.check_inputs(inputs)
    fingerprint = batch_settings.digest(settings)
    tasks, keys, skipped, resumed, misnamed = [], {}, [], {}, []
    for index, path in enumerate(inputs):
        if not utf8_name(path):
            misnamed.append(index)  # fails alone, below: it cannot be keyed, reported or printed
            continue
        try:
            sha = content_hash(path)
        except OSError as error:
            sha = f"unreadable: {error.strerror}"  # the task reports the error
        keys[index] = (task_key(path, sha, fingerprint), sha)
        record = None if args.no_resume else manifest.finished(keys[index][0])
        if record is not None:
            skipped.append({"input": path, "outputs": record["outputs"]})
            if "entry" in record:
                resumed[index] = dict(record["entry"], resumed=True)
        else:
            tasks.append((index, path))
    _check_names(tasks, args.output, settings, inputs)

    bar = Progress(len(inputs), args.progress, args.quiet)
    for item in skipped:
        bar.advance(item["input"], "skipped (done in an earlier run)")
    results, failures, outputs = {}, {}, []
    for index in misnamed:
        failures[index] = misnamed_failure(inputs[index])
        bar.advance(failures[index]["input"], f"FAILED: {failures[index]['message']}", failed=True)

    def on_result(index, outcome):
        for text in outcome.get("warnings", ()):
            messages.print_warning(text)
        path = inputs[index]
        key, sha = keys[index]
        record = {"key": key, "input": path, "sha256": sha, "settings": fingerprint, "status": outcome["status"],
                  "wall_seconds": outcome.get("wall_seconds"), "worker_pid": outcome.get("pid")}
        if outcome["status"] == "done":
            entry = outcome["entry"]
            entry["wall_seconds"] = outcome.get("wall_seconds")
            record["outputs"] = entry.get("outputs") or [entry["output"]]
            record["entry"] = entry
            results[index] = entry
            outputs.extend(record["outputs"])
            bar.advance(path, _summary(entry))
        else:
            record["message"] = outcome["message"]
            failures[index] = {"input": path, "message": outcome["message"]}
            bar.advance(path, f"FAILED: {outcome['message']}", failed=True)
        manifest.append(record)

    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    if workers < 0:
        raise TopStocError(f"--workers must be 0 (serial) or more, got {workers}")

    def announce(client):
        pids = sorted(client.run(os.getpid).values())
        where = args.scheduler or "local cluster"
        bar.line(f"topstoc batch: {len(tasks)} assets to run ({len(skipped)} skipped) on {where}, "
                      f"{len(pids)} workers (pids {' '.join(map(str, pids))})")

    try:
        if tasks and (args.scheduler or workers > 0):
            run_dask(tasks, args.output, settings, args.blender, on_result, workers=workers,
                     scheduler=args.scheduler, on_start=announce)
        elif tasks:
            bar.line(f"topstoc batch: {len(tasks)} assets to run ({len(skipped)} skipped), serially")
            run_serial(tasks, args.output, settings, args.blender, on_result)
    finally:
        bar.close()
    remove_stale_temporaries(outputs)
    remove_orphaned_scratch()

    finished = {**resumed, **results}  # the figures of assets done in earlier runs stay in the report
    report = {"settings": settings, "runner": {"scheduler": args.scheduler, "workers": 0 if args.scheduler else workers},
              "seconds": time.perf_counter() - started,
              "results": [finished[i] for i in sorted(finished)],
              "failures": [failures[i] for i in sorted(failures)], "skipped": skipped}
    write_report(report_path, report)
    missed = sum(bool(report_missed(entry)) for entry in results.values())
    lost = sum(bool(report_topology(entry)) for entry in results.values())
    notes = [text for count, text in ((missed, f"{missed} missed their target"),
                                      (lost, f"{lost} did not keep the topology")) if count]
    print(f"topstoc batch: {len(results)} done" + (f" ({', '.join(notes)})" if notes else "")
          + f", {len(skipped)} skipped, {len(failures)} failed in {report['seconds']:.1f} s; report {report_path}",
          flush=True)
    return 1 if failures else 0
