"""Output safety (issue 13): the case name is a label, the output folder is checked before any
computation, and results.json + report.html + extra files are replaced as one set, whatever
fails (read-only folder, full disk, file-size limit, SIGKILL between writes, concurrent runs)."""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from gearte.cli import EXIT_OUTPUT, main
from gearte.errors import OutputError
from gearte.report import outputs
from gearte.report.outputs import MARKER, check_output_dir, safe_label, write_file_set

GOOD = '[case]\nkind = "foundation_test"\nname = "{name}"\n[demo]\nlength_mm = {length}\n'
ROOT = Path(__file__).resolve().parents[1]


def _case(tmp_path: Path, name: str = "c", length: float = 4.0) -> Path:
    p = tmp_path / "cases" / f"{name}.toml"
    p.parent.mkdir(exist_ok=True)
    p.write_text(GOOD.format(name=name.replace('"', ""), length=length))
    return p


def _left_over(folder: Path) -> list[str]:
    """Temporaries gearte may have left in ``folder`` (staging folders, .tmp files)."""
    return [e.name for e in folder.iterdir() if "gearte-staging" in e.name or e.suffix == ".tmp"]


def _set(a: str, b: str) -> dict[str, bytes]:
    return {"results.json": a.encode(), "report.html": b.encode()}


def _read(out: Path) -> tuple[str, str]:
    return (out / "results.json").read_text(), (out / "report.html").read_text()


@pytest.mark.parametrize(
    "name, label",
    [("../../x", "_.._x"), ("..", "case"), ("/etc/passwd", "_etc_passwd"), ("a\x00b", "a_b")],
)
def test_case_name_is_a_label_never_a_path(name, label):
    assert safe_label(name) == label


def test_reproducer_name_dotdot_writes_under_out(tmp_path, monkeypatch):
    """Issue 13 reproducer: ``name = "../../x"`` wrote two folders up; now out/_.._x."""
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    case = work / "c.toml"
    case.write_text(GOOD.format(name="../../x", length=4.0))
    r = CliRunner().invoke(main, ["run", str(case), "--no-progress", "--no-report"])
    assert r.exit_code == 0, r.output
    assert (work / "out" / "_.._x" / "results.json").is_file()
    assert not (tmp_path / "x").exists() and sorted(p.name for p in tmp_path.iterdir()) == ["a"]


def test_set_replaces_the_previous_set_whole(tmp_path):
    out = tmp_path / "o"
    write_file_set(out, {**_set("1", "1"), "t.csv": b"x"})
    write_file_set(out, _set("2", "2"))
    assert _read(out) == ("2", "2")
    assert sorted(p.name for p in out.iterdir()) == sorted([MARKER, "results.json", "report.html"])
    assert json.loads((out / MARKER).read_text())["files"] == ["report.html", "results.json"]
    assert _left_over(tmp_path) == []


@pytest.mark.parametrize(
    "err", [errno.ENOSPC, errno.EFBIG, errno.EROFS, errno.EACCES, errno.EDQUOT]
)
def test_injected_write_failure_keeps_previous_set_and_no_temporaries(tmp_path, monkeypatch, err):
    out = tmp_path / "o"
    write_file_set(out, _set("old", "old"))
    calls = []

    def failing(path, data):
        calls.append(path)
        if len(calls) == 2:  # the first file is written, the second hits the fault
            raise OSError(err, os.strerror(err))
        real(path, data)

    real = outputs._write_file
    monkeypatch.setattr(outputs, "_write_file", failing)
    with pytest.raises(OutputError, match=os.strerror(err)):
        write_file_set(out, _set("new", "new"))
    assert _read(out) == ("old", "old")
    assert _left_over(tmp_path) == []


def test_disk_full_through_the_cli_is_exit_4_after_saying_so(tmp_path, monkeypatch):
    def full(path, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(outputs, "_write_file", full)
    r = CliRunner().invoke(main, ["run", str(_case(tmp_path)), "--out", str(tmp_path / "o")])
    assert r.exit_code == EXIT_OUTPUT, r.output
    assert "disk is full" in r.output and "Traceback" not in r.output
    assert _left_over(tmp_path) == []


def test_file_size_limit_is_a_user_error_not_a_bug(tmp_path):
    """A real RLIMIT_FSIZE in a subprocess: EFBIG, exit 4, previous outputs intact."""
    out = tmp_path / "o"
    write_file_set(out, _set("old", "old"))
    code = (
        "import resource, sys; resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000)); "
        f"sys.path.insert(0, {str(ROOT / 'tests')!r}); "
        "from gearte.studies import register_kind; "
        "register_kind('foundation_test', 'foundation_kind'); "
        "from gearte.cli import main; sys.exit(main())"
    )
    args = ["run", str(_case(tmp_path)), "--out", str(out), "--no-progress"]
    p = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    assert p.returncode == EXIT_OUTPUT, p.stderr
    assert "file-size limit" in p.stderr
    assert _read(out) == ("old", "old") and _left_over(tmp_path) == []


def test_read_only_output_is_refused_before_computing(tmp_path, monkeypatch):
    """Refused by the probe before the case runs (root ignores chmod, so the fault is injected
    into the probe where the test runs as root; as another user a real 0o555 folder is used)."""
    parent = tmp_path / "ro"
    parent.mkdir()
    write_file_set(parent / "o", _set("old", "old"))  # the previous set stays as it is
    if os.geteuid() == 0:

        def read_only(*a, **k):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))

        monkeypatch.setattr(outputs.tempfile, "mkdtemp", read_only)
    else:
        parent.chmod(0o555)
    ran = []
    monkeypatch.setattr("gearte.studies.run_case", lambda *a, **k: ran.append(1))
    try:
        r = CliRunner().invoke(main, ["run", str(_case(tmp_path)), "--out", str(parent / "o")])
    finally:
        parent.chmod(0o755)
    assert r.exit_code == EXIT_OUTPUT, r.output
    assert ran == [] and "Traceback" not in r.output
    assert _read(parent / "o") == ("old", "old") and _left_over(parent) == []


