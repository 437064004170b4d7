"""The forked report worker of ``gearte run`` (issue 12): the page it renders is the page rendered
in-process, and whatever goes wrong in it, the parent still writes the whole report."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gearte.report.background import ReportWorker

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")


# The worker forks only where no other Python thread runs (a fork copies one thread), and a test
# session may have threads left by other tests: the checks run in one fresh interpreter, each
# printing "name: ok" or "name: <what failed>".
_CHECKS = r"""
import os, re, sys, tempfile
from pathlib import Path
from gearte.report.background import ReportWorker
from gearte.report.outputs import write_outputs
from gearte.studies import RunOptions, run_case

def page(html):
    html = re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", "DATE", html)
    return re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "PNG", html)

def reaped(pid):
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False

def check(name, fn):
    try:
        fn()
        print(f"{name}: ok", flush=True)
    except Exception as exc:
        print(f"{name}: {type(exc).__name__}: {exc}", flush=True)

result = run_case("jiang2024_spur_pair", RunOptions(progress=False, samples=500))
tmp = Path(tempfile.mkdtemp())

def same_report():
    worker = ReportWorker.start()
    assert worker is not None, "did not fork"
    pid = worker.pid
    mine = write_outputs(result, tmp / "worker", worker=worker)
    alone = write_outputs(result, tmp / "alone")
    a, b = mine["report"].read_text(), alone["report"].read_text()
    assert page(a) == page(b), "pages differ"
    assert a.count("data:image/png;base64,") == b.count("data:image/png;base64,") > 0
    pngs = lambda html: re.findall(r"data:image/png;base64,[A-Za-z0-9+/=]+", html)
    assert pngs(a) == pngs(b), "the report process drew other pixels"
    need = {"figures", "render", "render: slowest figure", "html", "report process: warm-up",
            "report process: waited for the result"}
    assert need <= set(result.timings), result.timings
    assert reaped(pid), "zombie left"

def dead_worker():
    worker = ReportWorker.start()
    assert worker is not None, "did not fork"
    os.kill(worker.pid, 9)  # the worker dies before the result is sent
    paths = write_outputs(result, tmp / "out", worker=worker)
    assert paths["report"].read_text().count("data:image/png;base64,") > 0
    key = "report process failed: rendered in-process"
    assert key in result.timings, "fallback not said"
    del result.timings[key]

def unpicklable():
    worker = ReportWorker.start()
    assert worker is not None, "did not fork"
    pid = worker.pid
    result.analyses[0].values["unpicklable"] = lambda: None
    try:
        assert worker.submit(result) is False
        assert worker.collect() is None
    finally:
        del result.analyses[0].values["unpicklable"]
    assert reaped(pid), "zombie left"

def unused():
    worker = ReportWorker.start()
    assert worker is not None, "did not fork"
    with worker:
        pid = worker.pid
    assert reaped(pid), "zombie left"

