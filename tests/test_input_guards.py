"""Inputs that must be refused before they are read or parsed: special files (a device, a FIFO, a
folder) as case, measurement or bench files, case files that refer to each other in a cycle, and
parse bombs (a very long line, a dotted key thousands of parts deep). Each must end as bad input
(exit 2) naming the path, without reading the special file (which would never end or fill the
memory)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from gearte.cli import main
from gearte.errors import BenchFileError, CaseFileError
from gearte.io.case_file import MAX_LINE_CHARS, MAX_NESTING, _dotted_depth, load_case
from gearte.limits import read_input_file

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
posix_only = pytest.mark.skipif(sys.platform == "win32", reason="POSIX special files")


def _fifo(tmp_path: Path) -> Path:
    p = tmp_path / "pipe.csv"
    os.mkfifo(p)
    return p


def _validate(path: Path) -> tuple[int, str]:
    res = CliRunner().invoke(main, ["validate", str(path)])
    return res.exit_code, res.output


@posix_only
@pytest.mark.parametrize("special", ["/dev/zero", "/dev/urandom", "fifo", "folder"])
def test_read_input_file_refuses_special_files_before_reading(tmp_path, special):
    path = {"fifo": lambda: _fifo(tmp_path), "folder": lambda: tmp_path}.get(
        special, lambda: Path(special)
    )()
    if not path.exists():
        pytest.skip(f"{path} missing here")
    with pytest.raises(OSError) as info:
        read_input_file(path, 1000)
    assert "not a regular file" in str(info.value) or "folder" in str(info.value)


def test_read_input_file_refuses_a_file_over_the_limit(tmp_path):
    p = tmp_path / "big.csv"
    p.write_bytes(b"x" * 101)
    with pytest.raises(OSError, match="101 bytes; the limit is 100"):
        read_input_file(p, 100)
    assert read_input_file(p, 101) == b"x" * 101


@posix_only
@pytest.mark.parametrize("special", ["/dev/zero", "fifo", "folder"])
def test_case_path_to_a_special_file_is_bad_input(tmp_path, special):
    path = {"fifo": lambda: _fifo(tmp_path), "folder": lambda: tmp_path}.get(
        special, lambda: Path(special)
    )()
    code, out = _validate(path)
    assert code == 2, out
    assert str(path) in out and "not a regular file" in out


def _serial_case(tmp_path: Path, name: str, **replace: str) -> Path:
    """The bundled serial case written to ``tmp_path/name`` with its measurement paths absolute
    and ``replace`` applied (``key = "value"`` lines)."""
    text = (EXAMPLES / "synthetic_rv110e_serial.toml").read_text(encoding="utf-8")
    text = text.replace('"lots/', f'"{EXAMPLES.as_posix()}/lots/')
    lines = []
    for line in text.splitlines():
        key = line.split("=", 1)[0].strip()
        if "=" in line and key in replace:
            line = f'{key} = "{replace[key]}"'
        lines.append(line)
    out = tmp_path / name
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out


@posix_only
@pytest.mark.parametrize("special", ["/dev/zero", "/dev/urandom", "fifo", "folder"])
def test_measurement_file_that_is_special_is_bad_input(tmp_path, special):
    path = {"fifo": lambda: _fifo(tmp_path), "folder": lambda: tmp_path / "d"}.get(
        special, lambda: Path(special)
    )()
    if special == "folder":
        path.mkdir()
    case = _serial_case(tmp_path, "serial.toml", disc_bores=str(path))
    code, out = _validate(case)
    assert code == 2, out
    assert str(path) in out


@posix_only
def test_bench_file_that_is_a_device_is_bad_input(tmp_path):
    from gearte.io.bench import read_hysteresis

    with pytest.raises(BenchFileError, match="/dev/urandom.*device"):
        read_hysteresis("/dev/urandom")


def test_case_naming_itself_is_a_cycle(tmp_path):
    case = _serial_case(tmp_path, "self.toml", case="self.toml")
    with pytest.raises(CaseFileError, match=r"cycle \(.*self\.toml → .*self\.toml\)"):
        load_case(case)
    code, out = _validate(case)
    assert code == 2 and "cycle" in out


def test_two_cases_naming_each_other_are_a_cycle(tmp_path):
    _serial_case(tmp_path, "a.toml", case="b.toml")
    b = _serial_case(tmp_path, "b.toml", case="a.toml")
    code, out = _validate(b)
    assert code == 2, out
    assert "cycle" in out and "b.toml → " in out and "a.toml → " in out


def test_chain_drive_naming_its_own_file_is_a_cycle(tmp_path):
    text = (EXAMPLES / "robot_joint_spur_rv.toml").read_text(encoding="utf-8")
    assert 'case = "han2023_rv110e.toml"' in text
    p = tmp_path / "chain.toml"
    p.write_text(text.replace('case = "han2023_rv110e.toml"', 'case = "chain.toml"'), "utf-8")
    code, out = _validate(p)
    assert code == 2, out
    assert "chain.stages.1.drive" in out and "cycle" in out


def test_same_file_twice_is_not_a_cycle(tmp_path):
    """Two stages naming one drive file: loaded twice, one after the other — no cycle."""
    case = load_case("robot_joint_spur_rv")
    assert case.case.kind == "gear_chain"


def test_an_80_kb_dotted_key_is_refused_before_parsing(tmp_path):
    p = tmp_path / "dotted.toml"
    p.write_text('[case]\nkind = "rv_reducer"\n' + ".".join(["a"] * 40_000) + " = 1\n")
    assert p.stat().st_size > 80_000
    with pytest.raises(CaseFileError, match=f"the limit is {MAX_LINE_CHARS}"):
        load_case(p)


def test_a_dotted_key_deeper_than_the_nesting_limit_is_refused(tmp_path):
    p = tmp_path / "dotted.toml"
    depth = MAX_NESTING + 1
    p.write_text('[case]\nkind = "rv_reducer"\n' + ".".join(["a"] * depth) + " = 1\n")
    with pytest.raises(CaseFileError, match=f"dotted key of {depth} parts"):
        load_case(p)
    headers = "\n".join("[" + ".".join(["t"] * i) + "]" for i in range(1, depth + 1))
    p.write_text(headers + "\n")
    with pytest.raises(CaseFileError, match=f"line {depth} has a dotted key"):
        load_case(p)


@pytest.mark.parametrize(
    ("line", "depth"),
    [
        ("a.b.c = 1", 3),
        ('a."b.c".d = 1', 3),
        ("[x.y]", 2),
        ("v = [1.5, 2.5, 3.5, 4.5]", 2),
        ("t = 1979-05-27T07:32:00Z", 1),
        ('s = "a.b.c.d.e"', 1),
    ],
)
def test_dotted_depth(line, depth):
    assert _dotted_depth(line) == depth


def test_every_bundled_case_passes_the_preparse_guard():
    from gearte.cases import list_cases
    from gearte.io.case_file import _preparse_problem

    for name, path in list_cases().items():
        assert _preparse_problem(path.read_text(encoding="utf-8")) is None, name
