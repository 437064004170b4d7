"""The forked report worker of ``gearte run`` (issue 12): the page it renders is the page rendered
in-process, and whatever goes wrong in it, the parent still writes the whole report."""

from __future__ import annotations

import os
import re
from typing import Any

import pytest

from gearte.report.background import ReportWorker
from gearte.report.outputs import write_outputs
from gearte.studies import RunOptions, run_case

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")


def _page(html: str) -> str:
    """The page without what differs between two renderings (the date, the figures' PNG)."""
    html = re.sub(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC", "DATE", html)
    return re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "PNG", html)


@pytest.fixture(scope="module")
def result() -> Any:
    return run_case("jiang2024_spur_pair", RunOptions(progress=False, samples=500))


def _reaped(pid: int) -> bool:
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


def test_worker_renders_the_same_report_as_in_process(result: Any, tmp_path: Any) -> None:
    worker = ReportWorker.start("jiang2024_spur_pair")
    assert worker is not None
    pid = worker.pid
    mine = write_outputs(result, tmp_path / "worker", worker=worker)
    alone = write_outputs(result, tmp_path / "alone")
    a, b = mine["report"].read_text(), alone["report"].read_text()
    assert _page(a) == _page(b)
    assert a.count("data:image/png;base64,") == b.count("data:image/png;base64,") > 0
    assert {"figures", "render", "render: slowest figure", "html"} <= set(result.timings)
    assert _reaped(pid)  # no zombie left behind


def test_worker_that_cannot_render_falls_back_in_process(result: Any, tmp_path: Any) -> None:
    worker = ReportWorker.start()
    assert worker is not None
    os.kill(worker.pid, 9)  # the worker dies before the result is sent
    paths = write_outputs(result, tmp_path / "out", worker=worker)
    assert paths["report"].read_text().count("data:image/png;base64,") > 0


def test_unpicklable_result_is_rendered_in_process(result: Any, tmp_path: Any) -> None:
    worker = ReportWorker.start()
    assert worker is not None
    pid = worker.pid
    result.analyses[0].values["unpicklable"] = lambda: None  # noqa: E731 - cannot pickle
    try:
        assert worker.submit(result) is False
        assert worker.collect() is None
    finally:
        del result.analyses[0].values["unpicklable"]
    assert _reaped(pid)


def test_unused_worker_is_ended_and_reaped() -> None:
    with ReportWorker.start() as worker:
        pid = worker.pid
    assert _reaped(pid)
