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

Small runs are part of the test suite (``tests/test_fuzz_cases.py``, hypothesis-driven); the long
job is ``make fuzz`` (``python tests/fuzzing.py --count 10000``), which prints the tallies.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import re
import sys
import time
import tomllib
from collections import Counter
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


def check_text(text: str, tmp: Path) -> Outcome:
    """Validate one case file text as ``gearte validate`` would and classify the outcome."""
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case

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
    try:
        given = tomllib.loads(text)
    except Exception:  # noqa: BLE001
        return Outcome("accepted")
    kept = case.model_dump(mode="python")
    found = _coercions(given, kept)
    return Outcome("coerced", "; ".join(found)[:300]) if found else Outcome("accepted")


#: Memory limit of one fuzzed ``gearte run`` (address space) [bytes]: the memory bound.
RUN_MEMORY_LIMIT = 6 * 2**30


def run_cli(text: str, tmp: Path, timeout_s: float) -> Outcome:
    """``gearte run`` of an accepted mutant in a subprocess under a memory limit: exit 0, 1
    (analysis failed) or 2 (bad input) are fine; 3 (bug), a kill or a timeout are not."""
    import resource
    import subprocess

    path = tmp / "run.toml"
    path.write_text(text, encoding="utf-8")

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (RUN_MEMORY_LIMIT, RUN_MEMORY_LIMIT))

    args = ["run", str(path), "--out", str(tmp / "out"), "--no-report", "--no-progress"]
    args += ["--samples", "20", "--workers", "1"]
    try:
        p = subprocess.run(
            [sys.executable, "-m", "gearte", *args],
            capture_output=True,
            text=True,
            timeout=timeout_s,
            preexec_fn=limit,
        )
    except subprocess.TimeoutExpired:
        return Outcome("run_timeout", f"over {timeout_s} s")
    if p.returncode in (0, 1, 2):
        return Outcome(f"run_exit_{p.returncode}", p.stderr.strip().splitlines()[-1:].__str__())
    return Outcome("run_bug", f"exit {p.returncode}: {p.stderr.strip()[-300:]}")


def run(
    count: int,
    seed: int,
    tmp: Path,
    verbose: bool = False,
    runs: int = 0,
    run_timeout_s: float = 120.0,
) -> Counter[str]:
    """Fuzz ``count`` mutants; returns the tally of outcomes (examples printed if verbose).
    The first ``runs`` accepted mutants also go through ``gearte run`` (:func:`run_cli`)."""
    rng = random.Random(seed)
    bases = corpus()
    names = sorted(bases)
    tally: Counter[str] = Counter()
    for i in range(count):
        name = names[i % len(names)]
        text, done = mutant_text(bases[name], rng)
        out = check_text(text, tmp)
        tally[out.status] += 1
        if verbose and out.status in ("crash", "coerced", "bad_message"):
            print(f"[{out.status}] {name}: {done}\n    {out.detail}", file=sys.stderr)
        if out.status == "accepted" and tally["run_total"] < runs:
            tally["run_total"] += 1
            r = run_cli(text, tmp, run_timeout_s)
            tally[r.status] += 1
            if verbose and r.status in ("run_bug", "run_timeout"):
                print(f"[{r.status}] {name}: {done}\n    {r.detail}", file=sys.stderr)
    return tally


def main(argv: list[str] | None = None) -> int:
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--runs", type=int, default=0, help="accepted mutants also run (gearte run)")
    ap.add_argument("--run-timeout", type=float, default=120.0)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as d:
        tally = run(a.count, a.seed, Path(d), not a.quiet, a.runs, a.run_timeout)
    wall = time.perf_counter() - t0
    print(
        f"{a.count} fuzzed case files in {wall:.1f} s (seed {a.seed}): "
        f"{dict(sorted(tally.items()))}"
    )
    bad = sum(tally[k] for k in ("crash", "coerced", "bad_message", "run_bug", "run_timeout"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
