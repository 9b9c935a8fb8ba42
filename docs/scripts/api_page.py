"""Write docs/api.md: the user's API (``masonryfw``, grouped as ``__init__.pyi`` groups ``__all__``) and the plugin
authors' (``masonryfw.plugin_api``, grouped by the module each name comes from), a row a name with the first
paragraph of its docstring. Run from the project root: ``python docs/scripts/api_page.py``; a test keeps the
page and the two namespaces the same lists."""
from __future__ import annotations

import argparse
import ast
import importlib
import inspect
from pathlib import Path

import masonryfw as mf
import masonryfw.plugin_api as mfp

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "api.md"
HEAD = """# The public API

Two namespaces, each imported on first use (``import masonryfw`` costs milliseconds):

- `import masonryfw as mf`: the user's API. Build or read a wall, solve it, compare and draw results, read
  what they mean. Scripts and notebooks need nothing else.
- `import masonryfw.plugin_api as mfp`: what a plugin shares with the core, for plugin authors: the records
  and hooks of the contract, options, progress, the geometry of the ragged polygon layout, the role masks,
  the fields every solver's result derives the same way, files written atomically and read safely, text
  tables. Plugins import only these two namespaces; the modules behind them are not an API and may move.

Each row is the name's own docstring's first paragraph; `help(mf.<name>)` gives the rest. A test keeps this
page and the two `__all__` lists the same (`docs/scripts/api_page.py` writes it). A plugin is a package with
an entry point in the group `masonryfw` whose hooks return records (`Solver`, `Comparator`, `Plotter`, click
commands); see docs/architecture.md and the conformance kit (`masonryfw.testing`, README "Writing a solver
plugin").
"""


def first_paragraph(obj) -> str:
    """A function's or class's docstring (a cached function's too), not the docstring of a value's type."""
    own = inspect.isfunction(obj) or inspect.isclass(obj) or (callable(obj) and obj.__doc__ != type(obj).__doc__)
    doc = inspect.getdoc(obj) if own else None
    text = (doc or "").split("\n\n")[0]
    return " ".join(text.split()).replace("|", "\\|")


def constant_comment(module: str, name: str) -> str:
    """The ``#:`` comment above a module constant (its documentation), or its value's kind."""
    where = importlib.import_module(f"masonryfw.{module}")
    if name == "__version__":
        return " ".join((inspect.getdoc(where) or "").split())
    source = Path(inspect.getsourcefile(where)).read_text().splitlines()
    for number, line in enumerate(source):
        if line.startswith(f"{name} =") or line.startswith(f"{name}:"):
            comments = []
            k = number - 1
            while k >= 0 and source[k].startswith("#:"):
                comments.insert(0, source[k][2:].strip())
                k -= 1
            if comments:
                return " ".join(comments).replace("|", "\\|")
    return ""


def row(namespace, name: str, module: str) -> str:
    obj = getattr(namespace, name)
    text = first_paragraph(obj) or constant_comment(module, name)
    return f"| `{name}` | {text} |"


def user_groups() -> list[tuple[str, list[str]]]:
    """``__all__`` of ``__init__.pyi`` in its commented groups."""
    stub = (ROOT / "core" / "masonryfw" / "__init__.pyi").read_text()
    lines = stub[stub.index("__all__"):].splitlines()[1:]
    groups: list[tuple[str, list[str]]] = []
    for line in lines:
        line = line.strip()
        if line.startswith("#"):
            groups.append((line.lstrip("# "), []))
        elif line.startswith('"'):
            groups[-1][1].extend(ast.literal_eval(f"[{line}]"))
    return groups


def user_modules() -> dict[str, str]:
    tree = ast.parse((ROOT / "core" / "masonryfw" / "__init__.pyi").read_text())
    return {alias.asname or alias.name: node.module for node in tree.body if isinstance(node, ast.ImportFrom)
            for alias in node.names}


def plugin_groups() -> list[tuple[str, str, list[str]]]:
    """``(module, its docstring's first sentence, names)`` of every module ``plugin_api`` takes names from."""
    tree = ast.parse((ROOT / "core" / "masonryfw" / "plugin_api.pyi").read_text())
    mapping = {node.module: [alias.name for alias in node.names] for node in tree.body
               if isinstance(node, ast.ImportFrom)}
    out = []
    for module, names in mapping.items():
        doc = inspect.getdoc(importlib.import_module(f"masonryfw.{module}")) or ""
        out.append((module, " ".join(doc.split("\n\n")[0].split()), sorted(names)))
    return out


def page() -> str:
    modules = user_modules()
    parts = [HEAD]
    for title, names in user_groups():
        parts += [f"\n## {title}\n", "| name | what it is |", "|---|---|",
                  *(row(mf, name, modules[name]) for name in names)]
    parts.append("\n# For plugin authors: `masonryfw.plugin_api`\n")
    for module, doc, names in plugin_groups():
        parts += [f"\n## From `{module}`\n", doc, "", "| name | what it is |", "|---|---|",
                  *(row(mfp, name, module) for name in names)]
    return "\n".join(parts) + "\n"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=PAGE)
    args = parser.parse_args(argv)
    args.out.write_text(page())
    print(args.out)


if __name__ == "__main__":
    main()