check("same_report", same_report)
check("dead_worker", dead_worker)
check("unpicklable", unpicklable)
check("unused", unused)
"""


@pytest.fixture(scope="module")
def checks() -> dict[str, str]:
    p = subprocess.run(
        [sys.executable, "-c", _CHECKS], capture_output=True, text=True, timeout=900, check=False
    )
    out = dict(
        line.split(": ", 1) for line in p.stdout.splitlines() if ": " in line
    )  # name -> "ok" or the failure
    assert p.returncode == 0 and len(out) == 4, p.stdout + p.stderr[-3000:]
    return out


def test_worker_renders_the_same_report_as_in_process(checks: dict[str, str]) -> None:
    assert checks["same_report"] == "ok", checks["same_report"]


def test_worker_that_cannot_render_falls_back_in_process(checks: dict[str, str]) -> None:
    assert checks["dead_worker"] == "ok", checks["dead_worker"]


def test_unpicklable_result_is_rendered_in_process(checks: dict[str, str]) -> None:
    assert checks["unpicklable"] == "ok", checks["unpicklable"]


def test_unused_worker_is_ended_and_reaped(checks: dict[str, str]) -> None:
    assert checks["unused"] == "ok", checks["unused"]


def test_no_fork_while_other_threads_run() -> None:
    import threading

    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        assert ReportWorker.start() is None  # a fork would copy one thread of two
    finally:
        stop.set()
        t.join()


def test_fixed_grid_leaves_the_asked_room_around_each_panel() -> None:
    from gearte.plotting import new_figure

    fig, axes = new_figure(2, 3, figsize=(9.0, 5.6), margins_in=(0.9, 0.5, 0.3, 0.1))
    assert fig.get_layout_engine() is None  # nothing measured at draw time
    boxes = [ax.get_position() for ax in axes.ravel()]
    w, h = 9.0, 5.6
    assert boxes[0].x0 * w == pytest.approx(0.9) and boxes[2].x1 * w == pytest.approx(9.0 - 0.1)
    assert (boxes[1].x0 - boxes[0].x1) * w == pytest.approx(0.9)  # room for the next y labels
    assert (boxes[0].y0 - boxes[3].y1) * h == pytest.approx(0.5 + 0.3)  # x labels + title
    assert boxes[3].y0 * h == pytest.approx(0.5) and (1 - boxes[0].y1) * h == pytest.approx(0.3)
    with pytest.raises(ValueError, match="no room"):
        new_figure(1, 4, figsize=(3.0, 3.0), margins_in=(0.9, 0.5, 0.3, 0.1))


# Streaming (issue 12): each analysis's figures are drawn as soon as the analysis is done; the
# report of the final result must be the one drawn from the whole result.


@pytest.fixture(scope="module")
def cycloid_result() -> object:
    from gearte.studies import RunOptions, run_case

    return run_case("hu2020_rv80e_initial", RunOptions(progress=False))


def _pngs(figs: list) -> list[tuple[str, str, str]]:
    from gearte.report.html import render_all

    return [(r.analysis, r.title, r.png) for r in render_all(figs, workers=1)]


@pytest.mark.parametrize(
    ("case", "expected"),
    [("hu2020_rv80e_initial", {"geometry", "geometric_te", "tooth_contact"}),
     ("synthetic_rv_bench", {"load_series", "te_orders"}),
     ("wang2013_2kh_eq9", {"terms", "coupled_te", "assembly"})],
)  # fmt: skip
def test_figures_of_one_analysis_are_those_of_the_whole_result(
    cycloid_result, case: str, expected: set[str]
) -> None:
    from gearte.plotting import figures_for, figures_of, self_contained
    from gearte.studies import RunOptions, run_case

    result = (
        cycloid_result
        if case == "hu2020_rv80e_initial"
        else run_case(case, RunOptions(progress=False, samples=2000))
    )
    names = [a.name for a in result.analyses]
    drawn = [n for n in names if n in self_contained(result.kind)]
    assert set(drawn) == expected
    whole = _pngs(figures_for(result))
    alone = [p for n in drawn for p in _pngs(figures_of(result, {n}))]
    assert alone and alone == [p for p in whole if p[0] in drawn]  # same pixels and order


_REPORT_SIDE = r"""
import pickle, sys
from gearte.report.background import _Report, warm_up_plotting
numba_first, case, modules, case_bytes, analyses, final = pickle.loads(sys.stdin.buffer.read())
if numba_first:
    import numba  # what the parent imports before it forks the report process
warm_up_plotting(case)
rep = _Report(preload=bool(modules))
rep.take(("preload", modules, case_bytes))
for i, data in enumerate(analyses):
    rep.take(("analysis", i, data))
while rep.todo or any(rep.built.values()):
    rep.step()
