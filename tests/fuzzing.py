"""Fuzzing harness for case files (issue 13): a mutation corpus built from the bundled cases.

Each mutant is a bundled case with one to three mutations (a value replaced by a hostile one, a
key deleted, misspelt or added, a list emptied or blown up, deep nesting, a hostile name, or the
TOML text cut or corrupted). Every mutant is written as TOML text and goes through
:func:`gearte.io.case_file.load_case` — what ``gearte validate`` and ``gearte run`` call first —
and is classified:

* ``accepted``: validated; then checked for **silent coercion** (every input value the case kept
  must keep its type category: a bool stays a bool, a string a string, an int may fill a float);
* ``rejected``: a ``CaseFileError``; every line must be one line naming a key;
* ``crash``: any other exception (would be exit 3 "bug" in the CLI).

Accepted mutants also go through ``gearte run`` (``--runs N``, ``-1``: every accepted mutant),
through the CLI's own entry point (its exit codes, its output writing into a temporary folder),
with ``--samples 4 --workers 1`` (``--samples`` sets every Monte-Carlo count and caps every other
count of sampled work) and tight time/memory budgets (``GEARTE_MAX_SECONDS``/
``GEARTE_MAX_MEMORY_GB``, so an oversized mutant is refused at validation as it would be for a
user), under an address-space limit (:data:`RUN_MEMORY_LIMIT`, the memory bound) and a time-out.
The long job runs them in a **fork server** (:class:`ForkServer`): one parent imports gearte and
runs every bundled case once (every kind's kernels loaded or compiled), then forks a child per
mutant, ``--workers`` at a time; a child past the time-out is killed and reaped; per run the exit
code, the message, peak RSS, CPU and wall time are recorded (``--record``). ``--equivalence N``
runs N further accepted mutants both as real ``gearte run`` processes and through the fork
server and compares the outcomes. Exit 0, 1 or 2 with one error line (naming the key for bad
input) is fine; exit 3 (a bug), a crash, a time-out, a run past the memory bound or a malformed
message is not; and the input recorded in ``results.json`` must keep every given value's type
(no coercion through ``run`` either).

Measurement files are fuzzed too (``--files N``): the bundled bench files (TE traces, hysteresis
curve, :mod:`gearte.io.bench`), one file of each metrology format written from seeded parts and
the bundled lot's metrology files (:mod:`gearte.io.metrology`), mutated line- and cell-wise
(hostile cells, deleted, duplicated or swapped rows, ×50 blow-ups, renamed or re-united columns,
hostile metadata, cut or corrupted bytes), read by their reader: a complete object with finite
numbers, or one ``BenchFileError``/``MeasurementFileError`` line naming the file; anything else
is a crash. The lot's bore and eccentricity files are also checked against the lot's design, as
``validate`` and ``run`` check them, and an accepted file whose header gives a length column
another unit than its base file's is counted as ``file_unit_slip_accepted`` (silent nonsense:
must stay 0).

``--count -1`` replaces the random mutants by the **systematic sweep of extreme values**
(:func:`extreme_mutants`, ``make fuzz-extremes``): every positive number of every bundled case
set in turn to 1e-300, × 1e-9 and × 1e9, so every key is reached (docs/errors.md, "The
extreme-value sweep").

Small runs are part of the test suite (``tests/test_fuzz_cases.py``, hypothesis-driven); the long
job is ``make fuzz`` (``python tests/fuzzing.py --count 10000 --files 10000 --runs -1``), which
prints the tallies.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import random
import re
import sys
import time
import tomllib
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

HOSTILE_VALUES: list[Any] = [
    True,
    False,
    "1.3",
    "",
    "x" * 300,
    0,
    -1,
    1e300,
    -1e300,
    1e-300,
    10**30,
    -(10**30),
    2**63,
    float("nan"),
    float("inf"),
    float("-inf"),
    [],
    {},
    [1, 2, 3],
    {"a": 1},
    1000000.0,
    0.1234567,
    "../../x",
    "a\u0000b",
    "7/8",
    "1/0",
]
UNIT_SWAPS = [
    ("_mm", "_um"),
    ("_um", "_mm"),
    ("_Nm", "_Nmm"),
    ("_deg", "_rad"),
    ("_arcmin", "_arcsec"),
    ("_N", "_kN"),
]


# ----------------------------------------------------------------------------- TOML writing
def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # JSON escapes are valid TOML basic-string escapes
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(str(k))} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(data: dict[str, Any]) -> str:
    """A minimal TOML writer: top-level tables as ``[section]``, deeper tables inline."""
    lines: list[str] = []
    for k, v in data.items():
        if not isinstance(v, dict):
            lines.append(f"{_key(k)} = {_value(v)}")
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(f"[{_key(k)}]")
            lines += [f"{_key(str(kk))} = {_value(vv)}" for kk, vv in v.items()]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- mutation
def corpus() -> dict[str, dict[str, Any]]:
    """The bundled cases, parsed."""
    from gearte.cases import list_cases

    return {
        name: tomllib.loads(path.read_text(encoding="utf-8")) for name, path in list_cases().items()
    }


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out: list[tuple[Any, ...]] = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((*prefix, k))
            out += _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((*prefix, i))
            out += _paths(v, (*prefix, i))
    return out


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    node = data
    for p in path[:-1]:
        node = node[p]
    return node


def _typo(key: str, rng: random.Random) -> str:
    for a, b in UNIT_SWAPS:
        if key.endswith(a) and rng.random() < 0.5:
            return key[: -len(a)] + b
    if len(key) > 2:
        i = rng.randrange(len(key))
        return key[:i] + key[i + 1 :]
    return key + "x"


def mutate(data: dict[str, Any], rng: random.Random) -> tuple[dict[str, Any], str]:
    """One mutation of a deep copy of ``data``; returns it and a description."""
    data = json.loads(json.dumps(data))  # deep copy (TOML data is JSON-able, no dates here)
    paths = [p for p in _paths(data) if p[0] != "case" or rng.random() < 0.3]
    if not paths:
        return data, "none"
    path = rng.choice(paths)
    parent, last = _parent(data, path), path[-1]
    op = rng.choice(
        ["value", "value", "value", "delete", "typo", "unknown", "list", "deep", "scale", "kind"]
    )
    where = ".".join(map(str, path))
    if op == "value":
        parent[last] = rng.choice(HOSTILE_VALUES)
        return data, f"value {where} = {parent[last]!r}"[:120]
    if (
        op == "scale"
        and isinstance(parent[last], int | float)
        and not isinstance(parent[last], bool)
    ):
        parent[last] = parent[last] * rng.choice([-1, 0, 1e-9, 1e9, 1.5, 2])
        return data, f"scale {where}"
    if op == "delete" and isinstance(parent, dict):
        del parent[last]
        return data, f"delete {where}"
    if op in ("typo", "unknown") and isinstance(parent, dict):
        new = _typo(str(last), rng)
        if op == "typo":
            parent[new] = parent.pop(last)
        else:
            parent[new] = parent[last]
        return data, f"{op} {where} -> {new}"
    if op == "list" and isinstance(parent[last], list):
        v = parent[last]
        parent[last] = rng.choice([[], v * 50, v[:1], list(reversed(v)) + v])
        return data, f"list {where} len {len(parent[last])}"
    if op == "deep":
        depth = rng.choice([8, 40, 300])
        v: Any = parent[last]
        for _ in range(depth):
            v = [v]
        parent[last] = v
        return data, f"deep {where} x{depth}"
    if op == "kind" and isinstance(data.get("case"), dict):
        data["case"]["kind"] = rng.choice(
            ["cycloid_stage", "gear_pair", "planetary", "rv_reducer", "rv_dynamics", "nope", 1]
        )
        return data, f"kind {data['case']['kind']!r}"
    parent[last] = rng.choice(HOSTILE_VALUES)
    return data, f"value {where}"[:120]


def mutant_text(base: dict[str, Any], rng: random.Random) -> tuple[str, str]:
    """A mutant case file (TOML text) and what was done to it."""
    data, done = base, []
    for _ in range(rng.choice([1, 1, 2, 3])):
        data, d = mutate(data, rng)
        done.append(d)
    try:
        text = to_toml(data)
    except (TypeError, ValueError, RecursionError):
        text, done = to_toml(base), [*done, "(unwritable: base)"]
    r = rng.random()
    if r < 0.05:
        cut = rng.randrange(len(text))
        text, done = text[:cut], [*done, f"cut at {cut}"]
    elif r < 0.1:
        i = rng.randrange(len(text))
        text, done = (
            text[:i] + rng.choice(["\x00", "[", "]", '"', "=", "\n[x]\n"]) + text[i:],
            [
                *done,
                f"byte at {i}",
            ],
        )
    return text, "; ".join(done)


#: The extreme values of the systematic sweep (``--extremes``): each positive number of a
#: bundled case replaced by the smallest positive double-ish value, and scaled by 1e-9 and 1e9.
EXTREMES: list[tuple[str, Callable[[float], float]]] = [
    ("= 1e-300", lambda v: 1e-300),
    ("x 1e-9", lambda v: v * 1e-9),
    ("x 1e9", lambda v: v * 1e9),
]


def extreme_mutants() -> list[tuple[str, str, str]]:
    """Every positive number of every bundled case (the first element of a list) replaced in
    turn by each of :data:`EXTREMES`: ``[(base, done, text)]``, in a fixed order. Unlike the
    random mutants, this sweep reaches every key: a value inside the schema's range that no
    drive could have must be refused naming the key, not end as a solver that did not
    converge."""
    out = []
    for name, data in sorted(corpus().items()):
        for path in _paths(data):
            if path[0] == "case" or (isinstance(path[-1], int) and path[-1] != 0):
                continue
            v = _parent(data, path)[path[-1]]
            if isinstance(v, bool) or not isinstance(v, int | float) or v <= 0:
                continue
            where = ".".join(map(str, path))
            for label, f in EXTREMES:
                new = json.loads(json.dumps(data))
                _parent(new, path)[path[-1]] = float(f(float(v)))
                out.append((name, f"extreme {where} {label}", to_toml(new)))
    return out


# ----------------------------------------------------------------------------- checking
@dataclass
class Outcome:
    status: str  # accepted | rejected | crash | coerced | bad_message
    detail: str = ""


def _coercions(given: Any, kept: Any, path: str = "") -> list[str]:
    """Input values whose type category changed in the validated case (silent coercion)."""
    out: list[str] = []
    if isinstance(given, dict) and isinstance(kept, dict):
        for k, v in given.items():
            if k in kept:
                out += _coercions(v, kept[k], f"{path}.{k}" if path else str(k))
        return out
    if isinstance(given, list) and isinstance(kept, list | tuple):
        for i, (g, k) in enumerate(zip(given, kept, strict=False)):
            out += _coercions(g, k, f"{path}.{i}")
        return out
    if isinstance(given, bool) != isinstance(kept, bool):
        out.append(f"{path}: {given!r} -> {kept!r}")
    elif isinstance(given, str) and not isinstance(kept, str):
        out.append(f"{path}: {given!r} -> {kept!r}")
    elif isinstance(given, int | float) and isinstance(kept, str):
        out.append(f"{path}: {given!r} -> {kept!r}")
    elif isinstance(given, float) and isinstance(kept, int) and not isinstance(kept, bool):
        out.append(f"{path}: {given!r} -> {kept!r}")
    return out


def _one_problem_a_line(msg: str, path: str | None = None) -> bool:
    """A reader's message is one line, or ``N problems:`` and then one line per problem, each
    naming its file (``path`` where given; a file name otherwise): what ``gearte validate``
    prints for a series of bench files (every problem of every file)."""
    lines = msg.splitlines()
    if len(lines) == 1:
        return path is None or path in msg
    if not re.fullmatch(r"\d+ problems:", lines[0]):
        return False
    name = re.compile(r"\S+\.(csv|txt|tsv|dat|toml)\b")
    return all((path in line) if path else bool(name.search(line)) for line in lines[1:])


def check_text(text: str, tmp: Path) -> Outcome:
    """Validate one case file text as ``gearte validate`` would and classify the outcome."""
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case

    link_case_data(tmp)
    path = tmp / "mutant.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        case = load_case(path)
    except CaseFileError as exc:
        for field, msg in exc.errors:
            if "\n" in field or "\n" in msg or not field.strip():
                return Outcome("bad_message", f"{field!r}: {msg!r}")
        return Outcome("rejected", exc.errors[0][0])
    except Exception as exc:  # noqa: BLE001 - what the harness looks for
        return Outcome("crash", f"{type(exc).__name__}: {str(exc)[:200]}")
    # the pre-flight `gearte validate` makes after the schema (checks on the built drive), under
    # the budgets the fuzzed runs get, so an accepted mutant is one `run` should not refuse
    from gearte.errors import BenchFileError, ParameterError
    from gearte.studies import preflight

    saved = {k: os.environ.get(k) for k in RUN_BUDGETS}
    os.environ.update(RUN_BUDGETS)
    try:
        preflight(case)
    except ParameterError as exc:
        if "\n" in str(exc) or not exc.field.strip():
            return Outcome("bad_message", repr(str(exc)))
        return Outcome("rejected", exc.field)
    except BenchFileError as exc:  # rv_bench's pre-flight reads its bench files
        if not _one_problem_a_line(str(exc)) or not exc.file.strip():
            return Outcome("bad_message", repr(str(exc)))
        return Outcome("rejected", exc.file)
    except CaseFileError as exc:  # a case file the pre-flight loads (a chain's drive case)
        return Outcome("rejected", exc.errors[0][0])
    except Exception as exc:  # noqa: BLE001 - what the harness looks for
        return Outcome("crash", f"preflight {type(exc).__name__}: {str(exc)[:200]}")
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    try:
        given = tomllib.loads(text)
    except Exception:  # noqa: BLE001
        return Outcome("accepted")
    kept = case.model_dump(mode="python")
    found = _coercions(given, kept)
    return Outcome("coerced", "; ".join(found)[:300]) if found else Outcome("accepted")


#: Address-space limit of each run (``--runs``) [bytes]: the memory bound. A run past it fails to
#: allocate (``MemoryError``), which the harness counts as ``run_memory``.
RUN_MEMORY_LIMIT = 6 * 2**30
#: ``--samples`` of fuzzed runs: sets every Monte-Carlo / yield / batch count and caps every other
#: count of sampled work (Sobol, bootstrap, allocation, sweeps: ``gearte.studies.sample_cap``).
RUN_SAMPLES = 4
#: Budgets of fuzzed runs (gearte.limits): an oversized mutant is refused at validation.
RUN_BUDGETS = {"GEARTE_MAX_SECONDS": "20", "GEARTE_MAX_MEMORY_GB": "2"}
#: Outcomes of a run that fail the harness.
BAD_RUN = (
    "run_bug",
    "run_crash",
    "run_timeout",
    "run_memory",
    "run_coerced",
    "run_bad_message",
)


_LINKED: set[Path] = set()


def link_case_data(tmp: Path) -> None:
    """Make the bundled cases' data folders (bench files, the lot's metrology files) reachable
    from ``tmp`` as from ``examples/``, so mutants of the data-backed cases written there still
    find their files (otherwise they could only ever be rejected)."""
    from gearte.cases import case_path

    if tmp in _LINKED:
        return
    _LINKED.add(tmp)
    examples = case_path("synthetic_rv_bench").parent
    for entry in examples.iterdir():
        link = tmp / entry.name
        if entry.is_dir() and not link.exists():
            link.symlink_to(entry, target_is_directory=True)


def run_args(path: Path, out: Path, report: bool = False) -> list[str]:
    """Arguments of ``gearte run`` for a fuzzed case file (small samples, one worker)."""
    args = ["run", str(path), "--out", str(out), "--no-progress"]
    args += ["--samples", str(RUN_SAMPLES), "--workers", "1"]
    return args if report else [*args, "--no-report"]


_KEYED = re.compile(r"^error \((invalid parameter|invalid case|invalid data file|not found)\): \S")


def classify_run(code: int, stderr: str, text: str, out: Path) -> Outcome:
    """The outcome of one ``gearte run`` of an accepted mutant from its exit code, its stderr and
    its output folder: exit 0, 1 (analysis failed) or 2 (bad input) with one error line (naming
    the key for bad input) are fine; exit 3 (a bug), a ``MemoryError`` (past the memory bound), a
    malformed message or a coerced input in ``results.json`` are not."""
    errors = [ln for ln in stderr.splitlines() if ln.startswith("error (")]
    last = (errors or stderr.strip().splitlines() or [""])[-1][:200]
    if "MemoryError" in stderr:
        return Outcome("run_memory", last)
    if code not in (0, 1, 2):
        return Outcome("run_bug", f"exit {code}: {stderr[-300:]}")
    if code in (1, 2):
        if len(errors) != 1 or (code == 2 and not _KEYED.match(errors[0])):
            return Outcome("run_bad_message", f"exit {code}: {stderr[-300:]}")
        if errors[0].startswith("error (invalid parameter)") and " = " not in errors[0]:
            return Outcome("run_bad_message", errors[0][:300])
    if code == 0:
        doc = json.loads((out / "results.json").read_text(encoding="utf-8"))
        found = _coercions(tomllib.loads(text), doc["case"]["input"])
        if found:
            return Outcome("run_coerced", "; ".join(found)[:300])
    return Outcome(f"run_exit_{code}", last)


class _Alarm(KeyboardInterrupt):
    """The per-run alarm of :func:`run_cli`: stops the run as Ctrl-C would (also inside a
    compiled kernel, where CPython reports it as a SystemError caused by it)."""


def _cli_exit_code(args: list[str]) -> int:
    """``gearte run`` through the CLI's entry point in this process; its exit code."""
    from gearte.cli import main as cli_main

    try:
        cli_main(args, standalone_mode=False)
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def run_cli(text: str, tmp: Path, timeout_s: float, report: bool = False) -> Outcome:
    """``gearte run`` of an accepted mutant through the CLI entry point, in this process, with a
    per-run alarm (the small in-suite share; :class:`ForkServer` for the long job)."""
    import io
    import os
    import signal

    link_case_data(tmp)
    path = tmp / "run.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp / "out"
    fired = []

    def alarm(_signum: int, _frame: Any) -> None:
        fired.append(True)
        raise _Alarm

    old_env = {k: os.environ.get(k) for k in RUN_BUDGETS}
    os.environ.update(RUN_BUDGETS)
    old = signal.signal(signal.SIGALRM, alarm)
    old_term = signal.getsignal(signal.SIGTERM)  # the CLI installs its own: restore it after
    signal.setitimer(signal.ITIMER_REAL, timeout_s)
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = _cli_exit_code(run_args(path, out, report))
    except _Alarm:
        return Outcome("run_timeout", f"over {timeout_s} s")
    except MemoryError:
        return Outcome("run_memory", "MemoryError past the address-space limit")
    except Exception as exc:  # noqa: BLE001 - click usage errors and anything else
        return Outcome("run_bug", f"{type(exc).__name__}: {str(exc)[:200]}")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        signal.signal(signal.SIGTERM, old_term)
        for k, v in old_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    if fired:
        return Outcome("run_timeout", f"over {timeout_s} s (exit {code})")
    return classify_run(code, err.getvalue(), text, out)


