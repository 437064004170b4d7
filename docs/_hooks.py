"""MkDocs hooks of gearte's docs site (mkdocs.yml ``hooks``): pages generated at build time.

* ``reference/case-files.md``: the case-file reference, from the schemas
  (:func:`gearte.io.schema_reference.reference_markdown`);
* ``api/*.md``: one mkdocstrings block per public module of the facade, models, tolerance and
  drives packages (walked, so a new module appears without editing a page);
* ``gallery/``: the paper reproductions, run with the bundled cases (Monte-Carlo sample counts cut
  to :data:`GALLERY_SAMPLES`), their headline table and every figure of their report. The run's
  PNGs are cached in ``.docs_cache/gallery/<hash of src/ and examples/>/``: an unchanged tree
  rebuilds in seconds. ``GEARTE_DOCS_GALLERY=0`` leaves the gallery out (a page says so).

Run ``python docs/_hooks.py`` to fill the gallery cache without building the site. The cases run
in parallel processes, one per core (``GEARTE_DOCS_JOBS``).
"""

from __future__ import annotations

import hashlib
import json
import os
import pkgutil
import re
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / ".docs_cache" / "gallery"

#: The gallery: (bundled case, paper key, validation page), one reproduction per paper.
GALLERY: list[tuple[str, str, str]] = [
    ("hu2020_rv80e_initial", "hu2020", "validation/hu2020.md"),
    ("jiang2024_shoulder_swing", "jiang2024", "validation/jiang2024.md"),
    ("wang2013_2kh_eq9", "wang2013", "validation/wang2013.md"),
    ("han2023_rv110e", "han2023", "validation/han2023.md"),
    ("li2023_rv_errors", "li2023", "validation/li2023.md"),
    ("robot_joint_spur_rv", "jiang2024", "drives.md"),
    ("synthetic_rv110e_lot", "han2023", "selective-assembly.md"),
]
#: Monte-Carlo samples of the gallery runs (the figures' layout, not their statistics, is shown).
GALLERY_SAMPLES = 200

#: API pages: page → (title, introduction, modules; a package name means all its modules).
API_PAGES: dict[str, tuple[str, str, list[str]]] = {
    "api/index.md": (
        "API reference: top level",
        "The public entry points. `import gearte` exposes `load_case`, `validate_case`, "
        "`run_case`, `write_outputs` and `list_cases` (lazily imported from the modules below).",
        [
            "gearte.io.case_file.load_case",
            "gearte.io.case_file.validate_case",
            "gearte.studies.run_case",
            "gearte.studies.RunOptions",
            "gearte.results.StudyResult",
            "gearte.results.AnalysisResult",
            "gearte.report.outputs.write_outputs",
            "gearte.cases.list_cases",
            "gearte.errors",
            "gearte.units",
        ],
    ),
    "api/models.md": (
        "API reference: models",
        "Pure physics functions of arrays, one module per phenomenon (docs/architecture.md).",
        ["gearte.models"],
    ),
    "api/tolerance.md": (
        "API reference: tolerance",
        "The statistics of tolerances, tied to no drive: distributions, stack-up, Monte-Carlo, "
        "contributions, yield, allocation, ISO 1328 grades.",
        ["gearte.tolerance"],
    ),
    "api/drives.md": (
        "API reference: drives",
        "The drive interface and one adapter per drive; drives in series (docs/drives.md).",
        ["gearte.drives"],
    ),
}


def _modules(name: str) -> list[str]:
    """``name`` and, for a package, its public submodules (recursively), sorted."""
    import importlib

    if not name.startswith("gearte."):
        return [name]
    try:
        mod = importlib.import_module(name)
    except ImportError:
        return [name]  # a member (gearte.studies.run_case), not a module
    out = [name]
    if hasattr(mod, "__path__"):
        for m in pkgutil.walk_packages(mod.__path__, name + "."):
            if not any(p.startswith("_") for p in m.name.split(".")):
                out.append(m.name)
    return sorted(out) if hasattr(mod, "__path__") else out


