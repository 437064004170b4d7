"""`gearte warm-cache` (issue 12): the warm-up cases cover every study kind that has a bundled
case, each named case exists and is of its kind, and bad input is refused cleanly. (The warm-up
itself compiles for minutes; benchmarks/bench_compile.py measures it.)"""

from __future__ import annotations

import tomllib

from click.testing import CliRunner

from gearte.cases import list_cases
from gearte.cli import main
from gearte.warm import WARM_CASES


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


def test_warm_cache_refuses_an_unknown_kind():
    r = CliRunner().invoke(main, ["warm-cache", "--kind", "no_such_kind"])
    assert r.exit_code == 2
    assert "no_such_kind" in r.output
