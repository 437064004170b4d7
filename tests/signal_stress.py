"""Signal stress harness: SIGINT / SIGTERM at random times to real ``gearte run`` processes.

Each trial starts ``gearte run CASE`` (the ``gearte`` command's entry point, a process of its
own session, with Python's own SIGINT handler as in a terminal), waits a random delay, sends the
signal to the whole process group (as Ctrl-C in a terminal does) and waits for the exit, at most
``--timeout`` seconds; a process still alive then is a **hang** (its group is killed with SIGKILL
and reaped). Outcomes:

* ``stopped``: exit 128 + signal, one ``interrupted`` message, no traceback; the output folder
  holds a set marked ``"partial": true`` whose first warning says what was cut (``partial``), or
  the previous set stays untouched (``nothing written``), or — the signal came after the whole
  set was written — the complete set, and the message says so (``complete``);
* ``finished``: exit 0 before the signal came (the delay was longer than the run);
* ``hang``, or ``bad`` (any other exit code, a traceback, a partial set without its warning).

The cases are a Monte-Carlo (``jiang2024_spur_pair`` with 1e9 samples), a planetary
Monte-Carlo (``wang2013_2kh_eq9`` with 1e6 samples) and a yield run with an allocation search
(``hu2020_rv80e_yield``), each on 2 worker threads or processes. ``--load N`` runs N busy
processes beside them. Usage (docs/errors.md, "Signals")::

    nice -n 10 python tests/signal_stress.py --count 50 --load 2 --record out/signals.jsonl

runs 50 SIGINT and 50 SIGTERM trials (cases and schedulers in turn) and prints the tallies.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

#: The child: Python's own SIGINT handler (a job started in the background of a non-interactive
#: shell inherits SIGINT ignored), then the CLI.
CLI = (
    "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "from gearte.cli import entry; entry()"
)

#: ``(name, case, extra arguments, largest delay before the signal [s])``: each run takes 5 to
#: 10 s on a 2-core machine with the two busy processes beside it, so most signals land in the
#: sampled work (from start-up to the writing of the outputs) and a few after the end.
CASES = [
    ("monte_carlo", "jiang2024_spur_pair", ["--samples", "1000000000"], 5.0),
    ("planetary_monte_carlo", "wang2013_2kh_eq9", ["--samples", "1000000"], 5.0),
    ("yield_allocation", "hu2020_rv80e_yield", [], 5.0),
]
SCHEDULERS = ["threads", "processes"]


def trial(
    name: str,
    case: str,
    extra: list[str],
    scheduler: str,
    sig: int,
    delay_s: float,
    timeout_s: float,
    workdir: Path,
) -> dict:
    """One run signalled after ``delay_s``; the outcome as a JSON-ready dict."""
    out = workdir / "o"
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text("old")
    (out / ".gearte-outputs.json").write_text(
        json.dumps({"gearte": "old", "files": ["results.json"]})
    )
    args = [case, "--out", str(out), "--no-report", "--no-progress", "--workers", "2"]
    cmd = [sys.executable, "-c", CLI, "run", *args, "--scheduler", scheduler, *extra]
    env = {**os.environ, "GEARTE_DEBUG": "1"}  # a bug shows its traceback (counted as bad)
    t0 = time.monotonic()
    p = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        env=env,
    )
    rec: dict = {"case": name, "scheduler": scheduler, "signal": signal.Signals(sig).name}
    rec["delay_s"] = round(delay_s, 2)
    try:
        p.wait(timeout=delay_s)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, sig)
        rec["signalled"] = True
    try:
        _, err = p.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        rec.update(outcome="hang", wall_s=round(time.monotonic() - t0, 2))
        return rec
    rec["rc"] = p.returncode
    rec["wall_s"] = round(time.monotonic() - t0, 2)
    rec["message"] = err.strip().splitlines()[-1][:300] if err.strip() else ""
    if "Traceback" in err:
        rec["outcome"] = "bad"
        rec["why"] = "traceback"
        rec["stderr"] = err[-4000:]
        return rec
    if p.returncode == 0:
        rec["outcome"] = "finished"
        return rec
    if p.returncode != 128 + sig:
        rec["outcome"] = "bad"
        rec["why"] = f"exit {p.returncode}"
        rec["stderr"] = err[-4000:]
        return rec
    text = (out / "results.json").read_text()
    if text == "old":
        ok = "nothing written" in err
        rec["outcome"] = "stopped" if ok else "bad"
        rec["kept"] = "nothing written"
        return rec
    doc = json.loads(text)
    if doc.get("partial") is not True and "complete results were written" in err:
        rec["outcome"] = "stopped"  # the signal came after the whole set was written
        rec["kept"] = "complete"
        return rec
    warn = (doc.get("warnings") or [""])[0]
    ok = doc.get("partial") is True and warn.startswith("PARTIAL result")
    rec["outcome"] = "stopped" if ok else "bad"
    rec["kept"] = "partial"
    rec["cut"] = warn[:400]
    return rec


def _burn() -> None:  # pragma: no cover - a load generator
    while True:
        pass


def run(count: int, load: int, timeout_s: float, seed: int, record: Path | None) -> Counter:
    """``count`` SIGINT and ``count`` SIGTERM trials, cases and schedulers in turn; the tally."""
    rng = random.Random(seed)
    burners = [multiprocessing.Process(target=_burn, daemon=True) for _ in range(load)]
    for b in burners:
        b.start()
    tally: Counter = Counter()
    fh = record.open("a") if record else None
    try:
        trials = [(sig, i) for i in range(count) for sig in (signal.SIGINT, signal.SIGTERM)]
        for n, (sig, i) in enumerate(trials):
            name, case, extra, max_delay = CASES[i % len(CASES)]
            scheduler = SCHEDULERS[(i // len(CASES)) % len(SCHEDULERS)]
            delay = rng.uniform(0.5, max_delay)
            with tempfile.TemporaryDirectory(prefix="gearte-signals-") as tmp:
                rec = trial(name, case, extra, scheduler, sig, delay, timeout_s, Path(tmp))
            tally[(rec["signal"], rec["outcome"], rec.get("kept", ""))] += 1
            print(f"{n + 1}/{len(trials)} {json.dumps(rec)}", flush=True)
            if fh:
                fh.write(json.dumps(rec) + "\n")
                fh.flush()
    finally:
        for b in burners:
            b.terminate()
            b.join()
        if fh:
            fh.close()
    return tally


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=50, help="trials per signal")
    ap.add_argument("--load", type=int, default=2, help="busy processes beside the runs")
    ap.add_argument("--timeout", type=float, default=120.0, help="after the signal [s]")
    ap.add_argument("--seed", type=int, default=33)
    ap.add_argument("--record", type=Path, default=None)
    a = ap.parse_args()
    tally = run(a.count, a.load, a.timeout, a.seed, a.record)
    for key, n in sorted(tally.items()):
        print(" ".join(k for k in key if k), n)
    bad = sum(n for (_, outcome, _), n in tally.items() if outcome in ("hang", "bad"))
    print(f"hangs/bad: {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
