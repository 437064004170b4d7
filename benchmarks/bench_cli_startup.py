"""How fast does `gearte --help` answer? (issue 2: goal ≤ 150 ms).

Baseline measured in the same run: a bare Python interpreter start (`python -c pass`), so the ratio
shows what gearte's CLI adds on top of Python itself.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time


def _time(cmd: list[str], repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    base = _time([sys.executable, "-c", "pass"])
    cli = _time([sys.executable, "-m", "gearte", "--help"])
    print(f"python -c pass        : {base * 1e3:7.1f} ms (median of 7)")
    print(f"gearte --help         : {cli * 1e3:7.1f} ms (median of 7; goal ≤ 150 ms)")
    print(f"ratio (cli / python)  : {cli / base:7.2f}")


if __name__ == "__main__":
    main()