def api_page(title: str, intro: str, names: list[str]) -> str:
    """Markdown of one API page: ``title``, ``intro``, a mkdocstrings block per name."""
    out = [f"# {title}", "", intro, ""]
    for n in names:
        for m in _modules(n):
            out += [f"::: {m}", "    options:", "      show_root_full_path: true", ""]
    return "\n".join(out)


def _tree_hash() -> str:
    h = hashlib.sha256()
    for base in ("src/gearte", "examples"):
        for p in sorted((ROOT / base).rglob("*")):
            if p.is_file() and p.suffix in (".py", ".toml", ".j2", ".csv", ".txt", ".json"):
                h.update(str(p.relative_to(ROOT)).encode())
                h.update(p.read_bytes())
    import inspect

    h.update(f"{GALLERY!r} {GALLERY_SAMPLES} {inspect.getsource(run_case)}".encode())
    return h.hexdigest()[:16]


def _short_ref(ref: str) -> str:
    """``"Jiang J., Zhong X., … (2024). Title"`` → ``"Jiang et al. 2024"``."""
    surname = re.split(r"[ ,]", ref.strip(), maxsplit=1)[0]
    year = re.search(r"\((\d{4})\)", ref)
    return f"{surname} et al. {year.group(1)}" if year else ref.split(".")[0]


def _md_cell(text: str) -> str:
    return str(text).replace("|", "\\|")


def run_case(case_name: str, paper: str, page: str, out: Path) -> dict[str, Any]:
    """Run one gallery case, write its figures as PNG under ``out`` and return its manifest
    entry (title, headline rows, warnings, figures with title and caption, seconds)."""
    from gearte.io.case_file import load_case
    from gearte.plotting import figures_for
    from gearte.report.summary import headlines, tradeoff_warnings
    from gearte.studies import RunOptions
    from gearte.studies import run_case as run

    t0 = time.perf_counter()
    # no progress bars: the cases run side by side, their bars would overwrite each other
    result = run(load_case(case_name), RunOptions(samples=GALLERY_SAMPLES, progress=False))
    figs = figures_for(result)
    entries = []
    for i, f in enumerate(figs):
        file = f"{case_name}_{i:02d}.png"
        f.fig.savefig(out / file, dpi=80)
        entries.append(
            {"file": file, "title": f.title, "caption": f.caption, "analysis": f.analysis}
        )
    from gearte.report.html import render_report

    report = f"{case_name}_report.html"
    (out / report).write_text(render_report(result), encoding="utf-8")
    entry = {
        "title": result.case.case.title or case_name,
        "report": report,
        "paper": paper,
        "page": page,
        "headlines": [[r.title, r.quantity, r.value, r.spec, r.status] for r in headlines(result)],
        "warnings": list(result.warnings) + tradeoff_warnings(result),
        "figures": entries,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    print(f"gallery: {case_name}: {len(figs)} figures, {entry['seconds']} s", flush=True)
    return entry


def run_gallery(out: Path) -> dict[str, Any]:
    """Run every gallery case into ``out`` and return the manifest, case → entry. The cases run
    as separate processes, as many at a time as there are cores (``GEARTE_DOCS_JOBS`` to
    change it; 1 runs them in this process), each writing ``<case>.json`` beside its PNGs."""
    import subprocess
    from concurrent.futures import ThreadPoolExecutor

    out.mkdir(parents=True, exist_ok=True)
    jobs = int(os.environ.get("GEARTE_DOCS_JOBS", os.cpu_count() or 1))
    print(
        f"gallery: running {len(GALLERY)} cases, {max(1, jobs)} at a time (one line each as "
        "it finishes; cached until src/ or examples/ change)",
        flush=True,
    )
    if jobs <= 1:
        manifest = {c: run_case(c, paper, page, out) for c, paper, page in GALLERY}
    else:
        env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))

        def one(case: tuple[str, str, str]) -> None:
            cmd = [sys.executable, __file__, "--case", case[0], str(out)]
            subprocess.run(cmd, check=True, env=env)

        with ThreadPoolExecutor(min(jobs, len(GALLERY))) as pool:
            list(pool.map(one, GALLERY))
        manifest = {
            c: json.loads((out / f"{c}.json").read_text(encoding="utf-8")) for c, _, _ in GALLERY
        }
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    return manifest


