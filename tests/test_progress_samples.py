"""Progress in samples (issue 14 item 3): a sampled study's bar counts samples — total = the
study's samples, each finished chunk advancing it by its own sample count (the last chunk
smaller) — on threads, processes and a custom executor alike; work that is not sampled counts
its tasks. The bar is replaced by a recorder; no timing is asserted."""

from __future__ import annotations

import pytest

import gearte.execution.mapping as mapping
from gearte.errors import ParameterError
from gearte.execution import (
    ChunkExecutor,
    RunningStats,
    map_chunks,
    seeded_chunks,
)
from gearte.execution.backends import Batch
from gearte.execution.check import sample_chunk


class _Recorder:
    """Stands in for :class:`~gearte.execution.progress.ChunkProgress`; keeps what it is told."""

    made: list[_Recorder] = []

    def __init__(self, total, description, enabled, unit="chunks"):
        self.total, self.description, self.enabled, self.unit = total, description, enabled, unit
        self.advances: list[int] = []
        _Recorder.made.append(self)

    def advance(self, n=1):
        self.advances.append(n)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return None


@pytest.fixture
def bars(monkeypatch):
    _Recorder.made = []
    monkeypatch.setattr(mapping, "ChunkProgress", _Recorder)
    return _Recorder.made


def _stats(**kw) -> RunningStats:
    return map_chunks(
        sample_chunk,
        seeded_chunks(10_500, 4_000, seed=3),  # chunks of 4000, 4000, 2500
        reduce=RunningStats.merge,
        progress=True,
        **kw,
    )


@pytest.mark.parametrize(
    "backend", [{"workers": 1}, {"workers": 2}, {"scheduler": "processes", "workers": 2}]
)
def test_seeded_chunks_bar_counts_samples_with_the_uneven_last_chunk(bars, backend):
    """10 500 samples in chunks of 4000: total 10 500, advances {4000, 4000, 2500} (in any
    order of finishing), unit 'samples'; statistics bit-identical to a run without a bar."""
    s = _stats(**backend)
    (bar,) = bars
    assert (bar.total, bar.unit) == (10_500, "samples")
    assert sorted(bar.advances) == [2500, 4000, 4000]
    quiet = map_chunks(
        sample_chunk,
        seeded_chunks(10_500, 4_000, seed=3),
        reduce=RunningStats.merge,
        progress=False,
        workers=1,
    )
    assert (s.count, s.mean, s.m2, s.extra) == (quiet.count, quiet.mean, quiet.m2, quiet.extra)


class _ReverseExecutor(ChunkExecutor):
    """A fake backend: holds every submitted chunk, then hands them back last first."""

    name = "reverse"
    workers = 2

    def batch(self, shared=None, *, has_shared=False):
        return _ReverseBatch()


class _ReverseBatch(Batch):
    def __init__(self):
        super().__init__()
        self.jobs: list = []

    def __len__(self):
        return len(self.jobs)

    def submit(self, func, task, index, label):
        self.jobs.append((index, func(task)))

    def next_done(self):
        done, self.jobs = list(reversed(self.jobs)), []
        return done


def test_advances_follow_each_finished_chunks_own_size_out_of_order(bars):
    """Chunks handed back last first: the bar advances by 2500 first, then 4000, 4000 — each
    finished chunk's own count — and the results still reduce in chunk order."""
    s = _stats(scheduler=_ReverseExecutor())
    (bar,) = bars
    assert bar.advances == [2500, 4000, 4000]
    assert bar.total == 10_500
    assert s.count == 10_500


def test_explicit_sizes_for_tasks_that_are_not_chunks(bars):
    """Tuples ``(n, seed)`` with ``sizes``: the bar counts their samples; a wrong count of sizes
    is an error naming ``sizes``."""
    tasks = [(n, k) for k, n in enumerate([3, 3, 1])]
    out = map_chunks(lambda t: t[0], tasks, sizes=[3, 3, 1], workers=2, progress=True)
    assert out == [3, 3, 1]
    assert (bars[0].total, bars[0].unit, sorted(bars[0].advances)) == (7, "samples", [1, 3, 3])
    with pytest.raises(ParameterError, match="sizes"):
        map_chunks(lambda t: t[0], tasks, sizes=[3, 3], workers=1, progress=True)
    with pytest.raises(ParameterError, match="sizes"):  # a lazy iterable longer than sizes
        map_chunks(lambda t: t[0], iter(tasks), sizes=[3, 3], workers=1, progress=True)


def test_work_that_is_not_sampled_counts_its_tasks(bars):
    """A sweep-like map (no sample counts): total = tasks, one unit per finished task, in the
    unit the caller names."""
    map_chunks(abs, [-1, 2, -3], workers=2, progress=True, unit="points")
    assert (bars[0].total, bars[0].unit, bars[0].advances) == (3, "points", [1, 1, 1])
    map_chunks(abs, [-1, 2], workers=1, progress=True)
    assert (bars[1].total, bars[1].unit) == (2, "chunks")


def test_planetary_scenario_and_stack_monte_carlo_bars_count_samples(bars):
    """Two sampled studies end to end: Wang 2013's random-assembly scenario (tuple tasks) and a
    tolerance stack's Monte-Carlo (its own task type) — totals are their sample counts."""
    from gearte.io.case_file import load_case
    from gearte.runners.planetary_mc import run_scenario
    from gearte.studies.planetary import build_terms
    from gearte.tolerance.distributions import Normal
    from gearte.tolerance.montecarlo import monte_carlo
    from gearte.tolerance.stackup import Contributor, LinearStack

    terms, mags, _ = build_terms(load_case("wang2013_2kh_eq9"))
    run_scenario(terms, "random_assembly", mags, samples=2_500, chunk_size=1_000, seed=1)
    stack = LinearStack([Contributor("a", Normal(0.0, 1.0), 1.0)], name="s")
    monte_carlo(stack, n=25_000, chunk_size=10_000, seed=1, engine="numpy", progress=True)
    assert [(b.total, b.unit) for b in bars] == [(2_500, "samples"), (25_000, "samples")]
    assert sorted(bars[0].advances) == [500, 1000, 1000]
    assert sorted(bars[1].advances) == [5000, 10_000, 10_000]


def test_rate_column_reads_samples_per_second_on_a_terminal(monkeypatch):
    """On a terminal the bar is rich's, with the count's unit and the rate in samples/s."""
    from gearte.execution.progress import ChunkProgress

    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    with ChunkProgress(10, "study", True, "samples") as bar:
        assert bar.active
        bar.advance(4)
        task = bar._bar.tasks[0]
        assert (task.total, task.completed) == (10, 4)
        texts = [c.render(task) for c in bar._bar.columns if hasattr(c, "render")]
        assert any(str(t).endswith("samples/s") for t in texts)
    assert not bar.active  # closed on leaving


def test_no_bar_off_a_terminal_or_when_disabled(monkeypatch):
    """Logs, pipes and CI stay silent, as before (no line-per-10 % form: the CLI has only
    ``--no-progress``, no option to force progress off a terminal)."""
    from gearte.execution.progress import ChunkProgress

    monkeypatch.setattr("sys.stderr.isatty", lambda: False, raising=False)
    assert not ChunkProgress(10, "study", True, "samples").active
    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    assert not ChunkProgress(10, "study", False, "samples").active
