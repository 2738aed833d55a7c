"""What every benchmark prints about the machine it ran on."""

import os
import pathlib
import platform


def machine() -> str:
    """Cores, the engine's thread limit, CPU model, kernel and load average, on one line."""
    model = "unknown CPU"
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    threads = os.environ.get("TOPSTOC_NUM_THREADS") or os.environ.get("OMP_NUM_THREADS") or str(os.cpu_count())
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"{os.cpu_count()} cores (at most {threads} threads), {model}, "
            f"{platform.system()} {platform.release()}, load average {load}")


def save_figures(path: str, benchmark: str, method: str, **figures) -> None:
    """A benchmark's figures as JSON for scripts/benchmarks_md.py, with the machine and the date,
    written atomically (never a half-written file under the final name)."""
    import json
    import time

    document = {"benchmark": benchmark, "machine": machine(), "date": time.strftime("%Y-%m-%d"), "method": method,
                **figures}
    temporary = pathlib.Path(str(path) + ".tmp")
    temporary.write_text(json.dumps(document, indent=1) + "\n")
    temporary.replace(path)
