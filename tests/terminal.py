"""A pseudo-terminal for tests of what the command line draws on a terminal."""

import fcntl
import os
import pty
import select
import struct
import termios
import time


def open_terminal(columns: int = 100, rows: int = 30):
    """A pseudo-terminal ``columns`` wide (tqdm needs a width): (master, slave)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", rows, columns, 0, 0))
    return master, slave


def read_all(master, process, timeout=600) -> str:
    """Everything written to the terminal until the process ends."""
    chunks, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                data = os.read(master, 65536)
            except OSError:   # EIO: every slave end is closed
                break
            if not data:
                break
            chunks.append(data)
        elif process.poll() is not None:
            break
    return b"".join(chunks).decode(errors="replace")