def run_subprocess(text: str, tmp: Path, timeout_s: float, report: bool = False) -> Outcome:
    """``gearte run`` of a mutant as a real process (``python -m gearte``), same arguments,
    budgets and memory bound as the fork server: the reference the fork server is checked
    against (:func:`main`'s ``--equivalence``)."""
    import os
    import resource
    import subprocess

    tmp.mkdir(parents=True, exist_ok=True)
    link_case_data(tmp)
    path = tmp / "run.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp / "out"
    env = {**os.environ, **RUN_BUDGETS}

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (RUN_MEMORY_LIMIT, RUN_MEMORY_LIMIT))

    cmd = [sys.executable, "-m", "gearte", *run_args(path, out, report)]
    try:
        p = subprocess.run(
            cmd, capture_output=True, text=True, env=env, timeout=timeout_s, preexec_fn=limit
        )
    except subprocess.TimeoutExpired:
        return Outcome("run_timeout", f"over {timeout_s} s")
    if p.returncode < 0:
        return Outcome("run_crash", f"killed by signal {-p.returncode}: {p.stderr[-300:]}")
    return classify_run(p.returncode, p.stderr, text, out)


# ----------------------------------------------------------------------------- fork server
@dataclass
class RunRecord:
    """One fuzzed run: which mutant, its outcome, and what it cost."""

    index: int
    base: str
    done: str
    status: str
    code: int | None
    message: str
    peak_rss_mb: float
    wall_s: float
    cpu_s: float


