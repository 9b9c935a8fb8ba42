"""The core's shape: its modules import one another at the top only and in one direction (no cycle), and
its public API is the curated, documented list of docs/api.md."""
from __future__ import annotations

import ast
import inspect
import re
import subprocess
import sys
from pathlib import Path

import masonryfw as mf

CORE = Path(mf.__file__).resolve().parent
ROOT = Path(__file__).resolve().parents[2]


def core_imports() -> tuple[dict[str, set[str]], list[str]]:
    """Per core module, the core modules it imports at module level; and every import of a core module made
    inside a function (``module:line``)."""
    modules = {p.stem for p in CORE.glob("*.py")} | {"datasets"}
    graph, deferred = {}, []
    for path in sorted(CORE.glob("*.py")):
        tree = ast.parse(path.read_text())
        top = set()
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom) or node.level == 0 and not (node.module or "").startswith("masonryfw"):
                continue
            name = (node.module or "").removeprefix("masonryfw").lstrip(".").split(".")[0]
            targets = {name} if name else {alias.name for alias in node.names}
            targets &= modules
            if not targets:
                continue
            if any(node in ast.walk(f) for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))):
                deferred.append(f"{path.stem}:{node.lineno}")
            else:
                top |= targets
        graph[path.stem] = top - {path.stem}
    return graph, deferred


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    found, state = [], {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                found.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    return found


#: The one deferred import, by design: the command's entry installs the signal handlers before the command line's
#: imports (about a second), so that a Ctrl-C during them is answered (docs/faults.md).
ENTRY_IMPORT = "__main__"


def test_core_modules_import_each_other_at_the_top_and_without_a_cycle():
    graph, deferred = core_imports()
    assert {"api", "registry", "provenance", "options", "sources", "model", "semantics"} <= set(graph)
    assert [where for where in deferred if where.split(":")[0] != ENTRY_IMPORT] == []
    assert len(deferred) == 1 and graph[ENTRY_IMPORT] == {"signals"}
    assert cycles(graph) == []
    # the layers the architecture names: the lowest know nothing of the plugins or of the builder
    for low in ("model", "semantics", "options", "geometry", "schema", "errors"):
        assert not graph[low] & {"api", "registry", "provenance", "builder", "sources", "cli"}, (low, graph[low])
    assert "builder" in graph["sources"] and "sources" not in graph["builder"]


def test_the_public_api_is_the_documented_list():
    documented = set(re.findall(r"^\| `([A-Za-z_][A-Za-z0-9_]*)`", (ROOT / "docs" / "api.md").read_text(), re.M))
    assert set(mf.__all__) == documented
    assert len(mf.__all__) == len(set(mf.__all__))
    assert all(hasattr(mf, name) for name in mf.__all__)
    assert not [name for name in mf.__all__ if type(getattr(mf, name)).__name__ == "module"]
    undocumented = [name for name in mf.__all__ if (inspect.isfunction(getattr(mf, name)) or inspect.isclass(
        getattr(mf, name))) and not getattr(mf, name).__doc__]
    assert undocumented == []


def test_the_lazy_api_is_the_stub_and_import_loads_no_science():
    """``import masonryfw`` resolves names on first use from ``__init__.pyi``: the stub's ``__all__`` is the
    runtime one, every name comes from the module the stub says, and a fresh interpreter that imports the
    package and lists the plugins has loaded no xarray, SciPy, numba or matplotlib (NumPy it may: the
    comparator's default threshold is the core's constant)."""
    stub = ast.parse((CORE / "__init__.pyi").read_text())
    declared = next(node.value for node in stub.body if isinstance(node, ast.Assign)
                    and node.targets[0].id == "__all__")
    assert sorted(ast.literal_eval(declared)) == sorted(mf.__all__)
    sources = {alias.asname or alias.name: node.module for node in stub.body if isinstance(node, ast.ImportFrom)
               for alias in node.names}
    assert set(sources) == set(mf.__all__)
    for name, module in sources.items():
        assert getattr(mf, name) is getattr(__import__(f"masonryfw.{module}", fromlist=[name]), name), name
    probe = ("import sys, masonryfw\nfrom masonryfw.registry import installed_plugins\ninstalled_plugins()\n"
             "print(sorted({'xarray', 'scipy', 'numba', 'matplotlib', 'dask'} & set(sys.modules)))")
    loaded = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "[]"
