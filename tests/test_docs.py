"""The docs check fails on a broken link (issue 27), and the docs pass it.

``make test`` and ``make docs`` run ``$(MKDOCS)`` from the Makefile; these tests run that
very command on a copy of the docs, the package's folders and ``pyproject.toml`` (the
API reference's griffe extension reads the folders under their installed names), once
as they are and once with a link to a page that is not there. ``mkdocs build --strict
--quiet`` passed such a link: ``--quiet`` drops the warnings strict mode counts.
"""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: What the docs build reads.
INPUTS = ("mkdocs.yml", "pyproject.toml", "docs", "cosim", "fmu_src", "plant_models")


def docs_command() -> list[str]:
    """The Makefile's ``MKDOCS``, run by this test's Python."""
    for line in (ROOT / "Makefile").read_text(encoding="utf-8").splitlines():
        name, _, value = line.partition(":=")
        if name.strip() == "MKDOCS":
            words = shlex.split(value)
            assert words[0] == "$(BIN)/python", line
            return [sys.executable, *words[1:]]
    raise AssertionError("the Makefile defines no MKDOCS")


def copy_of_the_docs(folder: Path) -> Path:
    """The inputs of the docs build, copied into ``folder``."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in INPUTS:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, folder / name, ignore=ignore)
        else:
            shutil.copy2(ROOT / name, folder / name)
    return folder


def build(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run(docs_command(), cwd=folder, capture_output=True, text=True, timeout=600)


def test_the_docs_check_is_strict_and_not_quiet() -> None:
    command = docs_command()
    assert command[1:] == ["-m", "mkdocs", "build", "--strict"]


@pytest.mark.system
def test_the_docs_pass_the_check(tmp_path: Path) -> None:
    result = build(copy_of_the_docs(tmp_path))
    assert result.returncode == 0, result.stderr[-3000:]
    assert "WARNING" not in result.stderr, result.stderr[-3000:]
    assert (tmp_path / ".site" / "api" / "fmu" / "index.html").is_file()


@pytest.mark.system
def test_a_broken_link_fails_the_check(tmp_path: Path) -> None:
    folder = copy_of_the_docs(tmp_path)
    index = folder / "docs" / "index.md"
    index.write_text(
        index.read_text(encoding="utf-8") + "\n[a page that is not there](no-such-page.md)\n",
        encoding="utf-8",
    )
    result = build(folder)
    assert result.returncode != 0
    assert "no-such-page.md" in result.stderr, result.stderr[-3000:]
