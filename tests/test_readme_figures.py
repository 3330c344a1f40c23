"""README.md's Quick start 2, re-run: every figure its prose states about the sample log's
runs is what the run prints, to the digits shown.

The commands (steps 1, 2 and 5 of the section's shell block, with its ``$S`` and ``$M``),
and the figures (the paragraph after the block: "Step 2 finds …", "Step 5 designs …") are
read from README.md itself, so a README edit, or a change of the code, that makes the two
disagree fails here, naming the figure. A figure agrees when the printed one rounded to
the README's last digit is the README's, and the README shows no digit the run does not
print. Times ("in about 2 s") are not compared. The steps run in this process
(``arcosim.cli.main``) in a folder of their own holding a copy of the sample log, as a
user would type them in a checkout; ``control`` takes about 20 s on a loaded machine.

Quick start 3 prints no figures (file names and the model identifiers only), and Quick
start 1's table is ``arcosim reproduce``'s, a run of minutes: neither is checked here.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from decimal import ROUND_HALF_EVEN, Decimal
from pathlib import Path

import pytest

from arcosim.cli import main

ROOT = Path(__file__).resolve().parents[1]
#: The sample log, under the path the README's commands give.
SAMPLE = "examples/data/belt_drive.csv"

#: The paragraph's sentences, whitespace folded to one space.
STEP2 = re.compile(
    r"Step 2 finds (?P<masses>\d+) masses, J = (?P<J>[-+.\de, ]+?) kg·m² "
    r"and k = (?P<k>[-+.\de, ]+?) N·m/rad"
)
STEP5 = re.compile(
    r"Step 5 designs the `ActionReactionController` for it \(a (?P<move_time>[\d.]+) s move "
    r"of the last mass\) and says it is (?P<verdict>\w+): its sensorless loop decays at "
    r"(?P<moving>[\d.]+) 1/s or faster with every J_i, k_i within ±(?P<error>[\d.]+) % while "
    r"it moves, and at (?P<at_rest>[\d.]+) 1/s or faster at rest with the hold's dither"
)


@dataclass(frozen=True)
class Run:
    """One command's exit status and what it printed."""

    argv: list[str]
    code: int
    out: str
    err: str


def quick_start_2() -> str:
    """README.md's section "Quick start 2", up to the next section."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index("## Quick start 2")
    return text[start : text.index("\n## ", start)]


def readme_commands() -> dict[str, list[str]]:
    """Steps 1 (check), 2 (the whole chain) and 5 (control) of the section's shell block,
    as argument lists for ``arcosim``, its variables expanded as the shell would."""
    block = re.search(r"```sh\n(.*?)```", quick_start_2(), re.DOTALL)
    assert block, "README.md's Quick start 2 has no ```sh block"
    lines = block.group(1).replace("\\\n", " ").splitlines()
    variables: dict[str, str] = {}
    commands = []
    for line in lines:
        words = shlex.split(line, comments=True)
        if len(words) == 1 and re.fullmatch(r"\w+=.*", words[0]):
            name, _, value = words[0].partition("=")
            variables[name] = value
        elif words and words[0] == "arcosim":
            expanded = []
            for word in words[1:]:
                name = word[1:] if word.startswith("$") else None
                expanded += shlex.split(variables[name]) if name else [word]
            commands.append(expanded)
    steps = {
        "check": [c for c in commands if c[0] == "check"],
        "identify": [c for c in commands if c[0] == "identify" and "whole-chain" in c],
        "control": [c for c in commands if c[0] == "control"],
    }
    for name, found in steps.items():
        assert len(found) == 1, f"README.md's Quick start 2: {len(found)} `arcosim {name}` steps"
    return {name: found[0] for name, found in steps.items()}


def readme_figures() -> dict[str, list[str]]:
    """The figures the paragraph after the block states, by name: a list of one figure,
    or of one a mass for J and k."""
    text = " ".join(quick_start_2().split())
    figures: dict[str, list[str]] = {}
    for pattern in (STEP2, STEP5):
        match = pattern.search(text)
        assert match, (
            "README.md's Quick start 2 no longer has a sentence of the form "
            f"/{pattern.pattern}/: update the README or this test's pattern"
        )
        figures.update({name: value.split(", ") for name, value in match.groupdict().items()})
    return figures


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Run]:
    """The three steps run in order in a fresh folder holding the sample log."""
    folder = tmp_path_factory.mktemp("quick-start-2")
    (folder / SAMPLE).parent.mkdir(parents=True)
    shutil.copyfile(ROOT / SAMPLE, folder / SAMPLE)
    done = {}
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(folder)
        for name, argv in readme_commands().items():
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(argv)
            done[name] = Run(argv, code, out.getvalue(), err.getvalue())
    return done


def one(pattern: str, text: str) -> str:
    """The one group of ``pattern``'s single match in ``text``."""
    found = re.findall(pattern, text, re.MULTILINE)
    assert len(found) == 1, f"/{pattern}/ matched {len(found)} times in:\n{text}"
    return found[0]