html, _ = rep.finish(final)
print("numba" in sys.modules, sorted(m for m in sys.modules if m.startswith("numba.")))
print(html)
"""


def _report_side(case: str, samples: int, *, numba_first: bool, preload: bool):
    """Run ``case`` here, then feed its report process's side (:class:`_Report`) in a fresh
    interpreter as ``gearte run`` does: the case, each analysis as made, the final result;
    ``preload``: with the names of this process's gearte modules; ``numba_first``: numba
    imported before (as the report process inherits it from its parent). Returns the result, the
    report side's first output line (numba imported, numba submodules) and its page."""
    import pickle

    from gearte.report.background import _analysis_bytes, _final_frame
    from gearte.studies import RunOptions, run_case

    result = run_case(case, RunOptions(progress=False, samples=samples))
    sent = {id(a): (a, i, _analysis_bytes(a)) for i, a in enumerate(result.analyses)}
    final = pickle.loads(_final_frame(result, sent)[8:])
    modules = (
        sorted(m for m in sys.modules if m.startswith("gearte.") and m != "gearte.__main__")
        if preload
        else []
    )
    analyses = [v[2] for v in sent.values()]
    data = [numba_first, case, modules, pickle.dumps(result.case), analyses, final]
    p = subprocess.run(
        [sys.executable, "-c", _REPORT_SIDE],
        input=pickle.dumps(data),
        capture_output=True,
        timeout=300,
        check=False,
    )
    assert p.returncode == 0, p.stderr.decode()[-3000:]
    numba, html = p.stdout.decode().split("\n", 1)
    return result, numba, html.removesuffix("\n")


def _numba_free_cases() -> list[str]:
    """Every bundled case of a kind whose plotting module says ``NUMBA_FREE_RESULTS``."""
    from gearte.cases import list_cases
    from gearte.report.background import _kind_of, _plotting_module

    return [
        name
        for name in list_cases()
        if getattr(_plotting_module(name), "NUMBA_FREE_RESULTS", False) and _kind_of(name)
    ]


def test_numba_free_kinds_are_the_expected_ones() -> None:
    """The kinds that say so: every bundled kind — planetary, cycloid stage, gear pair, gear
    chain, strain wave and the RV kinds (reducer, serial, bench, lot); a kind dropping out of
    the list fails here first."""
    from gearte.cases import list_cases
    from gearte.report.background import _kind_of

    kinds = {_kind_of(name) for name in _numba_free_cases()}
    assert kinds == {
        "planetary",
        "cycloid_stage",
        "gear_pair",
        "gear_chain",
        "strain_wave",
        "rv_reducer",
        "rv_serial",
        "rv_bench",
        "rv_lot",
    }
    # every kind a bundled case uses (kinds other tests register in this process aside)
    assert kinds == {_kind_of(name) for name in list_cases()}
    # every quick case is a bundled one (a renamed case would drop out of the quick suite)
    assert set(_QUICK_NUMBA_FREE) <= set(_numba_free_cases())


#: Monte-Carlo samples of the numba-free report test: the RV kinds' dynamics batches and yields
#: cost ~17 ms a sample (li2023_rv_errors: 34 s at 2000); their figures are drawn from 64.
_RV_KINDS = {"rv_reducer", "rv_serial", "rv_bench", "rv_lot"}


def _samples(case: str) -> int:
    from gearte.report.background import _kind_of

    return 64 if _kind_of(case) in _RV_KINDS else 2000


#: The cases of the numba-free report test in the quick suite: each kind, each kind's yield, and
#: the RV cases holding the other record types (load sharing, loaded contact, catalogue,
#: stiffness chain, compensation, modal, DTE/ODE, serial, bench, lot); the other bundled cases
#: run with ``make test-slow`` (each is 3–5 s).
_QUICK_NUMBA_FREE = {
    "wang2013_2kh_eq9_yield",
    "hu2020_rv80e_initial",
    "jiang2024_spur_pair",
    "robot_joint_spur_rv_yield",
    "harmonicdrive_csf32_100",
    "han2023_rv110e",
    "han2023_rv110e_yield",
    "li2023_rv_errors",
    "hu2020_rv80e_initial_reducer",
    "synthetic_rv110e_serial",
    "synthetic_rv_bench",
    "synthetic_rv110e_lot",
}


