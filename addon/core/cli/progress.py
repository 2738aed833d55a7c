"""Progress on standard error for commands that run longer than a second.

One line, ``topstoc decimate: searching the vertex count for --max-error 1% ... 12 s``, redrawn in
place on a terminal and cleared when the command ends or before a warning or error prints (so
they never share its line). Off when standard error is not a terminal unless ``--progress``
asks for it (then one line per stage, no redrawing); off with ``--quiet`` and ``--json``.
Commands name their stages with ``stage("...")``; without a running ticker that does nothing.
"""

from __future__ import annotations

import sys
import threading
import time

#: a job shorter than this prints no progress
DELAY_SECONDS = 1.0
#: redraw interval on a terminal
TICK_SECONDS = 0.5

_lock = threading.RLock()
_state = {"ticker": None, "quiet": False}


def add_arguments(parser) -> None:
    """--progress and --quiet, for the commands that take them."""
    parser.add_argument("--progress", action="store_true",
                        help="show progress on standard error even when it is not a terminal "
                             "(default: only on a terminal, and only for jobs over a second)")
    parser.add_argument("--quiet", "-q", action="store_true",
                        help="no progress and no warnings on standard error (errors still print)")


def quiet() -> bool:
    return _state["quiet"]


class Ticker:
    """The progress line of one command (see the module docs)."""

    def __init__(self, command: str, redraw: bool, stream=None):
        self.command, self.redraw = command, redraw
        self.stream = stream or sys.stderr
        self.text, self.started, self.shown = "working", time.monotonic(), False
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="topstoc-progress", daemon=True)

    def start(self) -> "Ticker":
        self._thread.start()
        return self

    def stage(self, text: str) -> None:
        with _lock:
            changed = text != self.text
            self.text = text
            if changed and self.shown and not self.redraw:
                self._write_line()

    def _loop(self) -> None:
        if self._stop.wait(DELAY_SECONDS):
            return
        while True:
            with _lock:
                if self._stop.is_set():
                    return
                if self.redraw:
                    self._draw()
                elif not self.shown:
                    self._write_line()
            if self._stop.wait(TICK_SECONDS):
                return

    def _line(self) -> str:
        return f"{self.command}: {self.text} ... {time.monotonic() - self.started:.0f} s"

    def _draw(self) -> None:
        self.stream.write("\r\x1b[K" + self._line())
        self.stream.flush()
        self.shown = True

    def _write_line(self) -> None:
        self.stream.write(self._line() + "\n")
        self.stream.flush()
        self.shown = True

    def clear(self) -> None:
        """Ends the progress line so that the next message starts on a fresh one."""
        with _lock:
            if self.shown and self.redraw:
                self.stream.write("\r\x1b[K")
                self.stream.flush()
                self.shown = False

    def stop(self) -> None:
        with _lock:
            self._stop.set()
            self.clear()
        self._thread.join()


def set_quiet(value: bool) -> None:
    """--quiet: no progress and no warnings."""
    _state["quiet"] = bool(value)


def start(command: str, *, forced: bool = False, quiet: bool = False, stream=None):
    """Starts the command's ticker when progress is wanted (see the module docs); returns it or None.
    quiet: no progress (--quiet, --json)."""
    stream = stream or sys.stderr
    terminal = hasattr(stream, "isatty") and stream.isatty()
    if quiet or not (terminal or forced):
        return None
    ticker = Ticker(command, redraw=terminal, stream=stream).start()
    _state["ticker"] = ticker
    return ticker


class Attached:
    """Another progress display (batch's tqdm bar) driven like a ticker: redrawn every second, so
    its clock runs during a long asset, and cleared before a warning prints."""

    def __init__(self, clear, redraw):
        self._clear, self._redraw = clear, redraw
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="topstoc-progress", daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        while not self._stop.wait(2 * TICK_SECONDS):
            with _lock:
                self._redraw()

    def stage(self, text: str) -> None:
        pass

    def clear(self) -> None:
        with _lock:
            self._clear()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()


def attach(clear, redraw) -> None:
    """Makes another display the progress line (see Attached)."""
    stop()
    _state["ticker"] = Attached(clear, redraw)


def stop() -> None:
    ticker, _state["ticker"] = _state["ticker"], None
    if ticker is not None:
        ticker.stop()


def print_line(text: str, stream=None) -> None:
    """Prints one line with the progress line out of its way (no redraw can cut in)."""
    stream = stream or sys.stderr
    with _lock:
        clear()
        stream.write(text + "\n")
        stream.flush()


class StopOnOutput:
    """Standard output that ends the progress line at its first write: a command's report comes
    when its work is done, and must not share a line with the progress."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        if _state["ticker"] is not None:
            stop()
        return self._stream.write(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def stage(text: str) -> None:
    """Names what the command does now (shown on the progress line, if any)."""
    ticker = _state["ticker"]
    if ticker is not None:
        ticker.stage(text)


def clear() -> None:
    """Clears the progress line before another message prints on standard error."""
    ticker = _state["ticker"]
    if ticker is not None:
        ticker.clear()
