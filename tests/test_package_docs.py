"""Every package's docstring lists every module and subpackage it holds, so a reader finds
a module by its package's catalogue rather than by searching."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = sorted(
    init.parent
    for top in ("cosim", "fmu_src", "plant_models", "benchmarks")
    for init in (ROOT / top).rglob("__init__.py")
    if "native" not in init.parts and "example-files" not in init.parts
)


def _members(package: Path) -> list[str]:
    """The modules (without ``__init__``/``__main__``) and subpackages of ``package``."""
    modules = [p.stem for p in package.glob("*.py") if p.stem not in ("__init__", "__main__")]
    subpackages = [p.parent.name for p in package.glob("*/__init__.py")]
    return sorted(modules + subpackages)


@pytest.mark.parametrize("package", PACKAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_the_package_docstring_lists_every_module(package: Path) -> None:
    doc = ast.get_docstring(ast.parse((package / "__init__.py").read_text())) or ""
    missing = [m for m in _members(package) if not re.search(rf"(?<![\w]){m}(?![\w])", doc)]
    assert not missing, f"{package.relative_to(ROOT)}/__init__.py's docstring misses {missing}"
