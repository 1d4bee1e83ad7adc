"""The import graph of the packages has no circle and the low layers import no higher one.

Imports are read from the source with ``ast`` (module level and inside functions alike: an
import deferred into a function is still a dependency), so the test needs no optional extra.
Imports under ``if TYPE_CHECKING:`` count too: a module written against another module's types
depends on it as much as one that loads it (the loop written against the environment's config
was such a circle, issue 29).
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: Installed package name -> its folder in the repository (pyproject's package-dir mapping: the
#: folders agents/ and experiments/ install as encctl_gym.agents and encctl_gym.experiments).
PACKAGES = {"encctl_gym": "encctl_gym", "encctl_gym.agents": "agents", "encctl_gym.experiments": "experiments"}
#: The library: every module of encctl_gym outside the two applications.
APPLICATIONS = ("encctl_gym.agents", "encctl_gym.experiments")


def module_files(packages: Mapping[str, str] = PACKAGES) -> dict[str, Path]:
    """Dotted module name -> source file, for every module of ``packages`` (a package is its
    ``__init__``)."""
    modules: dict[str, Path] = {}
    for package, folder in packages.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = [package, *path.relative_to(ROOT / folder).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            name = ".".join(parts)
            if package == "encctl_gym" and any(name == app or name.startswith(app + ".") for app in APPLICATIONS):
                continue  # not a folder of the tree (the applications live at its top)
            modules[name] = path
    return modules


def _known(name: str, modules: Mapping[str, Path]) -> str | None:
    """The longest prefix of ``name`` that is one of ``modules`` (``a.b.func`` -> ``a.b``)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(module: str, source: str, modules: Mapping[str, Path], *, is_package: bool = False) -> set[str]:
    """The modules of ``modules`` that ``source`` (the text of ``module``) imports."""
    package = module if is_package else module.rpartition(".")[0]
    found: set[str] = set()
    for node in _runtime_nodes(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                stem = ".".join(base + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            # `from pkg import sub` imports the submodule; `from pkg.mod import name` the module
            targets = [f"{stem}.{alias.name}" if f"{stem}.{alias.name}" in modules else stem for alias in node.names]
        else:
            continue
        for target in targets:
            hit = _known(target, modules)
            if hit is not None and hit != module:
                found.add(hit)
    return found


def _runtime_nodes(tree: ast.AST) -> Iterable[ast.AST]:
    """Every node of ``tree``, the bodies of ``if TYPE_CHECKING:`` included (a type-only
    import is a dependency)."""
    return ast.walk(tree)


def import_graph(packages: Mapping[str, str] = PACKAGES) -> dict[str, set[str]]:
    """Module -> the package modules it imports."""
    modules = module_files(packages)
    return {
        name: imports_of(name, path.read_text(encoding="utf-8"), modules, is_package=path.name == "__init__.py")
        for name, path in modules.items()
    }


def cycles(graph: Mapping[str, Iterable[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (each a circle of imports),
    by Tarjan's algorithm (iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph.get(root, ())))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(graph.get(child, ()))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


# ----------------------------------------------------------------------------- the checker itself
def test_the_cycle_finder_finds_circles_and_only_circles() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a", "e"}, "e": set(), "f": {"f"}}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    assert sorted(cycles({"x": {"y"}, "y": {"x"}, "p": {"q"}, "q": {"p", "x"}})) == [["p", "q"], ["x", "y"]]


def test_imports_are_read_from_every_form_of_import_statement() -> None:
    modules = {name: Path(name) for name in ("pkg", "pkg.a", "pkg.b", "pkg.sub", "pkg.sub.c")}
    source = (
        "import pkg.a\n"
        "from . import b\n"
        "from .sub.c import thing\n"
        "def later():\n"
        "    from .. import a\n"  # from pkg.sub.c: up to pkg
        "import numpy\n"
    )
    assert imports_of("pkg.sub.c", source.replace("from .sub.c import thing\n", ""), modules) == {"pkg.a", "pkg.sub"}
    assert imports_of("pkg", "from .sub.c import thing\nfrom .a import f\n", modules, is_package=True) == {"pkg.sub.c", "pkg.a"}
    assert imports_of("pkg.b", "def f():\n    from .a import g\n", modules) == {"pkg.a"}
    typed = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .a import T\n"
    assert imports_of("pkg.b", typed, modules) == {"pkg.a"}  # a type-only import is a dependency


# ----------------------------------------------------------------------------- the packages
def test_the_packages_have_no_import_circle() -> None:
    graph = import_graph()
    assert len(graph) > 100  # the walk found the packages
    found = cycles(graph)
    detail = [" <-> ".join(c) + ": " + "; ".join(f"{a} -> {b}" for a in c for b in sorted(graph[a]) if b in c) for c in found]
    assert not found, "import circles:\n" + "\n".join(detail)


#: Lower layers and the layers they must not import (STYLE: layers import downward only; the
#: security analysis is pure mathematics beside the cryptography).
FORBIDDEN = {
    "encctl_gym.crypto": (
        "encctl_gym.attacks",
        "encctl_gym.cryptanalysis",
        "encctl_gym.loop",
        "encctl_gym.envs",
        "encctl_gym.security",
    ),
    "encctl_gym.security": (
        "encctl_gym.crypto",
        "encctl_gym.attacks",
        "encctl_gym.cryptanalysis",
        "encctl_gym.loop",
        "encctl_gym.envs",
    ),
    "encctl_gym.ident": ("encctl_gym.crypto", "encctl_gym.loop", "encctl_gym.envs", "encctl_gym.sim"),
    "encctl_gym.loop": ("encctl_gym.envs", "encctl_gym.multiagent"),  # the loop takes its own LoopSpec (issue 29)
    "encctl_gym": APPLICATIONS,
    "encctl_gym.agents": ("encctl_gym.experiments",),
}


@pytest.mark.parametrize("layer", sorted(FORBIDDEN))
def test_no_layer_imports_a_higher_one(layer: str) -> None:
    graph = import_graph()
    upward = sorted(
        f"{module} -> {target}"
        for module, targets in graph.items()
        if (module == layer or module.startswith(layer + ".")) and not (layer == "encctl_gym" and module.startswith(APPLICATIONS))
        for target in targets
        if any(target == high or target.startswith(high + ".") for high in FORBIDDEN[layer])
    )
    # the CLI is the application's entry point: it may reach the applications by name
    upward = [edge for edge in upward if not edge.startswith("encctl_gym.cli ->")]
    assert not upward, "upward imports:\n" + "\n".join(upward)


def test_type_checking_imports_count_as_dependencies() -> None:
    modules = {"pkg": Path("pkg/__init__.py"), "pkg.a": Path("pkg/a.py"), "pkg.b": Path("pkg/b.py"), "pkg.c": Path("pkg/c.py")}
    source = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .b import B\nelse:\n    from .c import C\n"
    assert imports_of("pkg.a", source, modules) == {"pkg.b", "pkg.c"}  # both branches
    assert imports_of("pkg.a", "import typing\nif typing.TYPE_CHECKING:\n    from .b import B\n", modules) == {"pkg.b"}
    assert cycles({"pkg.a": {"pkg.b"}, "pkg.b": imports_of("pkg.b", "if TYPE_CHECKING:\n    from .a import A\n", modules)}) == [
        ["pkg.a", "pkg.b"]
    ]
