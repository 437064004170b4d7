"""The status line of long stretches without other output (gearte.execution.heartbeat) and the
final line of `gearte run`, which gives the whole wall time of the command."""

from __future__ import annotations

import io
import re
import time

import pytest
from click.testing import CliRunner

from gearte.execution.heartbeat import Heartbeat, hide_status, show_status


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _wait_for(pred, timeout=5.0):
    t = time.perf_counter()
    while time.perf_counter() - t < timeout:
        if pred():
            return True
        time.sleep(0.02)
    return False


def test_a_quiet_stretch_is_named_once_it_lasts():
    out = _Terminal()
    with Heartbeat(stream=out, after=0.2, interval=0.02) as beat:
        beat.stage("running the analyses")
        assert beat.text(now=beat._quiet + 0.1) is None  # too short a quiet stretch
        assert _wait_for(lambda: "running the analyses" in out.getvalue())
        text = beat.text(now=beat._since + 7.4)
        assert text == "… running the analyses (7 s)"
        beat.stage("writing the report")  # the line goes on, with the new stage
        assert beat.text() is not None and beat.text().startswith("… writing the report (")
    assert out.getvalue().endswith("\r\033[K")  # the line is cleared at the end


def test_off_a_terminal_it_is_silent_unless_asked(monkeypatch):
    out = io.StringIO()
    with Heartbeat(stream=out, after=0.0, interval=0.02) as beat:
        beat.stage("loading")
        time.sleep(0.1)
    assert out.getvalue() == ""
    monkeypatch.setenv("GEARTE_HEARTBEAT", "1")
    out = io.StringIO()
    with Heartbeat(stream=out, after=0.05, interval=0.02) as beat:
        beat.stage("loading")
        assert _wait_for(lambda: "… loading" in out.getvalue())
    assert "\r" not in out.getvalue()  # plain lines in a log


def test_a_progress_bar_hides_it():
    out = _Terminal()
    with Heartbeat(stream=out, after=0.0, interval=0.02) as beat:
        hide_status()
        try:
            beat.stage("sampling")
            time.sleep(0.15)
            assert "sampling" not in out.getvalue()
        finally:
            show_status()
        assert _wait_for(lambda: "sampling" in out.getvalue())


def test_it_names_the_kernel_numba_compiles():
    numba = pytest.importorskip("numba")
    import gearte.execution.heartbeat as hb

    with Heartbeat(stream=_Terminal(), after=0.0, interval=10.0) as beat:
        beat.stage("running the analyses")

        @numba.njit(cache=False)
        def heartbeat_test_kernel(x):
            return x + 1

        names = []
        original = beat._compiling_start

        def spy(name):
            names.append(name)
            original(name)

        beat._compiling_start = spy
        hb.numba_ready()
        assert heartbeat_test_kernel(1) == 2
    assert "heartbeat_test_kernel" in names
    assert beat.compile_s > 0


def test_final_line_gives_the_whole_wall_time(tmp_path):
    from gearte.cli import main

    r = CliRunner().invoke(
        main, ["run", "jiang2024_spur_pair", "--out", str(tmp_path / "o"), "--no-report"]
    )
    assert r.exit_code == 0, r.output
    line = next(ln for ln in r.output.splitlines() if ln.startswith("jiang2024_spur_pair:"))
    m = re.fullmatch(
        r"jiang2024_spur_pair: (\d+) analyses in ([\d.]+) s; ([\d.]+) s in all, with "
        r"start-up and outputs( \(numba kernels [\d.]+ s\))?",
        line,
    )
    assert m, line
    assert float(m.group(3)) >= float(m.group(2))  # the whole command, not the analyses alone
