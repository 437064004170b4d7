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
    assert "report process failed: rendered in-process" in result.timings  # said, not hidden
    del result.timings["report process failed: rendered in-process"]


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
