"""Every backend runs every study (issue 13): nothing that crosses a process boundary is a local
closure, and a sampled analysis gives bit-identical numbers on every backend."""

from __future__ import annotations

import json
import tomllib

import pytest

from gearte.cases import case_path
from gearte.io.case_file import load_case_dict
from gearte.studies import RunOptions, run_case


def _small(name: str) -> dict:
    """A bundled case cut to its sampled analysis at a small size."""
    data = tomllib.loads(case_path(name).read_text(encoding="utf-8"))
    data["case"]["name"] = name
    if name == "li2023_rv_errors":
        data["analyses"] = {
            "batch": {"samples": 3, "duration_s": 0.01, "settle_s": 0.005, "chunk_size": 1}
        }
    elif name == "wang2013_2kh_eq9":
        data["analyses"] = {
            "coupled_te": None,
            "assembly": None,
            "monte_carlo": {"samples": 2000, "chunk_size": 500, "scenarios": ["random_assembly"]},
        }
        data["analyses"] = {k: v for k, v in data["analyses"].items() if v is not None}
    elif name == "wang2013_2kh_eq9_yield":
        y = data["analyses"]["yield"] | {"samples": 2000, "chunk_size": 250, "sobol_samples": 64}
        data["analyses"] = {"yield": y}
    return data


_SAMPLES = {"jiang2024_spur_pair": 20_000, "jiang2024_shoulder_swing": 20_000}


def _numbers(name: str, scheduler: str | None) -> str:
    """The analyses of the small case on ``scheduler`` (2 workers); afterwards no worker process
    of this run is left (the pool or cluster was shut down and its children reaped)."""
    import multiprocessing

    before = {p.pid for p in multiprocessing.active_children()}
    case = load_case_dict(_small(name))
    opts = RunOptions(progress=False, samples=_SAMPLES.get(name), scheduler=scheduler, workers=2)
    doc = json.loads(run_case(case, opts).to_json())
    left = [p for p in multiprocessing.active_children() if p.pid not in before]
    assert not left, f"{scheduler}: worker processes left after the run: {left}"
    return json.dumps(doc["analyses"], sort_keys=True)


def _without_timing(text: str) -> str:
    doc = json.loads(text)
    for a in doc.values():
        for k in [k for k in a["values"] if "wall" in k or "[s]" in k and "time" in k]:
            del a["values"][k]
    return json.dumps(doc, sort_keys=True)


def test_reproducer_rv_dynamics_batch_pickles_for_processes():
    """Issue 13 reproducer: ``--scheduler processes`` on the RV dynamics batch failed with exit 3
    "Can't pickle local object 'ode_system.<locals>.<lambda>'". What the batch sends to a worker
    process (the model and its compiled system) now survives a pickle round trip."""
    import pickle

    import numpy as np

    from gearte.runners.rv_dynamics_sim import ode_system
    from gearte.studies._rv_dynamics import build_dynamic_model
    from gearte.studies.rv_reducer import build_reducer

    case = load_case_dict(_small("li2023_rv_errors"))
    model, _ = build_dynamic_model(case, build_reducer(case.reducer))
    system = ode_system(model)
    again = pickle.loads(pickle.dumps((model, system)))[1]
    y = np.linspace(0.1, 1.0, model.n_dof * 2)
    assert again.output_python(0.0, y) == system.output_python(0.0, y)


@pytest.mark.slow
def test_reproducer_processes_backend_runs_the_rv_dynamics_batch():
    """The same reproducer end to end: bit-identical numbers on threads and processes."""
    threads = _without_timing(_numbers("li2023_rv_errors", "threads"))
    assert _without_timing(_numbers("li2023_rv_errors", "processes")) == threads


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", ["processes", "local-cluster"])
@pytest.mark.parametrize(
    "name",
    [
        "jiang2024_spur_pair",
        "jiang2024_shoulder_swing",
        "wang2013_2kh_eq9",
        "li2023_rv_errors",
        "wang2013_2kh_eq9_yield",
    ],
)
def test_every_kind_sampled_analysis_on_every_backend(name, scheduler):
    """Tolerance MC (gear pair, chain), planetary MC, RV dynamics batch and yield: bit-identical
    on threads, processes and a Dask local cluster; no worker process left after each run."""
    pytest.importorskip("distributed")
    reference = _without_timing(_numbers(name, "threads"))
    assert _without_timing(_numbers(name, scheduler)) == reference


@pytest.mark.slow
def test_yield_on_processes_matches_threads_and_leaves_no_child():
    """One corner of the backend matrix on its own (each worker process loads the compiled
    kernels: ~15 s on 2 busy cores): the yield Monte-Carlo with its Sobol indices on a process
    pool gives the threads' bits, and the pool's children are reaped."""
    reference = _without_timing(_numbers("wang2013_2kh_eq9_yield", "threads"))
    assert _without_timing(_numbers("wang2013_2kh_eq9_yield", "processes")) == reference


def test_process_pool_shutdown_cannot_hang_and_reaps_its_children():
    """A chunk stuck in a worker process (here: sleeping 10 min) no longer blocks the pool's
    shutdown forever nor leaves orphans: workers get ``shutdown_timeout_s``, then are stopped."""
    import time

    from gearte.execution.backends import PoolExecutor

    ex = PoolExecutor("processes", 2)
    ex.shutdown_timeout_s = 0.5
    batch = ex.batch()
    batch.submit(time.sleep, 600, 0, "stuck")
    procs = list(ex._pool._processes.values())
    assert procs
    ex.close()
    assert not any(p.is_alive() for p in procs)
