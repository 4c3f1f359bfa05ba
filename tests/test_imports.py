"""The package's imports form no loop: the structure can be drawn floor by floor.

Every import of a module of the package, at the top of a module or inside a
function, is an arrow from the importing module to the imported one and to
the packages above it that Python runs first (the importer's own packages
aside, which are already being run).  An arrow that closes a loop goes up a
floor; there must be none.
"""

import ast
from pathlib import Path

import sklearn_crbm

PACKAGE = Path(sklearn_crbm.__file__).resolve().parent
ROOT = PACKAGE.name


def _module_names():
    names = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts.pop()
        names[".".join(parts)] = (path, is_package)
    return names


def _ancestors(name):
    parts = name.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def import_graph():
    """``{module: set of the package's modules it makes Python run}``."""
    modules = _module_names()
    graph = {}
    for name, (path, is_package) in modules.items():
        package = name if is_package else name.rpartition(".")[0]
        named, implied = set(), set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                named.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")
                    base = base[: len(base) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module
                for alias in node.names:
                    submodule = f"{source}.{alias.name}"
                    # a submodule runs its package first; a name comes from it
                    named.add(submodule if submodule in modules else source)
        named &= set(modules)
        for target in named:
            implied |= _ancestors(target)
        graph[name] = (named | (implied - _ancestors(name))) - {name}
    return graph


def find_loop(graph):
    """One loop of ``graph`` as a list of modules, or None."""
    state = {}

    def visit(node, path):
        state[node] = "open"
        path.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == "open":
                return path[path.index(target) :] + [target]
            if target not in state:
                loop = visit(target, path)
                if loop:
                    return loop
        state[node] = "done"
        path.pop()
        return None

    for node in sorted(graph):
        if node not in state:
            loop = visit(node, [])
            if loop:
                return loop
    return None


def test_graph_sees_the_package():
    graph = import_graph()
    assert f"{ROOT}.utils._sequences" in graph
    assert f"{ROOT}.utils._sequences" in graph[f"{ROOT}.metrics._generation"]


def test_find_loop_finds_a_loop():
    assert find_loop({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_loop({"a": {"b"}, "b": set()}) is None


def test_no_import_goes_up_a_floor():
    loop = find_loop(import_graph())
    assert loop is None, "imports loop: " + " -> ".join(loop)
