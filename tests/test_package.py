"""The package as a dependency sees it: a licence file, the ``py.typed`` marker, and a typed
public API (mypy on a user script sees ``CaseBase`` and ``StudyResult``, not ``Any``)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

USER_SCRIPT = """\
import gearte

case = gearte.load_case("hu2020_rv80e_initial")
result = gearte.run_case(case)
reveal_type(case)
reveal_type(result)
reveal_type(result["tooth_contact"])
force: float = result["tooth_contact"]["max_contact_force [N]"]
result.missing_attribute  # an error: the result is typed, not Any
"""


def test_licence_file_matches_the_metadata():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert meta["license"] == {"text": "BSD-3-Clause"}
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("BSD 3-Clause License")
    assert "gearte developers" in text
    # the three clauses
    assert text.count("\n\n") >= 4 and "Neither the name of the copyright holder" in text


def test_py_typed_marker_is_in_the_package():
    assert (ROOT / "src" / "gearte" / "py.typed").is_file()


def test_version_is_0x_and_in_the_changelog():
    from gearte import __version__

    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    # one place: hatch reads the version from gearte/_version.py
    assert meta["project"]["dynamic"] == ["version"]
    assert meta["tool"]["hatch"]["version"]["path"] == "src/gearte/_version.py"
    assert re.fullmatch(r"0\.\d+\.\d+", __version__)
    changelog = (ROOT / "CHANGELOG.md").read_text()
    sections = re.findall(r"^## \[([^\]]+)\]", changelog, flags=re.M)
    assert sections[0] == "Unreleased"
    assert __version__ in sections, "the current version has a released CHANGELOG section"


def test_mypy_sees_typed_results_in_a_user_script(tmp_path):
    pytest.importorskip("mypy")
    script = tmp_path / "user_script.py"
    script.write_text(USER_SCRIPT)
    env = dict(os.environ, MYPYPATH=str(ROOT / "src"))
    # from the repository root: the project's mypy configuration and cache (`make test` warms it)
    proc = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-error-summary", str(script)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    revealed = re.findall(r'Revealed type is "([^"]+)"', proc.stdout)
    assert revealed == [
        "gearte.io.schema.CaseBase",
        "gearte.results.StudyResult",
        "gearte.results.AnalysisResult",
    ], proc.stdout + proc.stderr
    errors = [ln.split(": error: ")[1] for ln in proc.stdout.splitlines() if ": error:" in ln]
    # the one deliberate mistake is caught (with Any, mypy would accept it), nothing else
    assert errors == ['"StudyResult" has no attribute "missing_attribute"  [attr-defined]']
