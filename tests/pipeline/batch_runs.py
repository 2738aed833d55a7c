"""Running ``topstoc batch`` from the pipeline tests: to the end, or in the background with its
output lines collected while the test acts on the run; its outputs and report; processes by
command line (to find a worker's Blender child, or what a test left running)."""

import json
import os
import pathlib
import subprocess
import sys
import threading
import time

import cli
from conftest import BUILD

BOOKKEEPING = ("topstoc-manifest", "topstoc-report")


def batch(*args, timeout=600):
    """``topstoc batch ARGS --progress lines`` to the end (CompletedProcess)."""
    return cli.run("batch", *args, "--progress", "lines", timeout=timeout)


def outputs(folder) -> dict:
    """Output files (not the manifest or report) and their bytes."""
    folder = pathlib.Path(folder)
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())
            if p.is_file() and not p.name.startswith(BOOKKEEPING)}


def leftovers(folder) -> list:
    """Temporaries and scratch folders a killed task could leave behind."""
    return sorted(p.name for p in pathlib.Path(folder).iterdir()
                  if ".tmp" in p.name or p.name.startswith(".topstoc-partial"))


def report(folder, name="topstoc-report.json") -> dict:
    return json.loads((pathlib.Path(folder) / name).read_text())


def ran(data: dict) -> list:
    """The report's results of the assets this run decimated (not those resumed from an earlier run)."""
    return [entry for entry in data["results"] if not entry.get("resumed")]


def manifest(folder) -> list:
    return [json.loads(line) for line in (pathlib.Path(folder) / "topstoc-manifest.jsonl").open()]


class Background:
    """``topstoc batch`` running in the background; ``lines`` fills up as it prints."""

    def __init__(self, *args):
        env = dict(os.environ, PYTHONPATH=str(BUILD / "python"))
        command = [sys.executable, "-m", "topstoc", "batch", *map(str, args), "--progress", "lines"]
        self.process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        self.lines, self.errors = [], []
        self._readers = [threading.Thread(target=self._read, args=(stream, store), daemon=True)
                         for stream, store in ((self.process.stdout, self.lines), (self.process.stderr, self.errors))]
        for reader in self._readers:
            reader.start()

    def _read(self, stream, store):
        for line in stream:
            store.append(line)

    def worker_pids(self, timeout=120) -> list:
        """The worker pids the run announces."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.process.poll() is None:
            for line in list(self.lines):
                if "workers (pids" in line:
                    return [int(p) for p in line.split("(pids ")[1].split(")")[0].split()]
            time.sleep(0.05)
        raise AssertionError("no worker pids announced:\n" + "".join(self.lines + self.errors))

    def finish(self, timeout=600) -> int:
        try:
            self.process.wait(timeout=timeout)
        finally:
            self.stop()
        for reader in self._readers:
            reader.join(10)
        return self.process.returncode

    def stop(self):
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def output(self) -> str:
        return "".join(self.lines) + "".join(self.errors)


def processes(marker: str) -> dict:
    """Running processes (zombies excluded) whose command line holds ``marker``: {pid: parent pid}."""
    found = {}
    for entry in pathlib.Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if marker in command and fields[0] != "Z":
            found[int(entry.name)] = int(fields[1])
    return found


def alive(pid: int) -> bool:
    """Running: neither gone nor a zombie."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False
