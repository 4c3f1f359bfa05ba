"""How the modules of sklearn_crbm.datasets depend on each other."""

import ast
import graphlib
from pathlib import Path

import sklearn_crbm.datasets

FOLDER = Path(sklearn_crbm.datasets.__file__).parent


def _imports(path):
    """``(module-level, inside functions)`` sibling modules imported by a file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = {n.module for n in tree.body if isinstance(n, ast.ImportFrom) and n.level}
    nested = {
        n.module
        for n in ast.walk(tree)
        if isinstance(n, ast.ImportFrom) and n.level == 1 and n.module
    }
    return top, nested - top


def test_the_modules_import_each_other_without_a_cycle():
    graph = {}
    for path in FOLDER.glob("*.py"):
        top, nested = _imports(path)
        assert not nested, f"{path.name} imports {nested} inside a function"
        graph[path.stem] = {m for m in top if m}
    order = list(graphlib.TopologicalSorter(graph).static_order())  # CycleError
    # the skeleton parsers know bones, not the Skeleton class that calls them
    for parser in ("_asf", "_bvh_hierarchy", "_mit"):
        assert order.index(parser) < order.index("_skeleton")
        assert "_skeleton" not in graph[parser]
