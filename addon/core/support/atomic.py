"""Atomic file writes: a temporary file next to the target, then one rename.

``write_file(path, write)`` writes through ``<target>.tmp<pid>``, where the target is ``path``
with symlinks resolved (a symlinked output is written through: its target is replaced, the
link kept). Whatever goes wrong, no half-written file appears at the target and the temporary
file is removed:

- an error while writing (a full disk, a folder in the way) removes it and raises an OSError
  naming the file, without Python's ``[Errno N]`` prefix;
- SIGTERM or SIGINT while it exists removes it, then the signal takes its usual course (SIGTERM
  ends the process as before, SIGINT raises KeyboardInterrupt). Handlers can only be set in the
  main thread and only over handlers Python can put back; elsewhere (a Dask worker's task,
  Blender's own handlers) the next write sweeps up instead;
- SIGKILL cannot be caught: ``sweep`` removes the temporary files whose process is gone; the
  commands call it before they write (topstoc.core.support.output_guard.prepare_output), the batch
  after its run (topstoc.core.batch.run.remove_stale_temporaries). Not on every write: a
  folder of many outputs would be listed once per file.
"""

from __future__ import annotations

import os
import re
import signal
import threading
from contextlib import contextmanager

from .errors import one_line, shown_path

TEMPORARY = re.compile(r"\.tmp(\d+)$")


class _Signalled(BaseException):
    """A SIGTERM or SIGINT that arrived while a temporary file existed."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's process counts as alive)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def target(path) -> str:
    """The file a write to ``path`` replaces: ``path`` with symlinks resolved."""
    name = os.fspath(path)
    return os.path.realpath(name) if os.path.islink(name) else name


def sweep(path) -> int:
    """Removes ``<path>.tmp<pid>`` files whose process is gone; returns how many."""
    folder, base = os.path.split(target(path))
    try:
        names = os.listdir(folder or ".")
    except OSError:
        return 0
    removed = 0
    for name in names:
        match = TEMPORARY.search(name)
        if not match or name[:match.start()] != base:
            continue
        pid = int(match.group(1))
        if pid == os.getpid() or pid_alive(pid):
            continue
        try:
            os.remove(os.path.join(folder, name))
            removed += 1
        except OSError:
            pass
    return removed


@contextmanager
def _signals_raise():
    """While inside: SIGTERM and SIGINT raise _Signalled (main thread only; ignored signals and
    handlers set outside Python stay as they are)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise _Signalled(signum)

    previous = {}
    for signum in (signal.SIGTERM, signal.SIGINT):
        current = signal.getsignal(signum)
        # None: a handler set outside Python (Blender's), which could not be put back
        if current is not None and current is not signal.SIG_IGN:
            previous[signum] = signal.signal(signum, handler)
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old)


def file_error(path, error: OSError, note: str = "") -> OSError:
    """``error`` as an OSError whose text is one line naming ``path`` (no ``[Errno N]``)."""
    reason = one_line(OSError(error.errno, error.strerror)) if error.strerror else one_line(error)
    failure = OSError(f"{shown_path(path)}: cannot write the file ({reason}){note}")
    failure.errno = error.errno
    return failure


def write_file(path, write, *, discard_old: bool = False) -> None:
    """Calls ``write(stream)`` on a binary temporary file and renames it to ``path``'s target.
    ``discard_old``: when the write fails, the file already at the target is removed too (a
    report of an earlier run, which would otherwise pass for this run's)."""
    final = target(path)
    temporary = f"{final}.tmp{os.getpid()}"
    try:
        with _signals_raise():
            try:
                with open(temporary, "wb") as stream:
                    write(stream)
                os.replace(temporary, final)
            finally:
                if os.path.lexists(temporary):
                    os.remove(temporary)
    except _Signalled as signalled:
        os.kill(os.getpid(), signalled.signum)  # the usual handler is back: it ends us (or raises)
        raise KeyboardInterrupt from None
    except OSError as error:
        note = "; the earlier file there was removed" if discard_old and _removed(final) else ""
        raise file_error(path, error, note) from None


def _removed(path: str) -> bool:
    """Removes ``path``; whether there was a file to remove."""
    try:
        os.remove(path)
    except OSError:
        return False
    return True


def write_bytes(path, payload: bytes, *, discard_old: bool = False) -> None:
    """Writes ``payload`` to ``path`` atomically (see write_file)."""
    write_file(path, lambda stream: stream.write(payload), discard_old=discard_old)


def write_text(path, text: str, *, discard_old: bool = False) -> None:
    """Writes ``text`` (UTF-8) to ``path`` atomically (see write_file)."""
    write_bytes(path, text.encode("utf-8"), discard_old=discard_old)