def gallery(enabled: bool = True) -> tuple[dict[str, Any] | None, Path]:
    """The gallery's manifest and PNG folder, from the cache or a fresh run."""
    folder = CACHE / _tree_hash()
    if not enabled:
        return None, folder
    if (folder / "manifest.json").is_file():
        return json.loads((folder / "manifest.json").read_text(encoding="utf-8")), folder
    tmp = folder.with_name(folder.name + f".tmp{os.getpid()}")
    manifest = run_gallery(tmp)
    tmp.rename(folder)
    return manifest, folder


def headline_table(m: dict[str, Any]) -> list[str]:
    """Markdown lines of a gallery entry's headline table (the report's summary rows)."""
    spec = any(r[3] or r[4] for r in m["headlines"])
    cols = ["analysis", "quantity", "value"] + (["spec", "status"] if spec else [])
    p = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    prev = None
    for row in m["headlines"]:
        cells = [("" if row[0] == prev else row[0]), *row[1 : len(cols)]]
        prev = row[0]
        p.append("| " + " | ".join(_md_cell(c) for c in cells) + " |")
    return p


#: In a docs page, a line ``<!-- generated: headlines CASE -->`` becomes CASE's headline table
#: from the gallery run of this build (CASE must be in GALLERY): numbers in the guides are never
#: copied by hand.
GENERATED = re.compile(r"^<!-- generated: headlines (\w+) -->$", re.M)


def generated_markdown(markdown: str, src_uri: str, manifest: dict[str, Any] | None) -> str:
    """``markdown`` with each ``<!-- generated: headlines CASE -->`` replaced by the table."""

    def table(match: re.Match[str]) -> str:
        name = match.group(1)
        if name not in {c for c, _, _ in GALLERY}:
            raise KeyError(f"{src_uri}: {name!r} is not a gallery case (docs/_hooks.py GALLERY)")
        if manifest is None:
            return "*(Numbers left out of this build: `GEARTE_DOCS_GALLERY=0`.)*"
        up = "../" * src_uri.count("/")
        lines = headline_table(manifest[name])
        lines += [
            "",
            f"*`gearte run {name}`, run when this site was built; its figures and full report: "
            f"[gallery]({up}gallery/{name}.md).*",
        ]
        return "\n".join(lines)

    return GENERATED.sub(table, markdown)


