"""The layer order of docs/architecture.md, checked on the source: no package imports one above
it, and no import cycle between modules.

Every ``import``/``from ... import`` of every module under ``src/gearte`` is read with ``ast``
(imports inside functions included: a lazy import is still a dependency; imports under
``if TYPE_CHECKING:`` are left out: they exist for annotations only). Run alone with

    .venv/bin/python -m pytest -q tests/test_architecture.py
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gearte"

# Lowest first. A module may import modules of its own layer and of the layers below it.
# Keep in step with docs/architecture.md, "Layers".
LAYERS: list[tuple[str, ...]] = [
    (
        "gearte._version",
        "gearte._blas",
        "gearte._frames",
        "gearte._gc",
        "gearte._jit",
        "gearte.errors",
        "gearte.limits",
        "gearte.units",
        "gearte.labels",
        "gearte.references",
        "gearte.cases",
    ),
    ("gearte.execution",),
    ("gearte.geometry",),
    ("gearte.tolerance",),
    ("gearte.solvers",),
    ("gearte.models",),
    ("gearte.runners",),
    ("gearte.drives",),
    ("gearte.results", "gearte.io"),
    ("gearte.studies", "gearte.families"),
    ("gearte.plotting",),
    ("gearte.report",),
    ("gearte.sweep", "gearte.export"),
    ("gearte.cli", "gearte.__main__", "gearte"),
]


def module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def all_modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(SRC.rglob("*.py"))}


def layer_of(module: str) -> int:
    """Index in LAYERS of the longest prefix that matches ``module``."""
    best, best_len = None, -1
    for i, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > best_len:
                best, best_len = i, len(prefix)
    if best is None:
        raise AssertionError(f"{module} is in no layer of LAYERS (tests/test_architecture.py)")
    return best


def _is_type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"
    )


def imports_of(module: str, path: Path, modules: dict[str, Path]) -> list[tuple[str, int]]:
    """(imported gearte module, line) of every import statement outside TYPE_CHECKING blocks."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_pkg = path.name == "__init__.py"
    out: list[tuple[str, int]] = []

    def resolve(name: str) -> str | None:
        """The deepest existing module that ``name`` (a dotted name) refers to."""
        parts = name.split(".")
        while parts:
            cand = ".".join(parts)
            if cand in modules:
                return cand
            parts.pop()
        return None

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "gearte":
                    target = resolve(alias.name)
                    if target:
                        out.append((target, node.lineno))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_pkg else module.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                parent = ".".join(base + ([node.module] if node.module else []))
            else:
                parent = node.module or ""
            if parent.split(".")[0] == "gearte":
                for alias in node.names:
                    target = resolve(f"{parent}.{alias.name}") or resolve(parent)
                    if target:
                        out.append((target, node.lineno))
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return out


def import_graph() -> dict[str, list[tuple[str, int]]]:
    modules = all_modules()
    return {m: imports_of(m, p, modules) for m, p in modules.items()}


def test_every_module_has_a_layer():
    for module in all_modules():
        layer_of(module)


def test_no_package_imports_one_above_it():
    graph = import_graph()
    upward = []
    for module, targets in graph.items():
        for target, line in targets:
            if layer_of(target) > layer_of(module):
                upward.append(f"{module}:{line} imports {target} (a layer above it)")
    assert not upward, "\n".join(upward)


def find_cycles(graph: dict[str, list[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), or a self-import."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    cycles: list[list[str]] = []
    counter = [0]

    def strongconnect(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, []):
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph.get(v, []):
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            strongconnect(v)
    return cycles


def test_no_import_cycles():
    graph = {m: sorted({t for t, _ in ts if t != m}) for m, ts in import_graph().items()}
    cycles = find_cycles(graph)
    assert not cycles, "import cycles: " + "; ".join(" <-> ".join(c) for c in cycles)


def test_checker_finds_a_planted_upward_import_and_cycle(tmp_path):
    """The checker itself can fail: an upward import and a two-module cycle are reported."""
    assert layer_of("gearte.models.backlash") < layer_of("gearte.studies.planetary")
    assert find_cycles({"a": ["b"], "b": ["a"], "c": ["a"]}) == [["a", "b"]]
    pkg = tmp_path / "gearte" / "models"
    pkg.mkdir(parents=True)
    (pkg / "x.py").write_text("def f():\n    from gearte.studies import run_case\n")
    modules = {"gearte.models.x": pkg / "x.py", "gearte.studies": SRC / "studies/__init__.py"}
    assert imports_of("gearte.models.x", pkg / "x.py", modules) == [("gearte.studies", 2)]


@pytest.mark.parametrize("layer", [p for layer in LAYERS for p in layer])
def test_layers_name_existing_modules(layer):
    assert layer in all_modules(), f"LAYERS names {layer}, which does not exist"


# Hand-written angle/unit conversions that gearte.units provides (docs/architecture.md, "Units").
CONVERSIONS = re.compile(
    r"206264|3437\.7|648000|10800|180(\.0)?\s*/\s*np\.pi|np\.pi\s*/\s*180"
    r"|np\.(degrees|radians|rad2deg|deg2rad)\("
)
# Modules being rewritten in parallel (issue 11 items 2-4) that still convert by hand; the list
# only shrinks (test_unit_conversion_debt_only_shrinks).
CONVERSION_PENDING: set[str] = set()


def _hand_conversions() -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for module, path in all_modules().items():
        if module == "gearte.units":
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#")[0]
            if CONVERSIONS.search(code) and ">>>" not in code:
                out.setdefault(module, []).append(f"{n}: {line.strip()}")
    return out


def test_unit_conversions_only_through_gearte_units():
    found = {m: v for m, v in _hand_conversions().items() if m not in CONVERSION_PENDING}
    assert not found, "\n".join(f"{m}:{line}" for m, lines in found.items() for line in lines)


def test_unit_conversion_debt_only_shrinks():
    clean = (CONVERSION_PENDING & set(all_modules())) - set(_hand_conversions())
    assert not clean, f"remove from CONVERSION_PENDING (no hand conversion left): {clean}"