@pytest.mark.parametrize("where", ["file", "under_file", "dangling", "foreign", "nul"])
def test_unusable_out_is_refused_before_computing(tmp_path, where):
    f = tmp_path / "f.txt"
    f.write_text("x")
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("precious")
    (tmp_path / "link").symlink_to(tmp_path / "nowhere")
    target = {
        "file": f,
        "under_file": f / "o",
        "dangling": tmp_path / "link",
        "foreign": foreign,
        "nul": "a\x00b",
    }[where]
    with pytest.raises(OutputError) as err:
        check_output_dir(target)
    assert "\n" not in str(err.value)
    assert (foreign / "thesis.tex").read_text() == "precious" and f.read_text() == "x"


def test_out_containing_the_current_folder_is_refused(tmp_path, monkeypatch):
    out = tmp_path / "o"
    write_file_set(out, _set("1", "1"))
    monkeypatch.chdir(out)
    with pytest.raises(OutputError, match="current folder"):
        check_output_dir(out)


_KILLER = textwrap.dedent(
    """
    import os, signal, sys
    from gearte.report import outputs
    where, out = sys.argv[1], sys.argv[2]
    real_write, real_swap, n = outputs._write_file, outputs._swap, []
    def write(path, data):
        n.append(path)
        if where == "mid_write" and len(n) == 2:
            os.kill(os.getpid(), signal.SIGKILL)
        real_write(path, data)
    def swap(staging, target):
        if where == "before_swap":
            os.kill(os.getpid(), signal.SIGKILL)
        real_swap(staging, target)
    outputs._write_file, outputs._swap = write, swap
    outputs.write_file_set(out, {"results.json": b"new", "report.html": b"new"})
    """
)


@pytest.mark.parametrize("where", ["mid_write", "before_swap"])
def test_sigkill_between_writes_keeps_the_previous_set(tmp_path, where):
    out = tmp_path / "o"
    write_file_set(out, _set("old", "old"))
    p = subprocess.run([sys.executable, "-c", _KILLER, where, str(out)], capture_output=True)
    assert p.returncode == -signal.SIGKILL
    assert _read(out) == ("old", "old")
    assert len(_left_over(tmp_path)) == 1  # the killed process's staging folder ...
    write_file_set(out, _set("next", "next"))  # ... is removed by the next write
    assert _read(out) == ("next", "next") and _left_over(tmp_path) == []


_WRITER = textwrap.dedent(
    """
    import sys
    from gearte.report.outputs import write_file_set
    tag, out = sys.argv[1], sys.argv[2]
    for i in range(15):
        text = f"{tag}{i}".encode()
        write_file_set(out, {"results.json": text, "report.html": text})
    """
)


def test_two_concurrent_runs_into_one_folder_leave_one_whole_set(tmp_path):
    out = tmp_path / "o"
    write_file_set(out, _set("old", "old"))
    procs = [
        subprocess.Popen([sys.executable, "-c", _WRITER, tag, str(out)], stderr=subprocess.PIPE)
        for tag in "ab"
    ]
    while any(p.poll() is None for p in procs):
        # Read both files through one handle of the folder: the set a reader saw at one instant.
        dfd = os.open(out, os.O_RDONLY)
        try:
            pair = []
            for name in ("results.json", "report.html"):
                fd = os.open(name, os.O_RDONLY, dir_fd=dfd)
                pair.append(os.read(fd, 100))
                os.close(fd)
            assert pair[0] == pair[1], "results.json and report.html from different runs"
        except FileNotFoundError:
            pass  # swapped out, its old set being removed: not what a reader opens
        finally:
            os.close(dfd)
    for p in procs:
        assert p.wait() == 0, p.stderr.read()
    a, b = _read(out)
    assert a == b and a in ("a14", "b14")
    assert _left_over(tmp_path) == []


def test_sweep_output_is_one_set_with_its_plots(tmp_path):
    r = CliRunner().invoke(
        main,
        [
            "sweep",
            str(_case(tmp_path)),
            "--vary",
            "demo.length_mm=1:2:2",
            "--out",
            str(tmp_path / "s"),
            "--no-progress",
        ],
    )
    assert r.exit_code == 0, r.output
    assert (tmp_path / "s" / "sweep.csv").is_file() and (tmp_path / "s" / MARKER).is_file()
    assert _left_over(tmp_path) == []


def test_nonfinite_values_are_written_as_null_with_a_warning():
    """Issue 13: NaN was written as ``null`` without saying so."""
    import math

    from gearte.studies import run_case

    result = run_case({"case": {"kind": "foundation_test"}, "demo": {"length_mm": 1.0}})
    result["demo"].values["ratio"] = math.nan
    doc = json.loads(result.to_json())
    assert doc["analyses"]["demo"]["values"]["ratio"] is None
    assert any("ratio" in w and "null" in w for w in doc["warnings"])


def test_table_named_after_a_long_label_gets_a_file_name_that_fits():
    """Found by the fuzzing run: a gear-chain stage named with 300 characters named a CSV table
    whose file name the file system refused (exit 4 after the whole run). Long names are cut
    and made unique by a hash."""
    from gearte.report.tables import _file_name

    a, b = _file_name("x" * 300 + "_a"), _file_name("x" * 300 + "_b")
    assert len(a.encode()) <= 255 and len(b.encode()) <= 255 and a != b
    assert _file_name("stage_1_lost_motion") == "stage_1_lost_motion.csv"
    assert len(_file_name("é" * 300).encode()) <= 255
