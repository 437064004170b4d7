"""gearte gets its speed through the libraries' supported mechanisms: no stand-in modules and
no patches of other packages' attributes (the project's style, "Speed through supported doors").

Every module under ``src/gearte`` is read with ``ast`` and these fail the test:

* a module object made by hand (``types.ModuleType(...)``, ``ModuleType(...)``) — a fake;
* an entry written into ``sys.modules`` (``sys.modules[name] = m``, ``.update``,
  ``.setdefault``, ``.__setitem__``), except the module that ``importlib.util.module_from_spec``
  made from its own file in the same function (the importlib documentation's recipe for
  importing a file directly: the real module, not a stand-in);
* an attribute assigned (``=``, ``+=``, ``del``) on a name that was imported from another
  package (``matplotlib.artist.kwdoc = ...``, ``RendererAgg._x = ...``), or ``setattr`` /
  ``delattr`` on one, or ``setattr`` with a private attribute name (``"_..."``) on anything.

The checker is tested on planted examples, so it can fail.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gearte"


def _foreign_names(tree: ast.AST) -> set[str]:
    """Names bound in the module by importing another package (``import x.y`` binds ``x``)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] != "gearte":
                    names.add(alias.asname or alias.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom) and not node.level:
            if (node.module or "").split(".")[0] != "gearte":
                names.update(alias.asname or alias.name for alias in node.names)
    return names


def _root(node: ast.AST) -> str | None:
    while isinstance(node, ast.Attribute | ast.Subscript | ast.Call):
        node = node.func if isinstance(node, ast.Call) else node.value
    return node.id if isinstance(node, ast.Name) else None


def _is_sys_modules(node: ast.AST) -> bool:
    return (
        isinstance(node, ast.Attribute)
        and node.attr == "modules"
        and isinstance(node.value, ast.Name)
        and node.value.id == "sys"
    )


def _from_spec_names(func: ast.AST) -> set[str]:
    """Names assigned ``importlib.util.module_from_spec(...)`` (or ``module_from_spec(...)``)
    inside ``func``."""
    out: set[str] = set()
    for node in ast.walk(func):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
            f = node.value.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if name == "module_from_spec":
                out.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return out


#: Attributes the standard library documents as meant to be replaced by a program (not patches):
#: "threading.excepthook() can be overridden to control how uncaught exceptions raised by
#: Thread.run() are handled" (Python docs, threading); sys.excepthook likewise.
DOCUMENTED_HOOKS = frozenset({"threading.excepthook", "sys.excepthook"})


def findings(source: str, filename: str = "<planted>") -> list[str]:
    """What the test forbids in ``source``: one ``file:line: what`` entry per finding."""
    tree = ast.parse(source, filename)
    foreign = _foreign_names(tree)
    out: list[str] = []

    def report(node: ast.AST, what: str) -> None:
        out.append(f"{filename}:{getattr(node, 'lineno', 0)}: {what}")

    scopes = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]
    real: dict[int, set[str]] = {}  # id(node) -> module_from_spec names of its function
    for func in scopes:
        names = _from_spec_names(func)
        for node in ast.walk(func):
            real.setdefault(id(node), set()).update(names)

    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            fname = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if fname == "ModuleType":
                report(node, "a module object made by hand (a stand-in module)")
            if isinstance(f, ast.Attribute) and _is_sys_modules(f.value):
                if f.attr in ("update", "setdefault", "__setitem__"):
                    report(node, f"sys.modules.{f.attr}(...): a module put in by hand")
            if fname in ("setattr", "delattr") and len(node.args) >= 2:
                target, attr = node.args[0], node.args[1]
                private = isinstance(attr, ast.Constant) and str(attr.value).startswith("_")
                if _root(target) in foreign or private:
                    report(node, f"{fname} on another package's object or a private attribute")
        targets: list[ast.AST] = []
        if isinstance(node, ast.Assign):
            targets = list(node.targets)
        elif isinstance(node, ast.AugAssign | ast.AnnAssign):
            targets = [node.target]
        elif isinstance(node, ast.Delete):
            targets = list(node.targets)
        for t in targets:
            for sub in ast.walk(t):
                if isinstance(sub, ast.Subscript) and _is_sys_modules(sub.value):
                    value = getattr(node, "value", None)
                    ok = (
                        isinstance(node, ast.Assign)
                        and isinstance(value, ast.Name)
                        and value.id in real.get(id(node), set())
                    )
                    if not ok and not isinstance(node, ast.Delete):
                        report(node, "sys.modules[...] = a module that is not its file's own")
                elif (
                    isinstance(sub, ast.Attribute)
                    and sub is t
                    and _root(sub) in foreign
                    and ast.unparse(sub) not in DOCUMENTED_HOOKS
                ):
                    report(node, f"attribute {ast.unparse(sub)} of another package assigned")
    return out


def test_no_stand_in_modules_or_patched_attributes():
    found = [
        f
        for path in sorted(SRC.rglob("*.py"))
        for f in findings(path.read_text(encoding="utf-8"), str(path.relative_to(SRC.parent)))
    ]
    assert not found, "\n".join(found)


def test_checker_finds_planted_fakes_and_patches():
    planted = """
import sys
import types
import matplotlib.artist
from matplotlib.backends.backend_agg import RendererAgg as R

def fake():
    m = types.ModuleType("numba")
    sys.modules["numba"] = m

def patch():
    matplotlib.artist.kwdoc = lambda a: ""
    R._get_font_height_metrics = len
    setattr(matplotlib.artist.Artist, "_update_set_signature_and_docstring", None)
    sys.modules.setdefault("x", None)

def fine(obj, spec):
    import importlib.util
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    obj.value = 1
    obj.flags.writeable = False
"""
    found = findings(planted)
    lines = sorted(int(f.split(":")[1]) for f in found)
    assert lines == [8, 9, 12, 13, 14, 15], found
