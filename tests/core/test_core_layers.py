"""The core's shape: its modules import one another at the top only and in one direction (no cycle), and
its public API is the curated, documented list of docs/api.md."""
from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp

CORE = Path(mf.__file__).resolve().parent
ROOT = Path(__file__).resolve().parents[2]


#: Core's rooms, lowest first: a module imports only from its own room and the rooms below it (the top modules,
#: ``api``, ``cli``, ``plugin_api``, ``testing`` and their helpers, from any room).
ROOMS = ("runtime", "geometry", "format", "readers", "ground", "builders", "results", "contract")


#: What an installed ``masonryfw`` holds beside core's code: the bundled cases and the schemas (data packages).
DATA_PACKAGES = ("datasets", "schemas")


def core_files() -> list[Path]:
    """Core's ``.py`` files (not its ``__init__``s), in the source tree or installed, without the data packages."""
    return [p for p in sorted(CORE.rglob("*.py")) if p.name != "__init__.py"
            and p.relative_to(CORE).parts[0] not in DATA_PACKAGES]


def module_name(path: Path) -> str:
    """``room.module`` of a core file, or ``module`` for a top one."""
    return ".".join(path.relative_to(CORE).with_suffix("").parts)


def imported_modules(node: ast.ImportFrom, here: str, modules: set[str]) -> set[str]:
    """The core modules (``room.module``) a ``from ... import`` in the module ``here`` names."""
    if node.level == 0:
        if not (node.module or "").startswith("masonryfw"):
            return set()
        base = (node.module or "").removeprefix("masonryfw").lstrip(".")
    else:
        package = here.split(".")[:-1]
        package = package[:len(package) - (node.level - 1)] if node.level > 1 else package
        base = ".".join([*package, *filter(None, [node.module])])
    candidates = {base} if base in modules else {f"{base}.{a.name}".lstrip(".") for a in node.names}
    return candidates & modules or ({base.split(".")[0]} & {"datasets"})


def core_imports() -> tuple[dict[str, set[str]], list[str]]:
    """Per core module (``room.module``), the core modules it imports at module level; and every import of a core
    module made inside a function (``module:line``)."""
    paths = core_files()
    modules = {module_name(p) for p in paths} | {"datasets"}
    graph, deferred = {}, []
    for path in paths:
        here = module_name(path)
        tree = ast.parse(path.read_text())
        functions = [f for f in ast.walk(tree) if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))]
        top = set()
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom):
                continue
            targets = imported_modules(node, here, modules)
            if not targets:
                continue
            if any(node in ast.walk(f) for f in functions):
                deferred.append(f"{here}:{node.lineno}")
            else:
                top |= targets
        graph[here] = top - {here}
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
    assert {"api", "contract.registry", "contract.provenance", "contract.options", "builders.sources",
            "format.model", "results.semantics"} <= set(graph)
    assert [where for where in deferred if where.split(":")[0] not in (ENTRY_IMPORT, KIT_IMPORT)] == []
    assert len(deferred) == 2 and graph[ENTRY_IMPORT] == {"runtime.signals"}
    assert cycles(graph) == []


def test_every_core_module_lives_in_a_room_and_imports_only_downward():
    """Core is laid out in rooms along the data path (docs/architecture.md); a room imports from itself and the
    rooms below it, never above, and the top modules only are above every room."""
    graph, _ = core_imports()
    upward = []
    for module, targets in graph.items():
        if "." not in module:  # a top module: api, cli, plugin_api, testing, ...
            continue
        room = module.split(".")[0]
        assert room in ROOMS, f"{module}: not in one of core's rooms {ROOMS}"
        for target in targets:
            if target == "datasets":
                continue
            if "." not in target or ROOMS.index(target.split(".")[0]) > ROOMS.index(room):
                upward.append(f"{module} -> {target}")
    assert upward == []
    rooms = {p.parent.name for p in core_files() if p.parent != CORE}
    assert rooms == set(ROOMS)


