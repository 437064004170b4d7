"""The example notebooks (examples/notebooks/, issue 15 item 4) run top to bottom in a fresh
Jupyter kernel (nbclient), and their cells show what they say: the summary table, a pandas table,
the figures."""

from __future__ import annotations

import os
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = Path(__file__).resolve().parents[1] / "examples" / "notebooks"


def _run(name: str) -> nbformat.NotebookNode:
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    env_cache = os.environ.get("NUMBA_CACHE_DIR")
    client = NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    assert env_cache is None or os.environ["NUMBA_CACHE_DIR"] == env_cache
    client.execute()
    return nb


def _outputs(nb: nbformat.NotebookNode, kind: str) -> list[str]:
    out = []
    for cell in nb.cells:
        for o in cell.get("outputs", []):
            if o.get("output_type") == "error":
                raise AssertionError(f"{o['ename']}: {o['evalue']}")
            data = o.get("data", {})
            if kind in data:
                out.append(data[kind])
    return out


def test_the_example_notebooks_are_the_two_of_the_docs() -> None:
    assert sorted(p.name for p in NOTEBOOKS.glob("*.ipynb")) == [
        "cycloid_yield.ipynb",
        "first_rv_reducer.ipynb",
    ]


@pytest.mark.parametrize("name", ["first_rv_reducer.ipynb", "cycloid_yield.ipynb"])
def test_example_notebook_runs_and_shows_tables_and_figures(name: str) -> None:
    nb = _run(name)
    html = _outputs(nb, "text/html")
    assert any('class="gearte-repr"' in h for h in html)  # a result's summary
    assert any("dataframe" in h for h in html)  # a pandas table
    assert _outputs(nb, "image/png")  # a figure