def at_rest(out: str) -> list[str]:
    """The slowest of the at-rest decays ``control`` prints, 1/s."""
    cases = one(r"^at rest with the hold's dither \(.*?\): (.*)$", out).split("; ")
    decays = [re.fullmatch(r".*?: ([-+.\de]+) 1/s( at .*)?", case) for case in cases]
    assert all(decays), cases  # "no rest: …" has no decay to state
    return [min((d.group(1) for d in decays), key=Decimal)]


#: What the run prints for each figure the README states, from stdout: identify's
#: (whole-chain fit) or control's.
PRINTED: dict[str, tuple[str, Callable[[str], list[str]]]] = {
    "masses": ("identify", lambda out: [one(r"whole-chain fit \((\d+) masses\)", out)]),
    "J": ("identify", lambda out: re.findall(r"^\s+J\[\d+\]\s+(\S+)\s+±", out, re.MULTILINE)),
    "k": ("identify", lambda out: re.findall(r"^\s+k\[\d+\]\s+(\S+)\s+±", out, re.MULTILINE)),
    "move_time": ("control", lambda out: [one(r"move_time (\S+) s", out)]),
    "error": ("control", lambda out: [one(r"worst over J_i, k_i ±(\S+) % \(\d+ models\)", out)]),
    "moving": (
        "control",
        lambda out: [one(r"worst over J_i, k_i ±\S+ % \(\d+ models\): (\S+) 1/s", out)],
    ),
    "at_rest": ("control", at_rest),
}


def agrees(shown: str, printed: str) -> bool:
    """``shown`` is ``printed`` to the digits shown: ``printed`` rounded to ``shown``'s last
    digit is ``shown``, and ``shown`` has no digit past ``printed``'s last."""
    s, p = Decimal(shown), Decimal(printed)
    if s.as_tuple().exponent < p.as_tuple().exponent:
        return False
    return p.quantize(s, rounding=ROUND_HALF_EVEN) == s


def test_agrees_to_the_digits_shown() -> None:
    assert agrees("3.00064e-4", "0.000300064") and agrees("8.9973e-4", "0.00089973")
    assert agrees("3.4", "3.43") and agrees("0.45020", "0.450195")
    assert not agrees("3.0003e-4", "0.000300064")  # a stale figure
    assert not agrees("3.37", "3.4")  # a digit the run does not print
    assert not agrees("3.43", "3.48")


@pytest.mark.slow
def test_the_steps_run_as_the_readme_says(runs: dict[str, Run]) -> None:
    """Exit status 0 for each (1 for check or control, 3 for an untrusted fit would
    contradict the prose), the fit trusted, and the move of the last mass."""
    for name, run in runs.items():
        assert run.code == 0, (name, run.argv, run.out, run.err)
    assert runs["check"].out.splitlines()[-1].startswith("ok: "), runs["check"].out
    assert runs["identify"].out.splitlines()[0] == "verdict: trusted", runs["identify"].out
    n = one(r"whole-chain fit \((\d+) masses\)", runs["identify"].out)
    assert one(r"^design: load mass (\d+ of \d+) moved", runs["control"].out) == f"{n} of {n}"


@pytest.mark.slow
def test_the_control_verdict_is_the_readmes(runs: dict[str, Run]) -> None:
    (verdict,) = readme_figures()["verdict"]
    assert one(r"^verdict: (\w+):", runs["control"].out) == verdict


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(PRINTED))
def test_the_figure_is_the_runs(runs: dict[str, Run], name: str) -> None:
    shown = readme_figures()[name]
    step, read = PRINTED[name]
    printed = read(runs[step].out)
    assert len(shown) == len(printed) and all(map(agrees, shown, printed)), (
        f"README.md's Quick start 2 states {name} = {', '.join(shown)}; "
        f"`arcosim {step}` prints {', '.join(printed)}"
    )
