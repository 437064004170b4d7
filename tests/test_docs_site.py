"""The docs site's generated pages (docs/_hooks.py, mkdocs.yml; issue 15 item 2), without
building the site (`make docs` builds it, strict, in CI): the nav names only pages that exist or
are generated, the API pages list every public module, the gallery pages link their figures."""

from __future__ import annotations

import importlib.util
import pkgutil
from pathlib import Path

import pytest
import yaml

import gearte.models

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "docs" / "_hooks.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _nav_files(nav) -> list[str]:
    out = []
    for entry in nav:
        if isinstance(entry, dict):
            for v in entry.values():
                out += _nav_files(v) if isinstance(v, list) else [v]
        else:
            out.append(entry)
    return out


def test_nav_names_only_pages_that_exist_or_are_generated(hooks) -> None:
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    generated = {"reference/case-files.md", "gallery/index.md", *hooks.API_PAGES}
    missing = [
        f
        for f in _nav_files(config["nav"])
        if f not in generated and not (ROOT / "docs" / f).is_file()
    ]
    assert not missing


def test_models_api_page_lists_every_public_models_module(hooks) -> None:
    title, intro, names = hooks.API_PAGES["api/models.md"]
    page = hooks.api_page(title, intro, names)
    for m in pkgutil.walk_packages(gearte.models.__path__, "gearte.models."):
        if not any(p.startswith("_") for p in m.name.split(".")):
            assert f"::: {m.name}\n" in page


def test_gallery_pages_link_each_case_and_figure(hooks) -> None:
    manifest = {
        "demo_case": {
            "title": "Demo (Hu et al. 2020)",
            "paper": "hu2020",
            "page": "validation/hu2020.md",
            "headlines": [
                ["Geometry", "K1", "0.79", "", ""],
                ["Geometry", "Clearance", "0.02 mm", "", ""],
            ],
            "warnings": ["a | warning"],
            "figures": [
                {"file": "demo_case_00.png", "title": "Profile", "caption": "c", "analysis": "g"}
            ],
            "seconds": 1.0,
            "report": "demo_case_report.html",
        }
    }
    pages = hooks.gallery_pages(manifest)
    assert "[Demo (Hu et al. 2020)](demo_case.md)" in pages["gallery/index.md"]
    assert "Hu et al. 2020" in pages["gallery/index.md"]
    page = pages["gallery/demo_case.md"]
    assert "![Profile](demo_case_00.png)" in page
    assert "](../validation/hu2020.md)" in page
    assert "| analysis | quantity | value |\n" in page  # no spec columns when no row has one
    assert "| Geometry | K1 | 0.79 |" in page and "|  | Clearance | 0.02 mm |" in page
    assert "a | warning" in page
    assert "[demo_case_report.html](demo_case_report.html)" in page  # the full report


def test_gallery_left_out_says_so(hooks) -> None:
    assert "GEARTE_DOCS_GALLERY=0" in hooks.gallery_pages(None)["gallery/index.md"]


def test_short_citation(hooks) -> None:
    assert hooks._short_ref("Jiang J., Zhong X. (2024). Gear backlash") == "Jiang et al. 2024"
    assert hooks._short_ref("Hu, Li, Zhu, Cui (2020). An Elastic") == "Hu et al. 2020"


def test_guide_numbers_come_from_the_build(hooks) -> None:
    """A guide's ``<!-- generated: headlines CASE -->`` line becomes CASE's headline table of the
    build's gallery run (no hand-copied numbers); a case outside the gallery fails the build."""
    entry = {
        "headlines": [["Chain", "Joint lost motion max", "0.1282′", "", ""]],
        "report": "robot_joint_spur_rv_report.html",
    }
    page = "Text.\n\n<!-- generated: headlines robot_joint_spur_rv -->\n\nMore `<!-- x -->`.\n"
    out = hooks.generated_markdown(page, "drives.md", {"robot_joint_spur_rv": entry})
    assert "| Chain | Joint lost motion max | 0.1282′ |" in out
    assert "](gallery/robot_joint_spur_rv.md)" in out
    sub = hooks.generated_markdown(page, "validation/x.md", {"robot_joint_spur_rv": entry})
    assert "](../gallery/robot_joint_spur_rv.md)" in sub
    assert "GEARTE_DOCS_GALLERY=0" in hooks.generated_markdown(page, "drives.md", None)
    with pytest.raises(KeyError):
        hooks.generated_markdown("<!-- generated: headlines nope -->\n", "drives.md", {})
    # the guides that carry model numbers use it
    for guide in ("drives.md", "selective-assembly.md"):
        assert hooks.GENERATED.search((ROOT / "docs" / guide).read_text(encoding="utf-8"))
