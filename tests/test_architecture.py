"""The package's import graph: no cycles inside motion_core, and dependencies run one way
through its layers (docs/architecture.md). Lazy imports inside functions count too: a
cycle that only closes at call time is still a cycle."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "motion_core"

# a subpackage may import its own modules and those of lower layers, never a higher one
LAYERS = {
    "body": 0,
    "nn": 0,
    "models": 1,
    "verify": 1,
    "inference": 2,
    "formats": 3,
    "data": 3,
    "corpus": 4,
    "eval": 4,
    "train": 5,
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


@functools.cache
def import_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """module -> the package's modules it imports (at module level or inside functions)."""
    files = {_module_name(p): p for p in sorted(package.rglob("*.py"))}
    graph: dict[str, set[str]] = {}
    for name, path in files.items():
        is_pkg = path.name == "__init__.py"
        here = name.split(".") if is_pkg else name.split(".")[:-1]
        deps: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = here[: len(here) - (node.level - 1)]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                targets = [mod] + [f"{mod}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            for t in targets:
                # "from .x import y": y may be a module or a name in x; take the module that exists
                while t and t not in files:
                    t = t.rpartition(".")[0]
                if t and t != name and t.split(".")[0] == package.name:
                    deps.add(t)
        graph[name] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle as a list of modules (first == last), or None."""
    state: dict[str, int] = {}  # 1: on the stack, 2: done
    stack: list[str] = []

    def visit(n: str) -> list[str] | None:
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                return [*stack[stack.index(m) :], m]
            if m not in state and (found := visit(m)):
                return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(graph):
        if n not in state and (found := visit(n)):
            return found
    return None


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in LAYERS else None


def test_the_graph_sees_lazy_imports():
    graph = import_graph()
    # generate() is reached through a function-level import in motion_core/__init__.py
    assert "motion_core.inference.generation" in graph["motion_core"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_motion_core_has_no_import_cycle():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_every_subpackage_has_a_layer():
    subpackages = {p.parent.name for p in PACKAGE.glob("*/__init__.py")}
    assert subpackages == set(LAYERS), "give a new subpackage its layer in LAYERS and docs/architecture.md"
    assert {p.name for p in PACKAGE.glob("*.py")} == {"__init__.py"}, "modules belong in a layer"


@pytest.mark.parametrize("module", sorted(m for m in import_graph() if _layer(m)))
def test_imports_go_down_the_layers(module):
    mine = LAYERS[_layer(module)]
    up = [d for d in import_graph()[module] if _layer(d) and LAYERS[_layer(d)] > mine]
    assert not up, f"{module} (layer {mine}) imports a higher layer: {up}"


def test_the_core_never_imports_the_app():
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        names = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
        names += [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and not n.level]
        assert not [n for n in names if n.split(".")[0] in ("app", "gradio")], path
