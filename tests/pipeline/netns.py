"""Machines on one host for the multi-machine test: Linux network namespaces, each with its own
network stack and address, joined to a bridge on the host by veth pairs (root only).

    with Network(["head", "node1", "node2"]) as net:
        net.address("head")                       # '10.A.B.2'
        net.start("head", ["dask", "scheduler", ...])

Namespaces share the host's file system (a shared folder at the same path, as NFS would give)
and process table. Everything started is killed and every namespace, veth and the bridge are
deleted on exit, also after a failure; names carry the creating pid, so what a killed test run
left behind is removed by the next one.
"""

import os
import random
import re
import signal
import subprocess
import time

PREFIX = "tsn"


def _ip(*args, check=True) -> subprocess.CompletedProcess:
    done = subprocess.run(["ip", *args], capture_output=True, text=True, timeout=60)
    if check and done.returncode != 0:
        raise RuntimeError(f"ip {' '.join(args)}: {done.stderr.strip()}")
    return done


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


def _kill_namespace(name: str) -> None:
    """Kills every process in namespace ``name`` and deletes it."""
    pids = _ip("netns", "pids", name, check=False).stdout.split()
    for pid in map(int, pids):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    _ip("netns", "del", name, check=False)


def remove_leftovers() -> list:
    """Deletes namespaces and bridges of earlier runs whose creating process is gone."""
    removed = []
    for line in _ip("netns", "list", check=False).stdout.splitlines():
        match = re.match(rf"({PREFIX}([0-9a-f]+)n\d+)\b", line)
        if match and not _pid_alive(int(match.group(2), 16)):
            _kill_namespace(match.group(1))
            removed.append(match.group(1))
    for line in _ip("-o", "link", "show", "type", "bridge", check=False).stdout.splitlines():
        match = re.match(rf"\d+: ({PREFIX}([0-9a-f]+)br)\b", line)
        if match and not _pid_alive(int(match.group(2), 16)):
            _ip("link", "del", match.group(1), check=False)
            removed.append(match.group(1))
    return removed


def _free_subnet() -> str:
    """A 10.x.y.0/24 no interface of the host uses: '10.x.y'."""
    used = _ip("-4", "-o", "addr", check=False).stdout + _ip("-4", "route", check=False).stdout
    rng = random.Random()
    for _ in range(100):
        subnet = f"10.{rng.randrange(100, 250)}.{rng.randrange(0, 250)}"
        if subnet + "." not in used:
            return subnet
    raise RuntimeError("no free 10.x.y.0/24 subnet")


class Network:
    """A bridge on the host (address .1) and one namespace per machine (.2, .3, ...)."""

    def __init__(self, machines):
        self.machines = list(machines)
        tag = f"{PREFIX}{os.getpid():x}"
        self.bridge = tag + "br"
        self.namespaces = {m: f"{tag}n{i}" for i, m in enumerate(self.machines)}
        self.veths = {m: (f"{tag}h{i}", f"{tag}c{i}") for i, m in enumerate(self.machines)}
        self.subnet = None
        self.processes = []

    def address(self, machine=None) -> str:
        """The machine's address (the host's on the bridge without one)."""
        return f"{self.subnet}.{1 if machine is None else 2 + self.machines.index(machine)}"

    def __enter__(self):
        remove_leftovers()
        try:
            self.subnet = _free_subnet()
            _ip("link", "add", self.bridge, "type", "bridge")
            _ip("addr", "add", f"{self.address()}/24", "dev", self.bridge)
            _ip("link", "set", self.bridge, "up")
            for machine in self.machines:
                namespace, (outside, inside) = self.namespaces[machine], self.veths[machine]
                _ip("netns", "add", namespace)
                _ip("link", "add", outside, "type", "veth", "peer", "name", inside)
                _ip("link", "set", inside, "netns", namespace)
                _ip("link", "set", outside, "master", self.bridge, "up")
                _ip("-n", namespace, "addr", "add", f"{self.address(machine)}/24", "dev", inside)
                _ip("-n", namespace, "link", "set", inside, "up")
                _ip("-n", namespace, "link", "set", "lo", "up")
        except BaseException:
            self.close()
            raise
        return self

    def start(self, machine, command, **options) -> subprocess.Popen:
        """Starts ``command`` on ``machine`` (in its own process group, killed on exit)."""
        process = subprocess.Popen(["ip", "netns", "exec", self.namespaces[machine], *command],
                                   start_new_session=True, **options)
        self.processes.append(process)
        return process

    def pids(self, machine) -> set:
        """Every process running on ``machine``."""
        return set(map(int, _ip("netns", "pids", self.namespaces[machine], check=False).stdout.split()))

    def close(self) -> None:
        for process in self.processes:
            try:
                os.killpg(process.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for process in self.processes:
            try:
                process.wait(10)
            except subprocess.TimeoutExpired:
                pass
        for namespace in self.namespaces.values():
            _kill_namespace(namespace)   # also what left its process group
        for outside, _ in self.veths.values():
            _ip("link", "del", outside, check=False)   # gone with its namespace; if not, now
        _ip("link", "del", self.bridge, check=False)
        deadline = time.monotonic() + 10
        while self.leftovers() and time.monotonic() < deadline:
            time.sleep(0.1)

    def leftovers(self) -> list:
        """Namespaces and links of this network that still exist."""
        namespaces = set(_ip("netns", "list", check=False).stdout.split())
        links = set(re.findall(r"^\d+: ([^:@]+)", _ip("-o", "link", check=False).stdout, re.M))
        ours = [self.bridge] + [outside for outside, _ in self.veths.values()]
        return sorted(namespaces & set(self.namespaces.values())) + sorted(links & set(ours))

    def __exit__(self, *exc):
        self.close()
        return False
