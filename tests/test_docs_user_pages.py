"""The docs site is for users: no page refers to the project's issue tracker or work sessions
("issue 12", "#12", "session 9"), every study kind is on the home page. Checked on the Markdown
sources, the generated case-file reference and the docstrings the API pages render."""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
from pathlib import Path

import pytest

from gearte.io.kinds import available_kinds

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

# "issue 12", "issues 12 and 14", "Issue 14's", "session 9", "#12" (not an anchor, a colour or an
# upstream project's reference such as numba#8705)
ISSUE_REF = re.compile(r"\b(?:issues?|sessions?)\s+\d+|(?<![\w/&#])#\d{1,4}(?!\w)", re.IGNORECASE)


def issue_references(text: str) -> list[str]:
    """Every issue or session reference in ``text``, each with its line."""
    out = []
    for line in text.splitlines():
        for m in ISSUE_REF.finditer(line):
            out.append(f"{m.group(0)!r} in: {line.strip()[:120]}")
    return out


def test_the_check_finds_references():
    # the check must be able to fail
    assert issue_references("Since issue 12 the kernel ...")
    assert issue_references("(issues 12 and 14)")
    assert issue_references("Session 13: measured")
    assert issue_references("see #31 for the reason")
    assert not issue_references("numba#8705, a miscompilation")
    assert not issue_references("[link](page.md#section-2) and colour #336699")
    assert not issue_references("13 issues remain; Table 2, eq 32")


def _pages() -> list[Path]:
    return sorted(p for p in DOCS.rglob("*.md"))


@pytest.mark.parametrize("page", _pages(), ids=lambda p: str(p.relative_to(DOCS)))
def test_no_issue_references_in_docs_pages(page):
    assert issue_references(page.read_text(encoding="utf-8")) == []


def _shipped_kinds() -> set[str]:
    """The study kinds gearte ships (the tests register kinds of their own)."""
    studies = ROOT / "src" / "gearte" / "studies"
    return {
        p.stem
        for p in studies.glob("*.py")
        if not p.stem.startswith("_") and re.search(r"^KIND = ", p.read_text(), flags=re.M)
    }


def test_no_issue_references_in_the_generated_case_file_reference():
    from gearte.io.schema_reference import reference_markdown

    assert issue_references(reference_markdown(sorted(_shipped_kinds()))) == []


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", DOCS / "_hooks.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _docstrings(name: str) -> list[tuple[str, str]]:
    """(qualified name, docstring) of a module or member and its public members, as the API
    pages render them."""
    try:
        obj = importlib.import_module(name)
    except ImportError:
        mod, _, attr = name.rpartition(".")
        obj = getattr(importlib.import_module(mod), attr)
    out = [(name, inspect.getdoc(obj) or "")]
    members = inspect.getmembers(obj) if inspect.ismodule(obj) or inspect.isclass(obj) else []
    for attr, member in members:
        if attr.startswith("_"):
            continue
        owner = getattr(member, "__module__", None)
        if inspect.ismodule(obj) and owner != obj.__name__:
            continue  # imported names are rendered on their own module's page
        if inspect.isfunction(member) or inspect.isclass(member) or inspect.ismethod(member):
            out.append((f"{name}.{attr}", inspect.getdoc(member) or ""))
            if inspect.isclass(member):
                out += [
                    (f"{name}.{attr}.{a}", inspect.getdoc(m) or "")
                    for a, m in vars(member).items()
                    if not a.startswith("_") and callable(m) and m.__doc__
                ]
    return out


def test_no_issue_references_in_the_api_pages_docstrings():
    hooks = _hooks()
    found = []
    for _title, _intro, names in hooks.API_PAGES.values():
        for n in names:
            for m in hooks._modules(n):
                for qual, doc in _docstrings(m):
                    found += [f"{qual}: {r}" for r in issue_references(doc)]
    assert found == []


def test_every_study_kind_is_on_the_docs_home_page():
    home = (DOCS / "index.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (.+?) \|", home, flags=re.M)
    listed = {k for row in rows for k in re.findall(r"`(\w+)`", row)}
    kinds = _shipped_kinds()
    assert kinds <= set(available_kinds())
    assert kinds, "no study kinds found"
    assert kinds <= listed, sorted(kinds - listed)
