"""gearte's processes collect the young generation less often (:mod:`gearte._gc`); a process that
embeds the CLI keeps its own collector thresholds."""

from __future__ import annotations

import gc

from click.testing import CliRunner

import gearte.io.case_file as case_file
from gearte._gc import GC_THRESHOLD0, fewer_collections
from gearte.cli import main


def test_fewer_collections_restores_the_thresholds():
    old = gc.get_threshold()
    with fewer_collections():
        assert gc.get_threshold() == (GC_THRESHOLD0, 20, 100)
    assert gc.get_threshold() == old


def test_cli_command_runs_with_fewer_collections_and_restores(monkeypatch):
    seen = []
    real = case_file.load_case

    def spy(*args, **kwargs):
        seen.append(gc.get_threshold())
        return real(*args, **kwargs)

    monkeypatch.setattr(case_file, "load_case", spy)
    old = gc.get_threshold()
    res = CliRunner().invoke(main, ["validate", "hu2020_rv80e_initial"])
    assert res.exit_code == 0, res.output
    assert seen == [(GC_THRESHOLD0, 20, 100)]
    assert gc.get_threshold() == old