@pytest.mark.parametrize(
    "case",
    [
        c if c in _QUICK_NUMBA_FREE else pytest.param(c, marks=pytest.mark.slow)
        for c in _numba_free_cases()
    ],
)
def test_numba_free_report_is_drawn_without_importing_numba(case: str) -> None:
    """The report process of a kind whose plotting module says ``NUMBA_FREE_RESULTS`` (every
    bundled kind; every bundled case of them) imports none of the parent's modules: unpickling
    the case and every analysis, drawing the figures early and rendering the page import no
    numba (~0.5 s CPU beside the analyses); the page (for the planetary kind the histogram
    built alone after the result: ``OTHERS_READ_ALONE``) is the page drawn
    in one process from the whole result."""
    from gearte.report.background import _plotting_module
    from gearte.report.html import render_report

    assert _plotting_module(case).NUMBA_FREE_RESULTS
    result, numba, html = _report_side(case, _samples(case), numba_first=False, preload=False)
    assert numba == "False []"
    assert html.count("data:image/png;base64,") >= 2  # the figures, compared whole below
    assert _page(html) == _page(render_report(result))


@pytest.mark.parametrize("case", ["hu2020_rv80e_initial_reducer", "li2023_rv_errors"])
def test_preloading_report_process_draws_the_same_page(case: str) -> None:
    """The report process of a kind whose plotting module does not say ``NUMBA_FREE_RESULTS``
    (none bundled; a registered kind) imports the parent's gearte modules with the real numba
    (inherited from the parent, which imports it before the fork: ``_import_numba_for``) and
    unpickles every analysis; fed so, the RV cases (results of kernel modules: load sharing,
    TE, catalogue, mesh contact, modal, DTE, ODE) give the page drawn in one process from the
    whole result."""
    from gearte.report.html import render_report

    result, numba, html = _report_side(case, 8, numba_first=True, preload=True)
    assert numba.startswith("True")  # the real numba, with its submodules
    assert html.count("data:image/png;base64,") >= 5
    assert _page(html) == _page(render_report(result))


_NUMBA_BEFORE_FORK = r"""
import sys
sys.path.insert(0, sys.argv[1])
from gearte.report.background import _import_numba_for
from gearte.studies import register_kind
register_kind("foundation_test", "foundation_kind")
for case in ("hu2020_rv80e_initial_reducer", {"case": {"kind": "rv_lot"}}):
    _import_numba_for(case)
print("numba" in sys.modules)
_import_numba_for({"case": {"kind": "foundation_test"}, "demo": {"length_mm": 1.0}})
print("numba" in sys.modules)
"""


