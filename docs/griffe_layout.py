"""griffe extension: read the package ``arcosim`` from its folders, under its installed names.

``arcosim`` spans three folders of the repository, mapped by ``pyproject.toml``'s
``[tool.setuptools.package-dir]`` (``cosim/`` is ``arcosim``, ``fmu_src/`` is
``arcosim.fmu``, ``plant_models/`` is ``arcosim.plant``). griffe finds a package by the
name of its folder: it finds no folder ``arcosim``, falls back to importing ``arcosim``
(the editable install maps it) and inspecting it, and sees neither ``arcosim.fmu`` nor
``arcosim.plant``, which are not under ``cosim/``. When griffe has loaded ``arcosim``,
this extension reads the three folders in place, statically as griffe reads any
package, and puts that package in its place. Nothing is copied.

Used by mkdocstrings (``mkdocs.yml``: ``extensions: [docs/griffe_layout.py:InstalledLayout]``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import griffe

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def package_folders() -> dict[str, Path]:
    """Each package ``pyproject.toml`` maps to a folder of its own → that folder."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    mapping = config["tool"]["setuptools"]["package-dir"]
    return {package: ROOT / folder for package, folder in mapping.items()}


def read_module(
    name: str, path: Path, parent: griffe.Module | None, loader: griffe.GriffeLoader
) -> griffe.Module:
    """One module read from its source, as griffe's loader reads it."""
    code = path.read_text(encoding="utf-8-sig")
    loader.lines_collection[path] = code.splitlines(keepends=False)
    return griffe.visit(
        name,
        filepath=path,
        code=code,
        extensions=loader.extensions,
        parent=parent,
        docstring_parser=loader.docstring_parser,
        docstring_options=loader.docstring_options,
        lines_collection=loader.lines_collection,
        modules_collection=loader.modules_collection,
    )


def read_package(
    package: str,
    folder: Path,
    folders: dict[str, Path],
    loader: griffe.GriffeLoader,
    parent: griffe.Module | None = None,
) -> griffe.Module:
    """``package`` from ``folder``: its modules, its subfolders, and its mapped subpackages."""
    module = read_module(package.rpartition(".")[2], folder / "__init__.py", parent, loader)
    children = {
        path.stem: path for path in sorted(folder.glob("*.py")) if path.name != "__init__.py"
    }
    children |= {p.name: p for p in sorted(folder.iterdir()) if (p / "__init__.py").is_file()}
    children |= {
        name.rpartition(".")[2]: path
        for name, path in folders.items()
        if name.rpartition(".")[0] == package
    }
    for name, path in children.items():
        if path.suffix == ".py":
            child = read_module(name, path, module, loader)
        else:
            child = read_package(f"{package}.{name}", path, folders, loader, module)
        module.set_member(name, child)
    return module


class InstalledLayout(griffe.Extension):
    """Replace what griffe loaded of a package mapped to several folders by those folders."""

    def __init__(self) -> None:
        super().__init__()
        self.replacing = False

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **_: Any) -> None:
        folders = package_folders()
        if self.replacing or pkg.name not in folders:
            return
        package = read_package(pkg.name, folders[pkg.name], folders, loader)
        loader.modules_collection.set_member(package.path, package)
        loader.expand_exports(package)
        loader.expand_wildcards(package, external=False)
        self.replacing = True
        try:  # the other extensions (griffe's dataclasses) see the package read here
            loader.extensions.call("on_package", pkg=package, loader=loader)
        finally:
            self.replacing = False
