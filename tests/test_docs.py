"""The docs check fails on a broken link, and the docs pass it; the API pages
show no raw Sphinx role and no docstring section left as a paragraph.

``make test`` and ``make docs`` run ``$(MKDOCS)`` from the Makefile; these tests run that
very command on a copy of the docs, the package's folders and ``pyproject.toml`` (the
API reference's griffe extension reads the folders under their installed names), once
as they are and once with a link to a page that is not there. ``mkdocs build --strict
--quiet`` passed such a link: ``--quiet`` drops the warnings strict mode counts.
"""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: What the docs build reads.
INPUTS = ("mkdocs.yml", "pyproject.toml", "docs", "cosim", "fmu_src", "plant_models")
#: A Sphinx role left as text (``:func:`read_log```): the API pages must show none.
RAW_ROLE = re.compile(r":(func|mod|class|data|meth|attr|ref|obj):")
#: A docstring section header the numpydoc parser did not take (Google style, or a
#: section it did not recognise), at the start of a line of a paragraph.
SECTION = re.compile(
    r"^\s*(Args|Arguments|Attributes|Returns|Raises|Yields|Parameters|Examples|Notes|"
    r"Keyword Args|Other Parameters|See Also|Warns)\s*:",
    re.MULTILINE,
)


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


class Paragraphs(HTMLParser):
    """The text of every ``<p>`` of a page but mkdocstrings' own section titles."""

    def __init__(self) -> None:
        super().__init__()
        self.texts: list[str] = []
        self.depth = 0

    def handle_starttag(self, tag: str, attrs: list) -> None:
        if tag == "p":
            self.depth += 1
            self.texts.append("")
        elif self.depth and "doc-section-title" in (dict(attrs).get("class") or ""):
            self.texts[-1] += "\x00"  # a title mkdocstrings rendered: not a paragraph

    def handle_endtag(self, tag: str) -> None:
        if tag == "p" and self.depth:
            self.depth -= 1

    def handle_data(self, data: str) -> None:
        if self.depth:
            self.texts[-1] += data


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess]:
    """The docs as they are, built once: the copy's folder and the build's result."""
    folder = copy_of_the_docs(tmp_path_factory.mktemp("docs"))
    return folder, build(folder)


@pytest.mark.system
def test_the_docs_pass_the_check(built: tuple[Path, subprocess.CompletedProcess]) -> None:
    folder, result = built
    assert result.returncode == 0, result.stderr[-3000:]
    assert "WARNING" not in result.stderr, result.stderr[-3000:]
    assert (folder / ".site" / "api" / "fmu" / "index.html").is_file()


@pytest.mark.system
def test_the_api_pages_show_no_raw_markup(built: tuple[Path, subprocess.CompletedProcess]) -> None:
    folder, result = built
    assert result.returncode == 0, result.stderr[-3000:]
    pages = sorted((folder / ".site" / "api").rglob("*.html"))
    assert len(pages) >= 7
    roles, sections = [], []
    for page in pages:
        html = page.read_text(encoding="utf-8")
        name = page.relative_to(folder / ".site")
        roles += [
            f"{name}: {html[m.start() - 40 : m.end() + 40]!r}" for m in RAW_ROLE.finditer(html)
        ]
        parser = Paragraphs()
        parser.feed(html)
        sections += [
            f"{name}: {text[:80]!r}"
            for text in parser.texts
            if "\x00" not in text and SECTION.search(text)
        ]
    assert not roles, f"{len(roles)} raw Sphinx roles, e.g. " + "; ".join(roles[:5])
    assert not sections, f"{len(sections)} sections left as paragraphs: " + "; ".join(sections[:5])


@pytest.mark.system
def test_wide_tables_wrap(built: tuple[Path, subprocess.CompletedProcess]) -> None:
    folder, _ = built
    css = (folder / ".site" / "css" / "extra.css").read_text(encoding="utf-8")
    assert "white-space: normal" in css and "overflow-x: auto" in css
    page = (folder / ".site" / "index.html").read_text(encoding="utf-8")
    assert "css/extra.css" in page


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


