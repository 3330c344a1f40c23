"""The command line, the benchmarks and the examples stand on the public API only.

The public API is the ``__all__`` of ``arcosim`` and of the subpackages in
:data:`PUBLIC_PACKAGES`: what a user may import and what the API reference documents.
A module the CLI, a benchmark or an example needs beyond that is either made public
(named in its package's ``__all__``) or the work it does moves behind a library function
that is. Read from the source files, so a deferred import inside a function counts too.
"""

from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The packages whose ``__all__`` is the public API, besides ``arcosim`` itself.
PUBLIC_PACKAGES = (
    "arcosim",
    "arcosim.build",
    "arcosim.control",
    "arcosim.experiments",
    "arcosim.fleet",
    "arcosim.host",
    "arcosim.identification",
    "arcosim.sweeps",
    "arcosim.fmu.flexchain",
)


def public_names(package: str) -> set[str]:
    """The names ``package`` makes public (its ``__all__``; empty when it has none)."""
    return set(getattr(importlib.import_module(package), "__all__", ()))


def violations(folder: Path, own: tuple[str, ...]) -> list[str]:
    """Every import in ``folder`` of a name that is neither public nor in ``own``.

    ``own`` are the dotted prefixes the folder may import freely (its own package, the
    simulators). Returns ``"file:line: from module import name"`` strings.
    """
    found: list[str] = []
    for path in sorted(folder.rglob("*.py")):
        where = path.relative_to(folder.parent)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and not node.level:
                module = node.module or ""
                if not module.startswith("arcosim") or module.startswith(own):
                    continue
                allowed = public_names(module) if module in PUBLIC_PACKAGES else set()
                for alias in node.names:
                    if alias.name not in allowed:
                        found.append(f"{where}:{node.lineno}: from {module} import {alias.name}")
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    name = alias.name
                    internal = name.startswith("arcosim.") and name not in PUBLIC_PACKAGES
                    if internal and not name.startswith(own):
                        found.append(f"{where}:{node.lineno}: import {name}")
    return found


@pytest.mark.parametrize("package", PUBLIC_PACKAGES)
def test_no_public_name_is_a_submodule(package: str) -> None:
    """A public name that is also a submodule's would be the module once the submodule is
    imported (the import system binds it on the package), the function only before; a
    public name that *is* its submodule (``flexchain.defaults``) is the same either way."""
    module = importlib.import_module(package)
    folder = Path(module.__file__).parent
    submodules = {p.stem for p in folder.glob("*.py")} | {
        p.parent.name for p in folder.glob("*/__init__.py")
    }
    names = set(getattr(module, "__all__", ())) & submodules
    clash = sorted(n for n in names if not inspect.ismodule(getattr(module, n)))
    assert not clash, f"{package}: public names that are also submodules: {clash}"


@pytest.mark.parametrize("package", PUBLIC_PACKAGES)
def test_every_public_name_resolves(package: str) -> None:
    module = importlib.import_module(package)
    if package == "arcosim":
        assert module.__all__, "arcosim has no public names"
    missing = [name for name in getattr(module, "__all__", ()) if not hasattr(module, name)]
    assert not missing, f"{package}.__all__ names what it does not define: {missing}"


def test_cli_imports_only_the_public_api_and_itself() -> None:
    found = violations(ROOT / "cosim" / "cli", own=("arcosim.cli",))
    assert not found, "\n".join(found)


def test_benchmarks_and_examples_import_only_the_public_api() -> None:
    found = violations(ROOT / "benchmarks", own=()) + violations(ROOT / "examples", own=())
    assert not found, "\n".join(found)


def test_the_check_sees_an_internal_import(tmp_path: Path) -> None:
    """The checker itself: an internal import is reported, a public one is not."""
    (tmp_path / "probe.py").write_text(
        "from arcosim import read_log\nfrom arcosim.logs import read_log as r\n"
        "import arcosim.identification.fit\n",
        encoding="utf-8",
    )
    found = violations(tmp_path, own=())
    probe = f"{tmp_path.name}/probe.py"
    assert found == [
        f"{probe}:2: from arcosim.logs import read_log",
        f"{probe}:3: import arcosim.identification.fit",
    ]