def gallery_pages(manifest: dict[str, Any] | None) -> dict[str, str]:
    """Markdown of the gallery: ``gallery/index.md`` and one page per case."""
    from gearte.references import REFERENCES

    if manifest is None:
        return {
            "gallery/index.md": "# Gallery\n\nLeft out of this build (`GEARTE_DOCS_GALLERY=0`).\n"
        }
    index = [
        "# Gallery: the paper reproductions",
        "",
        "Each bundled paper case, run when these pages were built "
        f"(Monte-Carlo samples cut to {GALLERY_SAMPLES}), with its report's headline table "
        "and figures. The paper's equations as implemented and its published numbers beside "
        "gearte's are on the validation pages.",
        "",
        "| case | paper | figures | run time [s] |",
        "|---|---|---|---|",
    ]
    pages: dict[str, str] = {}
    for case_name, m in manifest.items():
        ref = REFERENCES.get(m["paper"], m["paper"])
        index.append(
            f"| [{_md_cell(m['title'])}]({case_name}.md) | {_short_ref(ref)} | "
            f"{len(m['figures'])} | {m['seconds']} |"
        )
        p = [
            f"# {m['title']}",
            "",
            f"Case `{case_name}` (`gearte run {case_name}`); paper: {ref}. "
            + (
                f"Validation: [{m['paper']}](../{m['page']})."
                if m["page"].startswith("validation/")
                else f"Guide: [{m['page'].removesuffix('.md').replace('-', ' ')}](../{m['page']})."
            ),
            "",
            "## Summary",
            "",
        ]
        p += headline_table(m)
        p += ["", f"The full report of this run: [{m['report']}]({m['report']})."]
        if m["warnings"]:
            p += ["", '!!! warning "Warnings"', ""]
            p += [f"    - {w}" for w in m["warnings"]]
        p += ["", "## Figures", ""]
        for f in m["figures"]:
            p += [f"### {f['title']}", "", f"![{f['title']}]({f['file']})", ""]
            if f["caption"]:
                p += [f["caption"], ""]
        pages[f"gallery/{case_name}.md"] = "\n".join(p)
    pages["gallery/index.md"] = "\n".join(index) + "\n"
    return pages


# --- MkDocs events -----------------------------------------------------------------------------

_STATE: dict[str, Any] = {}


def on_config(config: Any) -> Any:
    """Run (or read from the cache) the gallery and list its pages under "Gallery" in the nav."""
    sys.path.insert(0, str(ROOT / "src"))
    enabled = os.environ.get("GEARTE_DOCS_GALLERY", "1") != "0"
    manifest, folder = gallery(enabled)
    _STATE.update(manifest=manifest, folder=folder)
    for i, entry in enumerate(config.nav or []):
        if isinstance(entry, dict) and "Gallery" in entry and manifest:
            pages: list[Any] = [{"Overview": "gallery/index.md"}]
            pages += [{m["title"].split(" (")[0]: f"gallery/{c}.md"} for c, m in manifest.items()]
            config.nav[i] = {"Gallery": pages}
    return config


def on_files(files: Any, config: Any) -> Any:
    """Add the generated pages (and the gallery's PNGs) to the site's files."""
    from mkdocs.structure.files import File

    from gearte.io.schema_reference import reference_markdown

    def add(uri: str, content: str | bytes) -> None:
        files.append(File.generated(config, uri, content=content))

    add("reference/case-files.md", reference_markdown())
    for page, (title, intro, names) in API_PAGES.items():
        add(page, api_page(title, intro, names))
    manifest, folder = _STATE["manifest"], _STATE["folder"]
    for uri, text in gallery_pages(manifest).items():
        add(uri, text)
    if manifest:
        for m in manifest.values():
            for f in m["figures"]:
                add(f"gallery/{f['file']}", (folder / f["file"]).read_bytes())
            add(f"gallery/{m['report']}", (folder / m["report"]).read_bytes())
    return files


def on_page_markdown(markdown: str, page: Any, **kwargs: Any) -> str:
    """Fill the generated numbers of a guide page (:func:`generated_markdown`)."""
    return generated_markdown(markdown, page.file.src_uri, _STATE.get("manifest"))


_ROLE = re.compile(r":(?:class|func|mod|data|meth|attr|exc|obj|const):(?=<code)")


def on_page_content(html: str, **kwargs: Any) -> str:
    """Docstrings use Sphinx roles (``:func:`x```); Markdown renders them as ``:func:<code>x
    </code>``: drop the role, keep the code."""
    return _ROLE.sub("", html)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--case"]:  # one case, run by run_gallery in its own process
        name, folder = sys.argv[2], Path(sys.argv[3])
        paper, page = next((p, g) for c, p, g in GALLERY if c == name)
        entry = run_case(name, paper, page, folder)
        (folder / f"{name}.json").write_text(json.dumps(entry), encoding="utf-8")
    else:
        m, where = gallery()
        print(f"gallery cached in {where} ({len(m or {})} cases)")