def _single_threaded() -> None:
    """One thread per library before numpy/numba load: forked children must not inherit a BLAS
    or numba thread pool (a fork copies only the calling thread), and the machine is shared."""
    import os

    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ.setdefault(var, "1")


class ForkServer:
    """Runs accepted mutants through ``gearte run`` in forked children of one warm parent.

    The parent imports gearte and runs every bundled case once (:meth:`warm`: every kind's
    module imported, every kernel loaded or compiled), then forks one child per mutant. The
    child is ``gearte run`` in-process — the CLI's entry point, its exit codes and its output
    writing into a temporary folder — under an address-space limit (:data:`RUN_MEMORY_LIMIT`,
    the memory bound) with its stdout/stderr in files. At most ``workers`` children run at once;
    a child past ``timeout_s`` is killed (SIGKILL) and reaped. Per run the parent records the
    exit code, the message, the child's peak RSS and CPU time (``wait4``) and the wall time.
    """

    def __init__(
        self,
        root: Path,
        workers: int,
        timeout_s: float,
        report: bool = False,
        on_record: Callable[[RunRecord], None] | None = None,
        cpu_limit_s: int | None = None,
    ) -> None:
        self.root, self.workers, self.timeout_s, self.report = root, workers, timeout_s, report
        self.cpu_limit_s = cpu_limit_s
        self.running: dict[int, tuple[tuple[int, str, str, str], float, Path]] = {}
        self.records: list[RunRecord] = []
        self.on_record = on_record
        link_case_data(root)

    def warm(self, names: list[str] | None = None) -> dict[str, str]:
        """Run each bundled case once in this process (small samples); ``{name: outcome}``."""
        import tempfile

        bases = corpus()
        got = {}
        for name in names if names is not None else sorted(bases):
            with tempfile.TemporaryDirectory(dir=self.root) as d:
                got[name] = run_cli(to_toml(bases[name]), Path(d), 600.0, self.report).status
        return got

    def submit(self, index: int, base: str, done: str, text: str) -> None:
        """Fork a child that runs ``text`` (waits for a free slot first)."""
        import os
        import tempfile

        while len(self.running) >= self.workers:
            self._reap(block=True)
        d = Path(tempfile.mkdtemp(prefix=f"run{index}-", dir=self.root))
        (d / "run.toml").write_text(text, encoding="utf-8")
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            self._child(d, text)
        self.running[pid] = ((index, base, done, text), time.monotonic(), d)

    def _child(self, d: Path, text: str) -> None:
        import os
        import resource

        code = 99
        try:
            resource.setrlimit(resource.RLIMIT_AS, (RUN_MEMORY_LIMIT, RUN_MEMORY_LIMIT))
            if self.cpu_limit_s is not None:  # CPU time: fair on a machine shared with others
                used = resource.getrusage(resource.RUSAGE_SELF)
                lim = int(used.ru_utime + used.ru_stime) + self.cpu_limit_s
                resource.setrlimit(resource.RLIMIT_CPU, (lim, lim + 5))
            os.environ.update(RUN_BUDGETS)
            for fd, name in ((1, "stdout"), (2, "stderr")):
                f = os.open(d / name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
                os.dup2(f, fd)
                os.close(f)
            # Python's streams onto those files (under pytest they point at its capture)
            sys.stdout = open(1, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
            sys.stderr = open(2, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
            code = _cli_exit_code(run_args(d / "run.toml", d / "out", self.report))
        except BaseException as exc:  # noqa: BLE001 - a click usage error or anything else
            what = "MemoryError" if isinstance(exc, MemoryError) else type(exc).__name__
            print(f"harness: {what}: {exc}", file=sys.stderr)
            code = 98
        finally:
            with contextlib.suppress(Exception):
                sys.stdout.flush()
                sys.stderr.flush()
            os._exit(code)

    def _finish(self, pid: int, status: int, ru: Any, timed_out: bool) -> None:
        import os
        import shutil
        import signal

        (index, base, done, text), t0, d = self.running.pop(pid)
        wall = time.monotonic() - t0
        stderr = (d / "stderr").read_text("utf-8", "replace") if (d / "stderr").exists() else ""
        code: int | None = None
        if timed_out:
            out = Outcome("run_timeout", f"over {self.timeout_s} s, killed")
        elif os.WIFSIGNALED(status) and (
            os.WTERMSIG(status) == signal.SIGXCPU
            or (  # the hard CPU limit
                os.WTERMSIG(status) == signal.SIGKILL
                and self.cpu_limit_s is not None
                and ru.ru_utime + ru.ru_stime >= self.cpu_limit_s
            )
        ):
            out = Outcome("run_timeout", f"over {self.cpu_limit_s} s of CPU, stopped")
        elif os.WIFSIGNALED(status):
            out = Outcome("run_crash", f"signal {os.WTERMSIG(status)}: {stderr[-300:]}")
        else:
            code = os.WEXITSTATUS(status)
            try:
                out = classify_run(code, stderr, text, d / "out")
            except Exception as exc:  # noqa: BLE001 - an unreadable results.json
                out = Outcome("run_bug", f"exit {code}, results unreadable: {exc}")
        self.records.append(
            RunRecord(
                index,
                base,
                done,
                out.status,
                code,
                out.detail.splitlines()[0][:200] if out.detail else "",
                ru.ru_maxrss / 1024,
                wall,
                ru.ru_utime + ru.ru_stime,
            )
        )
        shutil.rmtree(d, ignore_errors=True)
        if self.on_record is not None:
            self.on_record(self.records[-1])

    def _reap(self, block: bool) -> None:
        import os
        import signal

        while True:
            done = False
            for pid, (_job, t0, _d) in list(self.running.items()):
                got, status, ru = os.wait4(pid, os.WNOHANG)
                if got:
                    self._finish(pid, status, ru, False)
                    done = True
                elif time.monotonic() - t0 > self.timeout_s:
                    os.kill(pid, signal.SIGKILL)
                    _, status, ru = os.wait4(pid, 0)
                    self._finish(pid, status, ru, True)
                    done = True
            if done or not block or not self.running:
                return
            time.sleep(0.02)

    def poll(self) -> None:
        """Reap finished children and kill those past the time-out, without waiting."""
        self._reap(block=False)

    def drain(self) -> list[RunRecord]:
        """Wait for every child; the records of all runs so far."""
        while self.running:
            self._reap(block=True)
        return self.records


# ----------------------------------------------------------------------------- measurement files
BENCH_READERS = {"te_trace": "read_te_trace", "hysteresis": "read_hysteresis"}
METROLOGY_READERS = {
    "disc_profile": "read_disc_profiles",
    "disc_pitch": "read_disc_pitch",
    "pins": "read_pins",
    "crank_eccentricity": "read_crank_eccentricity",
    "disc_bores": "read_disc_bores",
    "runout": "read_runout",
    "bearing_clearance": "read_bearing_clearances",
}
HOSTILE_CELLS = [
    "",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e309",
    "-1e309",
    "1e-320",
    "abc",
    "1,5",
    "0x10",
    "1_000",
    "true",
    "9" * 400,
    "-0",
    '"',
    "\x00",
    "\u00a0",
    "D-01",
    "../../x",
    "1e6",
    "-1e6",
]


def measurement_corpus() -> dict[str, tuple[str, str]]:
    """Base measurement files: ``name -> (reader, text)``; the bundled bench files and one file
    of each metrology format written by its writer from seeded parts."""
    import tempfile

    import numpy as np

    from gearte.cases import case_path
    from gearte.io import metrology as mt

    bench = case_path("synthetic_rv_bench").parent / "synthetic_rv_bench"
    te = sorted((bench / "te").glob("*.csv"))[0]
    files: dict[str, tuple[str, str]] = {
        # the bundled files are a rig's export (units given in the case): units into the header
        "te_trace": (
            "te_trace",
            _thin(
                te.read_text("utf-8").replace(
                    "Angle CW;TE CW;Angle CCW;TE CCW",
                    "Angle CW [deg];TE CW [arcsec];Angle CCW [deg];TE CCW [arcsec]",
                ),
                20,
            ),
        ),  # fmt: skip
        "hysteresis": ("hysteresis", _thin((bench / "hysteresis.csv").read_text("utf-8"), 10)),
    }
    rng = np.random.default_rng(13)
    parts = {
        "disc_profile": (
            mt.write_disc_profiles,
            {
                "D-1": mt.DiscProfile(
                    tuple(np.sort(rng.uniform(-3, 3, 5)) for _ in range(3)),
                    tuple(rng.normal(0, 0.003, 5) for _ in range(3)),
                )
            },
        ),
        "disc_pitch": (mt.write_disc_pitch, {"D-1": rng.normal(0, 0.005, 3)}),
        "pins": (
            mt.write_pins,
            {"H-7": mt.PinSet(rng.uniform(9.9, 10, 4), np.zeros(4), np.zeros(4))},
        ),
        "crank_eccentricity": (
            mt.write_crank_eccentricity,
            {"C-1": mt.CrankCams(rng.uniform(1.4, 1.6, 2), rng.normal(0, 0.01, 2))},
        ),
        "disc_bores": (mt.write_disc_bores, {"D-1": rng.normal(50, 0.01, (3, 2))}),
        "runout": (mt.write_runout, {"P-1": mt.Runout(0.012, 1.3), "P-2": mt.Runout(0.004, -2)}),
        "bearing_clearance": (
            mt.write_bearing_clearances,
            {"C-1": {"cam_1": 0.003, "cam_2": 0.004, "carrier": 0.002}},
        ),
    }
    with tempfile.TemporaryDirectory() as d:
        for fmt, (write, data) in parts.items():
            path = Path(d) / f"{fmt}.csv"
            write(path, data)
            files[fmt] = (fmt, path.read_text("utf-8"))
    # the bundled lot's files (examples/lots/*/), cut to the parts of their first two serials
    for path in sorted((case_path("synthetic_rv_bench").parent / "lots").glob("*/*.csv")):
        text = path.read_text("utf-8")
        fmt = re.search(r"^#\s*format:\s*(\w+)", text, re.M)
        if fmt and fmt[1] in METROLOGY_READERS:
            files[f"lot {path.parent.name}/{path.name}"] = (fmt[1], _first_serials(text, 2))
    return files


def _first_serials(text: str, n: int) -> str:
    """A metrology file with the rows of its first ``n`` serial numbers only."""
    lines = text.splitlines()
    head = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    serials: list[str] = []
    kept = []
    for ln in lines[head + 1 :]:
        serial = ln.split(",", 1)[0]
        if serial not in serials:
            serials.append(serial)
        if len(serials) > n:
            break
        kept.append(ln)
    return "\n".join([*lines[: head + 1], *kept]) + "\n"


def _thin(text: str, every: int) -> str:
    """A bench file with every ``every``-th data row (a few hundred rows: fast to fuzz, still a
    valid file covering the same range)."""
    lines = text.splitlines()
    head = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    rows = lines[head + 1 :]
    kept = rows[::every] + ([rows[-1]] if (len(rows) - 1) % every else [])
    return "\n".join([*lines[: head + 1], *kept]) + "\n"


def mutate_csv(text: str, rng: random.Random) -> tuple[str, str]:
    """One to three line/cell mutations of a measurement file's text, and what was done."""
    lines = text.splitlines()
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        if not lines:
            lines = [""]
        i = rng.randrange(len(lines))
        op = rng.choice(["cell", "cell", "cell", "delete", "dup", "blow", "swap", "header", "meta"])
        if op == "cell":
            cells = re.split(r"([,;\t])", lines[i])
            j = rng.randrange(0, len(cells), 2) if cells else 0
            cells[j] = rng.choice(HOSTILE_CELLS).encode().decode("unicode_escape")
            lines[i] = "".join(cells)
        elif op == "delete":
            del lines[i]
        elif op == "dup":
            lines.insert(i, lines[i])
        elif op == "blow":
            lines = lines[: i + 1] + lines[i:] * rng.choice([2, 50])
        elif op == "swap":
            k = rng.randrange(len(lines))
            lines[i], lines[k] = lines[k], lines[i]
        elif op == "header":
            h = next((n for n, ln in enumerate(lines) if ln and not ln.startswith("#")), 0)
            cells = re.split(r"([,;\t])", lines[h])
            j = rng.randrange(0, len(cells), 2)
            swap = rng.choice(["[um]", "[mm]", "[deg]", "[rad]", "[arcsec]", "[N·m]", "[kg]", ""])
            cells[j] = rng.choice([re.sub(r"\[.*\]", swap, cells[j]), cells[j][:-1], "x"])
            lines[h] = "".join(cells)
            i = h
        else:
            lines.insert(0, rng.choice(["# sped_rpm: 1", "# format: pins", "# torque_Nm: x"]))
        done.append(f"{op}@{i}")
    out = "\n".join(lines) + "\n"
    r = rng.random()
    if r < 0.05:
        cut = rng.randrange(len(out) + 1)
        out, done = out[:cut], [*done, f"cut at {cut}"]
    elif r < 0.1:
        i = rng.randrange(len(out) + 1)
        out = out[:i] + rng.choice(["\x00", "\ufeff", "\r", "\u2028", "\xff"]) + out[i:]
        done.append(f"byte at {i}")
    return out, "; ".join(done)


def _finite(obj: Any) -> bool:
    """Every number of a reader's result is finite (NaN never slips in as data)."""
    import dataclasses

    import numpy as np

    if isinstance(obj, dict):
        return all(_finite(v) for v in obj.values())
    if isinstance(obj, list | tuple):
        return all(_finite(v) for v in obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return all(_finite(getattr(obj, f.name)) for f in dataclasses.fields(obj))
    if isinstance(obj, np.ndarray) and obj.dtype.kind in "fc":
        return bool(np.isfinite(obj).all())
    if isinstance(obj, float):
        return math.isfinite(obj)
    return True


_DESIGN: list[Any] = []


def _lot_design() -> Any:
    """The design reducer of the bundled lot (``han2023_rv110e_no_errors``), built once."""
    if not _DESIGN:
        from gearte.io.case_file import load_case
        from gearte.studies.rv_reducer import build_reducer

        _DESIGN.append(build_reducer(load_case("han2023_rv110e_no_errors").reducer))
    return _DESIGN[0]


def check_measurement(reader: str, text: str, tmp: Path, design: bool = False) -> Outcome:
    """Read one measurement file text with its reader and classify the outcome; with
    ``design`` (a file of the bundled lot), what the reader accepts is also checked against the
    lot's design as ``validate`` and ``run`` check it (bore centres, cam eccentricities:
    :func:`gearte.studies._measured.check_measured_against_design`)."""
    from gearte.errors import BenchFileError, MeasurementFileError
    from gearte.io import bench, metrology
    from gearte.studies._measured import check_measured_against_design

    path = tmp / "measured.csv"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    module, name = (
        (bench, BENCH_READERS[reader])
        if reader in BENCH_READERS
        else (metrology, METROLOGY_READERS[reader])
    )
    try:
        counts = {"disc_bores": {"bores": 3}, "crank_eccentricity": {"cams": 2}}
        kw = counts.get(reader, {}) if design else {}  # the design's counts, as validate passes
        got = getattr(module, name)(path, **kw)
        if design and reader in ("disc_bores", "crank_eccentricity"):
            key = "bores" if reader == "disc_bores" else "cams"
            check_measured_against_design(_lot_design(), str(path), **{key: got})
    except (BenchFileError, MeasurementFileError) as exc:
        msg = str(exc)
        if not _one_problem_a_line(msg, str(path)):  # every problem of the file, one line each
            return Outcome("bad_message", msg[:300])
        return Outcome("rejected", msg[:120])
    except Exception as exc:  # noqa: BLE001 - what the harness looks for
        return Outcome("crash", f"{type(exc).__name__}: {str(exc)[:200]}")
    if not _finite(got):
        return Outcome("nonfinite", "a reader returned NaN/inf")
    return Outcome("accepted")


def _length_units(text: str) -> list[tuple[str, str]]:
    """``(column, length unit)`` of a measurement file's header (the first line that is neither
    blank nor a ``#`` line), in order."""
    lines = text.removeprefix("\ufeff").splitlines()  # as the readers see it
    head = next((ln for ln in lines if ln.strip() and not ln.strip().startswith("#")), "")
    out = []
    for cell in re.split(r"[,;\t]", head):
        m = re.match(r"\s*(.*?)\s*\[\s*(um|µm|micron|mm)\s*\]\s*$", cell.lower())
        if m:
            out.append((m[1], "mm" if m[2] == "mm" else "um"))
    return out


def fuzz_measurements(count: int, seed: int, tmp: Path, verbose: bool = False) -> Counter[str]:
    """Fuzz ``count`` mutated measurement files; the tally of outcomes (``file_*``)."""
    rng = random.Random(seed)
    bases = measurement_corpus()
    names = sorted(bases)
    tally: Counter[str] = Counter()
    for i in range(count):
        reader, text = bases[names[i % len(names)]]
        mutant, done = mutate_csv(text, rng)
        out = check_measurement(reader, mutant, tmp, design=names[i % len(names)].startswith("lot"))
        if out.status == "accepted" and _length_units(mutant) != _length_units(text):
            # a length column read in another unit than the base file's (a unit slip in the
            # header): silent nonsense unless a range or the design refuses it
            out = Outcome("unit_slip_accepted", done)
        tally[f"file_{out.status}"] += 1
        if verbose and out.status not in ("accepted", "rejected"):
            print(f"[file {out.status}] {reader}: {done}\n    {out.detail}", file=sys.stderr)
    return tally


def run(
    count: int,
    seed: int,
    tmp: Path,
    verbose: bool = False,
    runs: int = 0,
    run_timeout_s: float = 120.0,
    server: ForkServer | None = None,
    records: Any = None,
) -> Counter[str]:
    """Fuzz ``count`` mutants (``-1``: the systematic sweep of :func:`extreme_mutants`); returns
    the tally of outcomes (examples printed if verbose).
    The first ``runs`` accepted mutants (``-1``: every one) also go through ``gearte run``: in
    children of ``server`` when given, else in this process (:func:`run_cli`)."""
    rng = random.Random(seed)
    bases = corpus()
    names = sorted(bases)
    tally: Counter[str] = Counter()
    link_case_data(tmp)

    def random_mutants() -> Iterator[tuple[str, str, str]]:
        for i in range(count):
            name = names[i % len(names)]
            text, done = mutant_text(bases[name], rng)
            yield name, done, text

    mutants = extreme_mutants() if count < 0 else random_mutants()
    for i, (name, done, text) in enumerate(mutants):
        out = check_text(text, tmp)
        tally[out.status] += 1
        if server is not None:
            server.poll()
        if verbose and out.status in ("crash", "coerced", "bad_message"):
            print(f"[{out.status}] {name}: {done}\n    {out.detail}", file=sys.stderr)
        if records is not None:
            records.write(json.dumps({"index": i, "base": name, "done": done, **vars(out)}) + "\n")
        if out.status == "accepted" and (runs < 0 or tally["run_total"] < runs):
            tally["run_total"] += 1
            if server is not None:
                server.submit(i, name, done, text)
                continue
            r = run_cli(text, tmp, run_timeout_s)
            tally[r.status] += 1
            if verbose and r.status in BAD_RUN:
                print(f"[{r.status}] {name}: {done}\n    {r.detail}", file=sys.stderr)
    return tally


#: Outcomes that fail the harness.
BAD = ("crash", "coerced", "bad_message", "file_crash", "file_bad_message", "file_nonfinite")


def equivalence(
    count: int, seed: int, tmp: Path, server: ForkServer, timeout_s: float
) -> list[str]:
    """The first ``count`` accepted mutants of ``seed``, run both as real ``gearte run``
    processes (:func:`run_subprocess`) and through the fork server: their outcomes must agree
    (status and message). Returns the disagreements."""
    import tempfile

    rng = random.Random(seed)
    bases = corpus()
    names = sorted(bases)
    jobs = []
    i = 0
    while len(jobs) < count and i < 100 * count:
        name = names[i % len(names)]
        text, done = mutant_text(bases[name], rng)
        if check_text(text, tmp).status == "accepted":
            jobs.append((i, name, done, text))
        i += 1
    first = len(server.records)
    server.on_record = None  # not part of the fuzzed runs
    for job in jobs:
        server.submit(*job)
    forked = {r.index: r for r in server.drain()[first:]}
    bad = []
    for i, name, done, text in jobs:
        with tempfile.TemporaryDirectory(dir=tmp) as d:
            ref = run_subprocess(text, Path(d), timeout_s, server.report)
        got = forked[i]
        ref_msg = ref.detail.splitlines()[0][:200] if ref.detail else ""
        same_msg = ref_msg == got.message or ref.status == "run_exit_0"
        if ref.status != got.status or not same_msg:
            bad.append(f"{name}: {done}: subprocess {ref.status} {ref_msg!r} != fork {got}")
    return bad


def main(argv: list[str] | None = None) -> int:
    _single_threaded()
    import os
    import resource
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--count",
        type=int,
        default=10_000,
        help="mutated case files (-1: the systematic sweep of extreme values instead, "
        "every positive number of every bundled case = 1e-300, x 1e-9, x 1e9)",
    )
    ap.add_argument("--files", type=int, default=0, help="mutated measurement files")
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument(
        "--runs",
        type=int,
        default=0,
        help="accepted mutants also run through gearte run (-1: every accepted mutant)",
    )
    ap.add_argument("--run-timeout", type=float, default=120.0, help="per run, wall [s]")
    ap.add_argument(
        "--run-cpu-limit",
        type=int,
        default=None,
        help="per run, CPU time [s] (RLIMIT_CPU of the fork server's child); with it the wall "
        "time-out is only a backstop: give a larger --run-timeout on a shared machine",
    )
    ap.add_argument(
        "--workers", type=int, default=os.cpu_count() or 1, help="runs at once (fork server)"
    )
    ap.add_argument(
        "--in-process",
        action="store_true",
        help="run mutants in this process one by one (no fork server)",
    )
    ap.add_argument(
        "--equivalence",
        type=int,
        default=0,
        help="accepted mutants also run as real `gearte run` processes, compared to the fork",
    )
    ap.add_argument("--report", action="store_true", help="runs also write report.html")
    ap.add_argument("--record", type=Path, default=None, help="JSON lines: every mutant and run")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    records = a.record.open("w", encoding="utf-8") if a.record else None
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        server = None
        warm_s = 0.0
        if a.runs and not a.in_process:

            def on_record(r: RunRecord) -> None:  # as each run ends: a long job can be followed
                if records is not None:
                    records.write(json.dumps({"run": vars(r)}) + "\n")
                    records.flush()
                if not a.quiet and r.status in BAD_RUN:
                    print(f"[{r.status}] {r.base}: {r.done}\n    {r.message}", file=sys.stderr)

            server = ForkServer(tmp, a.workers, a.run_timeout, a.report, on_record, a.run_cpu_limit)
            warmed = server.warm()
            warm_s = time.perf_counter() - t0
            if not a.quiet:
                print(f"warm parent in {warm_s:.1f} s: {warmed}", file=sys.stderr)
        elif a.runs:
            resource.setrlimit(resource.RLIMIT_AS, (RUN_MEMORY_LIMIT, RUN_MEMORY_LIMIT))
        tally = run(a.count, a.seed, tmp, not a.quiet, a.runs, a.run_timeout, server, records)
        if server is not None:
            for r in server.drain():
                tally[r.status] += 1
        t1 = time.perf_counter()
        mismatches: list[str] = []
        if a.equivalence and server is not None:
            mismatches = equivalence(a.equivalence, a.seed + 1, tmp, server, a.run_timeout)
            tally["equivalence_checked"] = a.equivalence
            tally["equivalence_mismatch"] = len(mismatches)
            for m in mismatches:
                print(f"[equivalence] {m}", file=sys.stderr)
        t2 = time.perf_counter()
        tally += fuzz_measurements(a.files, a.seed, tmp, not a.quiet)
    t3 = time.perf_counter()
    if records is not None:
        records.close()
    runs = server.records if server is not None else []
    peak_self = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # kB -> GB
    peak_run = max((r.peak_rss_mb for r in runs), default=0.0) / 1024
    slowest = max((r.wall_s for r in runs), default=0.0)
    cpu = sum(r.cpu_s for r in runs)
    what = "the extreme-value sweep:" if a.count < 0 else ""
    n_cases = tally["accepted"] + tally["rejected"] + tally["crash"] + tally["coerced"]
    n_cases += tally["bad_message"]
    print(
        f"{what} {n_cases} fuzzed case files ({tally['run_total']} accepted mutants also run, "
        f"{'fork server, ' + str(a.workers) + ' workers' if server else 'in process'}) in "
        f"{t1 - t0:.1f} s (warm-up {warm_s:.1f} s; runs {cpu:.1f} s CPU, slowest {slowest:.1f} s "
        f"wall, peak RSS of a run {peak_run:.2f} GB, bound {RUN_MEMORY_LIMIT / 2**30:.0f} GiB "
        f"address space); equivalence {t2 - t1:.1f} s; {a.files} fuzzed measurement files in "
        f"{t3 - t2:.1f} s (seed {a.seed}); peak RSS of the harness {peak_self:.2f} GB: "
        f"{dict(sorted(tally.items()))}"
    )
    bad = sum(tally[k] for k in BAD + BAD_RUN) + len(mismatches)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