def test_numba_is_imported_before_the_fork_only_for_kinds_without_the_flag() -> None:
    """``gearte run`` imports numba before it forks the report process only where the case's
    kind does not say ``NUMBA_FREE_RESULTS`` (its report process then preloads the parent's
    modules, above): not for a bundled RV case or a case dict of an RV kind; for the test
    suite's registered kind, whose plotting module does not say it."""
    from pathlib import Path

    p = subprocess.run(
        [sys.executable, "-c", _NUMBA_BEFORE_FORK, str(Path(__file__).parent)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout.split() == ["False", "True"]


def _page(html: str) -> str:
    import re

    return re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", "DATE", html)


@pytest.mark.parametrize(("early_steps", "changed"), [(0, False), (2, True), (99, True)])
def test_streamed_report_is_the_report_of_the_final_result(
    cycloid_result, early_steps: int, changed: bool
) -> None:
    """The report process's side fed as ``gearte run`` feeds it: the case, each analysis as it
    is made, some figures drawn before the final result (none, some, all), and an analysis
    changed after it was streamed (drawn again from the final result)."""
    import copy
    import pickle

    from gearte.report.background import _analysis_bytes, _final_frame, _Report
    from gearte.report.html import render_report

    result = copy.deepcopy(cycloid_result)
    rep = _Report()
    rep.take(("preload", [], pickle.dumps(result.case)))
    sent = {}
    for i, a in enumerate(result.analyses):
        data = _analysis_bytes(a)
        sent[id(a)] = (a, i, data)
        rep.take(("analysis", i, data))
    for _ in range(early_steps):
        if not (rep.todo or any(rep.built.values())):
            break
        rep.step()
    if early_steps >= 99:
        assert sum(len(d) for d in rep.drawn.values()) == 6  # every figure drawn early
    if changed:  # the study changes a result after making it
        v = result["tooth_contact"].values
        v["contact_force [N]"] = 2.0 * v["contact_force [N]"]
    frame = _final_frame(result, sent)
    parts = pickle.loads(frame[8:])[2]
    assert [how for how, _ in parts].count("new") == int(changed)
    html, timings = rep.finish(pickle.loads(frame[8:]))
    assert _page(html) == _page(render_report(result))
    assert timings["report process: figures during the analyses"] >= 0.0


@pytest.mark.parametrize("case", ["li2023_rv", "synthetic_rv_bench"])
def test_log_axes_are_drawn_without_mathtext(case: str, monkeypatch) -> None:
    """The kinds with a log axis (the DTE spectrum, the bench order spectrum) get plain-text
    tick labels (``10⁻³``) from ``polish``: drawing every figure of their report parses no
    mathtext (its parser cost the report process ~0.05-0.3 s CPU on the critical path), and
    the log axes are labelled at their decades."""
    import matplotlib.mathtext

    from gearte.plotting import figures_for
    from gearte.report.html import render_all
    from gearte.studies import RunOptions, run_case

    def no_mathtext(self, s, *args, **kwargs):
        raise AssertionError(f"mathtext parsed: {s!r}")

    monkeypatch.setattr(matplotlib.mathtext.MathTextParser, "parse", no_mathtext)
    figs = figures_for(run_case(case, RunOptions(progress=False, samples=8)))
    assert render_all(figs, workers=1)  # every figure drawn
    labels = [
        t.get_text()
        for f in figs
        for ax in f.fig.axes
        for axis in (ax.xaxis, ax.yaxis)
        if axis.get_scale() == "log"
        for t in axis.get_ticklabels()
    ]
    assert any(lab.startswith("10") and lab[2:3] in "⁻⁰¹²³⁴⁵⁶⁷⁸⁹" for lab in labels), labels
    assert not any("$" in lab for lab in labels)


def test_plain_log_labels() -> None:
    """Decades as ``10ⁿ``, other labelled ticks as ``c×10ⁿ``; a log axis whose formatter a
    figure set itself keeps it."""
    from matplotlib.ticker import LogFormatterSciNotation, ScalarFormatter

    from gearte.plotting import new_figure
    from gearte.plotting.display import _plain_log_formatter, polish

    fmt = _plain_log_formatter()(base=10.0)
    assert fmt._num_to_string(1e-3, 1e-5, 1.0) == "10⁻³"
    assert fmt._num_to_string(1.0, 1e-5, 1.0) == "10⁰"
    assert fmt._num_to_string(100.0, 1.0, 1e4) == "10²"
    assert fmt._num_to_string(2e-3, 1e-5, 1.0) == "2×10⁻³"
    fig, (a, b) = new_figure(1, 2)
    a.semilogy([1, 2], [1e-3, 1e2])
    b.semilogy([1, 2], [1e-3, 1e2])
    b.yaxis.set_major_formatter(ScalarFormatter())
    polish(fig)
    assert isinstance(a.yaxis.get_major_formatter(), _plain_log_formatter())
    assert isinstance(a.yaxis.get_minor_formatter(), _plain_log_formatter())
    assert isinstance(b.yaxis.get_major_formatter(), ScalarFormatter)
    assert isinstance(b.yaxis.get_minor_formatter(), _plain_log_formatter())
    assert not isinstance(a.xaxis.get_major_formatter(), LogFormatterSciNotation)