# -- docs/cli.md and the README say what the commands do ---------------------------------

NUMBERS = {"three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8}


def _parser(command: str):
    """The argparse parser of ``arcosim COMMAND``."""
    import argparse

    from arcosim.cli import make_parser

    parser = make_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices[command]


def test_reproduce_counts_its_experiments_alike_everywhere() -> None:
    """The experiments ``reproduce`` runs (its module's numbered list): the help's
    "three … and four beyond", the README's sentence and table, and docs/cli.md agree."""
    import arcosim.experiments.reproduce as module

    count = len(re.findall(r"^\d+\. ", module.__doc__, re.MULTILINE))
    helped = re.search(r"paper's (\w+) experiments .* and (\w+) beyond", _parser("reproduce")
                       .description.replace("\n", " "))  # fmt: skip
    assert NUMBERS[helped[1]] + NUMBERS[helped[2]] == count
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    quick = readme[readme.index("## Quick start 1") : readme.index("## Quick start 2")]
    said = re.search(r"(\w+) experiments on the paper's bench .* and (\w+) on a flexible", quick,
                     re.DOTALL)  # fmt: skip
    assert NUMBERS[said[1].lower()] + {"one": 1}[said[2]] == count, said[0]
    assert len(re.findall(r"^\| \d+ \|", quick, re.MULTILINE)) == count
    cli = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    assert re.search(r"Runs the (\w+) experiments", cli)[1] == next(
        w for w, n in NUMBERS.items() if n == count
    )


def test_the_cli_page_lists_every_method_and_scenario_the_help_offers() -> None:
    """identify's --method choices and simulate's scenarios, each in docs/cli.md's tables;
    the rigid scenario's current as its help states it."""
    from arcosim.experiments.control_scenarios import CONTROL_SCENARIOS
    from arcosim.experiments.scenarios import SCENARIOS

    cli = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    method = next(a for a in _parser("identify")._actions if a.dest == "method")
    row = next(line for line in cli.splitlines() if line.startswith("| `--method` |"))
    for choice in method.choices:
        assert f"`{choice}`" in row, choice
    for name in [*SCENARIOS, *CONTROL_SCENARIOS]:
        assert f"\n| `{name}` |" in cli, name
    current = re.search(r"(\d+(\.\d+)?) A", SCENARIOS["rigid"].description)[0]
    assert f"| `rigid` | rigid maneuver, {current} " in cli
    simulate = cli[cli.index("## `arcosim simulate`") : cli.index("## `arcosim excite`")]
    assert not re.search(r"(?<![\d.])2 A\b", simulate)  # the rigid current was once "2 A"
    build = cli[cli.index("## `arcosim build`") : cli.index("## `arcosim simulate`")]
    assert "`ActionReactionController.fmu`" in build and "`MotionControl.ssp`" in build


def test_the_cli_page_names_every_command_and_option_the_parsers_take() -> None:
    """Every subcommand has a ``## `arcosim NAME` `` section in docs/cli.md, and every
    long option its parser takes appears in that section, or in the page's opening
    (options every command shares, ``--tool-names``): a new option left undocumented
    fails here."""
    import argparse

    from arcosim.cli import make_parser

    cli = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")
    parser = make_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    headings = re.findall(r"^## `arcosim (\w+)", cli, re.MULTILINE)
    assert set(commands.choices) <= set(headings), set(commands.choices) - set(headings)
    shared = cli[: cli.index("\n## ")]
    missing = {}
    for name, sub in commands.choices.items():
        start = cli.index(f"## `arcosim {name}")
        end = cli.find("\n## ", start + 1)
        section = cli[start : end if end > 0 else len(cli)]
        options = [o for a in sub._actions for o in a.option_strings if o.startswith("--")]
        absent = [o for o in options if o != "--help" and o not in section + shared]
        if absent:
            missing[name] = absent
    assert not missing, missing
