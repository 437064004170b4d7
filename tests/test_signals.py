"""Signals (issue 13): SIGINT and SIGTERM stop a run cleanly with exit 128 + signal number, keep
the previous outputs, and an interrupted sweep writes the points that finished, marked partial."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from gearte.report.outputs import write_file_set

TESTS = Path(__file__).resolve().parent
CLI = (
    f"import sys; sys.path.insert(0, {str(TESTS)!r}); "
    "from gearte.studies import register_kind; register_kind('stall_test', 'stall_kind'); "
    "from gearte.cli import main; sys.exit(main())"
)


def _start(tmp_path: Path, args: list[str]) -> tuple[subprocess.Popen, Path]:
    marker = tmp_path / "stalling"
    env = {**os.environ, "GEARTE_TEST_STALL": str(marker)}
    p = subprocess.Popen(
        [sys.executable, "-c", CLI, *args], env=env, stderr=subprocess.PIPE, text=True
    )
    return p, marker


def _wait_for(p: subprocess.Popen, marker: Path) -> None:
    import time

    while not marker.exists():  # the run announces the stall; no timing assumption
        assert p.poll() is None, p.stderr.read()
        time.sleep(0.05)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_mid_run_exits_cleanly_and_keeps_previous_outputs(tmp_path, sig):
    case = tmp_path / "c.toml"
    case.write_text('[case]\nkind = "stall_test"\n[demo]\nlength_mm = 1.0\nstall = true\n')
    out = tmp_path / "o"
    write_file_set(out, {"results.json": b"old", "report.html": b"old"})
    p, marker = _start(tmp_path, ["run", str(case), "--out", str(out), "--no-progress"])
    _wait_for(p, marker)
    p.send_signal(sig)
    assert p.wait() == 128 + sig
    err = p.stderr.read()
    assert "interrupted" in err and "Traceback" not in err
    assert (out / "results.json").read_bytes() == b"old"
    assert (out / "report.html").read_bytes() == b"old"
    assert [e.name for e in tmp_path.iterdir() if "staging" in e.name] == []


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_sweep_writes_finished_points_marked_partial(tmp_path, sig):
    case = tmp_path / "c.toml"
    case.write_text('[case]\nkind = "stall_test"\n[demo]\nlength_mm = 1.0\n')
    out = tmp_path / "s"
    args = ["sweep", str(case), "--vary", "demo.stall=false,false,true", "--workers", "1"]
    p, marker = _start(tmp_path, [*args, "--out", str(out), "--no-progress"])
    _wait_for(p, marker)
    p.send_signal(sig)
    assert p.wait() == 128 + sig, p.stderr.read()
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["partial"] is True
    assert [pt["params"] for pt in doc["points"]] == [{"demo.stall": False}] * 2
