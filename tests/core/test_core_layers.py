"""The core's shape: its modules import one another at the top only and in one direction (no cycle), and
its public API is the curated, documented list of docs/api.md."""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

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


#: The deferred imports, by design: the command's entry installs the signal handlers before the command line's
#: imports (about a second), so that a Ctrl-C during them is answered (docs/faults.md); the test models import
#: the conformance suite (which needs pytest) only when it is named, so that the docs' models need no pytest.
ENTRY_IMPORT = "__main__"
KIT_IMPORT = "testing"


def test_core_modules_import_each_other_at_the_top_and_without_a_cycle():
    graph, deferred = core_imports()
    assert {"api", "registry", "provenance", "options", "sources", "model", "semantics"} <= set(graph)
    assert [where for where in deferred if where.split(":")[0] not in (ENTRY_IMPORT, KIT_IMPORT)] == []
    assert len(deferred) == 2 and graph[ENTRY_IMPORT] == {"signals"}
    assert cycles(graph) == []
    # the layers the architecture names: the lowest know nothing of the plugins or of the builder
    for low in ("model", "semantics", "options", "geometry", "schema", "errors"):
        assert not graph[low] & {"api", "registry", "provenance", "builder", "kinds", "sources", "cli"}, (low, graph[low])
    assert "kinds" in graph["sources"] and "sources" not in graph["kinds"]


def _documented(text: str) -> set[str]:
    return set(re.findall(r"^\| `([A-Za-z_][A-Za-z0-9_]*)`", text, re.M))


@pytest.mark.parametrize("namespace", [mf, mfp], ids=["masonryfw", "plugin_api"])
def test_the_two_namespaces_are_the_documented_lists(namespace):
    """docs/api.md lists the user's API, then (after its "For plugin authors" heading) the plugin authors'; each
    list is its namespace's ``__all__``, every name resolves and has its documentation on the page."""
    page = (ROOT / "docs" / "api.md").read_text()
    user, plugin = page.split("# For plugin authors")
    assert set(namespace.__all__) == _documented(user if namespace is mf else plugin)
    assert len(namespace.__all__) == len(set(namespace.__all__))
    assert not set(mf.__all__) & set(mfp.__all__)  # one way to each name
    assert all(hasattr(namespace, name) for name in namespace.__all__)
    assert not [name for name in namespace.__all__ if type(getattr(namespace, name)).__name__ == "module"]
    assert not re.findall(r"^\| `\w+` \|  \|$", page, re.M)  # every row says what its name is


def test_the_page_is_the_one_the_script_writes():
    from importlib.util import module_from_spec, spec_from_file_location

    spec = spec_from_file_location("api_page", ROOT / "docs" / "scripts" / "api_page.py")
    script = module_from_spec(spec)
    spec.loader.exec_module(script)
    assert script.page() == (ROOT / "docs" / "api.md").read_text()


def test_the_role_codes_are_read_in_one_place():
    """Every mask of block roles is asked of ``masonryfw.roles`` (the codes were rewritten in 13 places)."""
    readers = [f"{path.relative_to(ROOT)}" for path in [*CORE.glob("*.py"), *(ROOT / "plugins").rglob("*.py")]
               if path.name != "roles.py" and re.search(r'flags\("block_role"\)', path.read_text())]
    assert readers == []


#: The benchmarks that time a plugin's own kernels apart (its assembly, its element forces, its return map): they
#: may import that plugin's modules, as its tests do.
KERNEL_BENCHMARKS = {"bench_la.py": "masonryfw_la", "bench_fdem.py": "masonryfw_fdem", "bench_jmm.py": "masonryfw_jmm"}


def test_packages_import_only_each_others_public_namespaces():
    """A plugin, a benchmark or a docs script imports ``masonryfw``, ``masonryfw.plugin_api`` (and the conformance
    kit, and the bundled drawings' generator), and of another plugin only its public names, never a core module
    or another plugin's inside (compare's LTSM chart took six private names of the assessment module;
    benchmarks took plugin internals and the drawing reader)."""
    allowed = {"masonryfw", "masonryfw.plugin_api", "masonryfw.testing", "masonryfw.datasets.drawings"}
    found = []
    for folder in ("plugins", "benchmarks", "docs/scripts"):
        for path in (ROOT / folder).rglob("*.py"):
            own = path.relative_to(ROOT).parts[1] if folder == "plugins" else KERNEL_BENCHMARKS.get(path.name)
            for node in ast.walk(ast.parse(path.read_text())):
                names = [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 else \
                    [a.name for a in node.names] if isinstance(node, ast.Import) else []
                for name in filter(None, names):
                    top = name.split(".")[0]
                    if top == "masonryfw" and name not in allowed:
                        found.append(f"{path.relative_to(ROOT)}: {name}")
                    elif top.startswith("masonryfw_") and top != own and name != top:
                        found.append(f"{path.relative_to(ROOT)}: {name}")
    assert found == []


def test_the_models_of_the_docs_are_read_without_pytest(tmp_path):
    """``masonryfw.testing`` (the arch and the corner building the docs use) imports without pytest; only the
    conformance suite needs it, and is imported when it is named."""
    import subprocess
    import sys

    script = ("import sys\nsys.modules['pytest'] = None  # no pytest: importing it fails\n"
              "import masonryfw.testing as mt\n"
              "print(mt.corner_building().sizes['block'], mt.arch_model(0.15).sizes['block'])\n"
              "try:\n    mt.SolverConformance\nexcept ImportError:\n    print('the kit needs pytest')\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    sizes, kit = done.stdout.splitlines()
    assert all(int(n) > 10 for n in sizes.split()) and kit == "the kit needs pytest"
