"""`gearte warm-cache` (issue 12): the warm-up cases cover every study kind that has a bundled
case, each named case exists and is of its kind, the parallel chains hold each warm-up case
once, and bad input is refused cleanly. (The warm-up itself compiles for a minute;
benchmarks/bench_compile.py measures it and checks with --coverage that no bundled case
compiles anything after it.)"""

from __future__ import annotations

import tomllib

from click.testing import CliRunner

from gearte.cases import list_cases
from gearte.cli import main
from gearte.warm import BENCH_CASES, WARM_ALSO, WARM_CASES, WARM_CHAINS, WARM_USES, _chains


def _kind_of(path) -> str:
    return tomllib.loads(path.read_text(encoding="utf-8"))["case"]["kind"]


def test_warm_cases_cover_every_kind_with_a_bundled_case():
    bundled = list_cases()
    kinds = {_kind_of(p) for p in bundled.values()}
    assert kinds <= set(WARM_CASES)
    for kind, cases in WARM_CASES.items():
        for c in cases:
            assert c in bundled, f"{kind}: {c} is not a bundled case"
            assert _kind_of(bundled[c]) == kind


def test_warm_chains_hold_every_warm_up_case_once_and_bench_cases_one_per_kind():
    chained = [c for chain in WARM_CHAINS for c in chain]
    assert sorted(chained) == sorted(c for cases in WARM_CASES.values() for c in cases)
    assert len(set(chained)) == len(chained)
    bundled = list_cases()
    assert set(BENCH_CASES) == set(WARM_CASES)
    for kind, case in BENCH_CASES.items():
        assert _kind_of(bundled[case]) == kind
    # a kind filter keeps only that kind's cases, in chain order
    assert _chains(["rv_serial"]) == [[("rv_serial", "synthetic_rv110e_serial")]]
    # a kind without warm-up cases of its own warms the kinds whose kernels it uses
    assert _chains(["rv_lot"]) == _chains(["rv_reducer"]) != []
    chain_cases = {c for ch in _chains(["gear_chain"]) for _, c in ch}
    assert chain_cases == set(WARM_CASES["gear_pair"]) | set(WARM_CASES["rv_reducer"])
    for kind, uses in WARM_USES.items():
        assert not WARM_CASES[kind] and set(uses) <= set(WARM_CASES)


def test_warm_also_compiles_belong_to_warm_up_cases_and_name_functions():
    import importlib

    warm_up = {c for cases in WARM_CASES.values() for c in cases}
    for case, refs in WARM_ALSO.items():
        assert case in warm_up
        for ref in refs:
            module, name = ref.split(":")
            assert callable(getattr(importlib.import_module(module), name))


def test_warm_cache_refuses_an_unknown_kind():
    r = CliRunner().invoke(main, ["warm-cache", "--kind", "no_such_kind"])
    assert r.exit_code == 2
    assert "no_such_kind" in r.output