def test_every_room_says_what_it_holds_and_is_in_the_wheel():
    """Each room's ``__init__`` says what it holds and how data passes through it; the package list of
    pyproject.toml names every room (a wheel without one could not be imported)."""
    import tomllib

    packages = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    for room in ROOMS:
        assert f"masonryfw.{room}" in packages
        doc = ast.get_docstring(ast.parse((CORE / room / "__init__.py").read_text())) or ""
        assert len(doc.split()) >= 25, f"{room}/__init__.py: say what the room holds and how data passes through it"


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
    """Every mask of block roles is asked of ``masonryfw.format.roles`` (the codes were rewritten in 13 places)."""
    readers = [f"{path.relative_to(ROOT)}" for path in [*CORE.rglob("*.py"), *(ROOT / "plugins").rglob("*.py")]
               if path.name != "roles.py" and re.search(r'flags\("block_role"\)', path.read_text())]
    assert readers == []
    compared = [f"{path.relative_to(ROOT)}" for path in [*CORE.rglob("*.py"), *(ROOT / "plugins").rglob("*.py")]
                if path.name != "roles.py" and re.search(r'[=!]= *(mfp\.)?ROLE\["\w+_support|ROLE\["\w+_support"\] *[=!]=', path.read_text())]
    assert compared == []  # a mask of a role is asked (moving_blocks, fixed_blocks), not compared to its code


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


@pytest.mark.parametrize("namespace", [mf, mfp], ids=["masonryfw", "plugin_api"])
def test_each_namespace_stub_names_where_each_name_lives(namespace):
    """``__init__.pyi`` and ``plugin_api.pyi`` are the lazy tables themselves (``lazy_loader.attach_stub``): every
    name they import is the object of the module they name, and ``__all__`` is their names, so a type checker, an
    IDE or a reader following a name lands where it is defined."""
    import importlib

    stub = Path(namespace.__file__).with_suffix(".pyi")
    imports = [node for node in ast.parse(stub.read_text()).body if isinstance(node, ast.ImportFrom)]
    named = {alias.name: node.module for node in imports for alias in node.names}
    assert set(named) == set(namespace.__all__)
    for name, module in named.items():
        assert getattr(namespace, name) is getattr(importlib.import_module(f"masonryfw.{module}"), name), name


def test_the_architecture_page_maps_the_house_as_it_is():
    """docs/architecture.md's rooms table lists every core module in its room, and its name counts are the code's."""
    page = (ROOT / "docs" / "architecture.md").read_text()
    for room in ROOMS:
        row = re.search(rf"^\| `{room}/` \|[^|]*\| (.*) \|$", page, re.M)
        assert row, room
        listed = set(re.findall(r"`(\w+)`", row.group(1)))
        assert listed == {p.stem for p in (CORE / room).glob("*.py")} - {"__init__"}, room
    assert f"({len(mf.__all__)} names)" in page and f"{len(mfp.__all__)} names" in page


#: A Sphinx-style cross-reference to a name of the house: ``:func:`masonryfw.plugin_api.next_node``` and the like.
CROSS_REFERENCE = re.compile(r":(?:mod|func|class|data|attr|meth|exc):`~?(masonryfw[\w.]*)`")


def resolves(dotted: str) -> bool:
    """Whether ``dotted`` names a module, or an attribute path from the longest module it starts with."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            target: object = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(target, name):
                return False
            target = getattr(target, name)
        return True
    return False


def test_every_cross_reference_in_core_and_the_plugins_names_what_exists():
    """A docstring that sends the reader to ``masonryfw.x`` sends them somewhere: after a move into rooms or a
    rename, twelve did not (``masonryfw.outline_walls``, plugin names cited on the user's face)."""
    files = [*sorted(p for p in CORE.rglob("*.py*") if p.suffix in (".py", ".pyi")
                     and p.relative_to(CORE).parts[0] not in DATA_PACKAGES),
             *sorted(p for p in (ROOT / "plugins").rglob("*.py") if "site-packages" not in p.parts)]
    stale = [f"{path.name}:{text[:match.start()].count(chr(10)) + 1}: {match.group(1)}"
             for path in files for text in [path.read_text()] for match in CROSS_REFERENCE.finditer(text)
             if not resolves(match.group(1))]
    assert len(files) > 100
    assert not stale, stale
