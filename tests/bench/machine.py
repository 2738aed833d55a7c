"""What every benchmark prints about the machine it ran on."""

import os
import pathlib
import platform


def machine() -> str:
    """Cores, OpenMP threads, CPU model, kernel and load average, on one line."""
    model = "unknown CPU"
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    threads = os.environ.get("OMP_NUM_THREADS", str(os.cpu_count()))
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"{os.cpu_count()} cores ({threads} OpenMP threads), {model}, "
            f"{platform.system()} {platform.release()}, load average {load}")
