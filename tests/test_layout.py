"""The package's layout and the one direction of its imports.

Read from the source files (every ``import`` statement, at module level or inside a
function), not from what happens to be imported, so a deferred import counts too.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
#: Folder of the design card → the package it holds.
FOLDERS = {"cosim": "arcosim", "fmu_src": "arcosim.fmu", "plant_models": "arcosim.plant"}


def module_files() -> dict[str, Path]:
    """Every module of the package, by dotted name (a package by its ``__init__``)."""
    modules: dict[str, Path] = {}
    for folder, package in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            modules[".".join([package, *parts])] = path
    return modules


MODULES = module_files()


def imports_of(name: str, path: Path) -> set[str]:
    """Absolute names of every module ``name`` imports (relative imports resolved)."""
    is_package = path.name == "__init__.py"
    package = name if is_package else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join([*base, node.module] if node.module else base)
            else:
                target = node.module or ""
            found.add(target)
            # ``from pkg import module`` imports a module too
            found |= {f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in MODULES}
    return found


GRAPH = {name: imports_of(name, path) for name, path in MODULES.items()}


def internal(name: str) -> set[str]:
    """The project's own modules that ``name`` imports."""
    return {m for m in GRAPH[name] if m in MODULES}


def in_package(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def test_pyproject_lists_every_package_of_the_design_card_folders() -> None:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(config["tool"]["setuptools"]["packages"])
    packages = {n for n, p in MODULES.items() if p.name == "__init__.py"}
    assert listed == packages
    assert config["tool"]["setuptools"]["package-dir"] == {v: k for k, v in FOLDERS.items()}


#: Modules every subpackage outside the FMUs may import: the lazy loading of its public names.
EVERYWHERE = ("arcosim.lazy",)

#: Subpackage → the project's packages its modules may import (besides itself).
ALLOWED = {
    "arcosim.identification": ("arcosim.errors", "arcosim.fmu.flexchain"),
    "arcosim.fmu": (),
    "arcosim.plant": ("arcosim.fmu",),
    "arcosim.host": (
        "arcosim.errors",
        "arcosim.logs",
        "arcosim.fmu",
        "arcosim.portability",
        "arcosim.version",
    ),
    "arcosim.control": ("arcosim.errors", "arcosim.fmu", "arcosim.plant"),
    "arcosim.build": (
        "arcosim.errors",
        "arcosim.fmu",
        "arcosim.plant",
        "arcosim.portability",
        "arcosim.version",
    ),
}


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_each_subpackage_imports_only_what_its_job_allows(package: str) -> None:
    wrong = {
        (name, target)
        for name in MODULES
        if in_package(name, package)
        for target in internal(name)
        if not in_package(target, package)
        and not any(
            in_package(target, allowed)
            for allowed in ALLOWED[package]
            + (() if package.startswith("arcosim.fmu") else EVERYWHERE)
        )
    }
    assert not wrong, f"{package} imports outside its job: {sorted(wrong)}"


def test_identification_needs_no_fmi_host_build_or_cli_code() -> None:
    third_party = {
        m.split(".")[0]
        for name in MODULES
        if in_package(name, "arcosim.identification")
        for m in GRAPH[name]
        if m not in MODULES and not in_package(m, "arcosim")
    }
    assert third_party - set(sys.stdlib_module_names) <= {"numpy", "scipy", "threadpoolctl"}


def test_code_inside_the_fmus_uses_the_standard_library_and_relative_imports_only() -> None:
    for name in (n for n in MODULES if in_package(n, "arcosim.fmu")):
        outside = {m for m in GRAPH[name] if m not in MODULES and not in_package(m, "arcosim")}
        absolute = {m.split(".")[0] for m in outside}
        assert absolute - set(sys.stdlib_module_names) <= {"pythonfmu"}, name
        source = MODULES[name].read_text(encoding="utf-8")
        assert "from arcosim" not in source and "import arcosim" not in source, name
        if absolute & {"pythonfmu"}:  # only the stand-in for the runtime each FMU bundles
            assert in_package(name, "arcosim.fmu.pythonfmu"), name


def test_nothing_imports_the_command_line() -> None:
    users = {
        name
        for name in MODULES
        if not in_package(name, "arcosim.cli") and name != "arcosim.__main__"
        if any(in_package(t, "arcosim.cli") for t in internal(name))
    }
    assert not users


def test_no_import_cycle() -> None:
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(name: str) -> None:
        state[name] = 1
        path.append(name)
        for target in sorted(internal(name)):
            if target == name:
                continue
            if state.get(target) == 1:
                cycle = [*path[path.index(target) :], target]
                raise AssertionError("import cycle: " + " → ".join(cycle))
            if target not in state:
                visit(target)
        path.pop()
        state[name] = 2

    for name in sorted(MODULES):
        if name not in state:
            visit(name)
