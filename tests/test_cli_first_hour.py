"""An engineer's first hour with the command line.

Help written for a terminal (no raw markup, examples), ``--chain`` for every method that
uses a chain, status lines on stderr (never on stdout, so ``--json`` stays JSON), and
``arcosim example`` writing the sample log and its script from the installed package.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

import pytest

from arcosim.cli import main, make_parser
from arcosim.cli.example import FILES
from arcosim.fmu.flexchain import defaults
from tests.cli_runs import run

ROOT = Path(__file__).resolve().parents[1]
#: Markup a terminal shows raw: ``code``, Sphinx roles, a literal block's ``::``.
MARKUP = re.compile(r"``|:func:|:mod:|:class:|:data:|:meth:|::$", re.MULTILINE)


def subcommands() -> dict[str, argparse.ArgumentParser]:
    parser = make_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


# -- help -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(subcommands()))
def test_every_help_reads_in_a_terminal(name: str) -> None:
    text = subcommands()[name].format_help()
    assert not MARKUP.search(text), MARKUP.search(text).group(0)
    assert "Contract" not in text
    examples = [line for line in text.splitlines() if line.startswith(f"  arcosim {name}")]
    assert examples, f"arcosim {name} --help shows no example"
    assert len(text.splitlines()) < 90, "help longer than a screen or two"


def test_the_top_level_help_lists_every_command() -> None:
    text = make_parser().format_help()
    assert not MARKUP.search(text)
    for name in subcommands():
        assert name in text


def test_identify_help_names_the_drive_first() -> None:
    """k_to, J_mo, encoder_cpr and --scale in the description, before the option list."""
    text = subcommands()["identify"].format_help()
    head = text[: text.index("positional arguments")]
    for needed in ("--set k_to=", "--set J_mo=", "--set encoder_cpr=", "--scale", "--chain"):
        assert needed in head, needed


# -- arcosim example ----------------------------------------------------------------------


def test_the_packaged_examples_are_the_checkouts() -> None:
    """``cosim/example-files`` (package data) holds what ``examples/`` links to: the same
    bytes."""
    for name in FILES:
        packaged = ROOT / "cosim" / "example-files" / name
        assert packaged.read_bytes() == (ROOT / "examples" / name).read_bytes(), name


def test_example_writes_the_sample_and_never_overwrites_without_force(capsys, tmp_path) -> None:
    out = tmp_path / "first-hour"
    code, stdout, _ = run(capsys, "example", "--out", out)
    assert code == 0
    for name in FILES:
        assert (out / name).read_bytes() == (ROOT / "examples" / name).read_bytes()
        assert str(out / name) in stdout
    script = out / "identify_your_drive.py"
    script.write_text("# my edits\n")
    code, _, err = run(capsys, "example", "--out", out)
    assert code == 2 and "--force" in err and script.read_text() == "# my edits\n"
    code, _, _ = run(capsys, "example", "--out", out, "--force")
    assert code == 0 and script.read_bytes() == (ROOT / "examples" / FILES[0]).read_bytes()


def test_example_refuses_a_file_as_its_folder(capsys, tmp_path) -> None:
    (tmp_path / "file").write_text("x")
    code, _, err = run(capsys, "example", "--out", tmp_path / "file")
    assert code == 2 and err.startswith("arcosim: error: --out")


# -- --chain everywhere -----------------------------------------------------------------


@pytest.fixture(scope="module")
def log(fmus, tmp_path_factory) -> Path:
    """A 1 s log of the flexible maneuver (as `arcosim simulate --out` writes it)."""
    path = tmp_path_factory.mktemp("log") / "flexible.csv"
    assert main(["simulate", "--fmus", str(fmus), "--duration", "1", "--out", str(path)]) == 0
    return path


#: A whole-chain report of the bench's chain, a little off (as a fit would give it).
CHAIN = {
    "masses": 3,
    **{f"J[{i + 1}]": 1.1 * x for i, x in enumerate(defaults.J)},
    **{f"k[{i}]": 0.9 * defaults.K for i in (1, 2, 3)},
    **{f"B[{i}]": 1.2 * defaults.B for i in (1, 2, 3)},
    "D_m": 2e-5,
    "f_c": 2e-3,
    "std": {"J[1]": 1e-7},
}


def as_sets(chain: dict) -> list[str]:
    """The chain as the ``--set`` options one would paste."""
    return [
        a for k, v in chain.items() if k not in ("masses", "std") for a in ("--set", f"{k}={v!r}")
    ]


@pytest.fixture(scope="module")
def chain_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("chain") / "chain.json"
    path.write_text(json.dumps(CHAIN))
    return path


def test_chain_feeds_the_observer_replay_as_the_pasted_values(
    capsys, fmus, log, chain_file
) -> None:
    """Quick start 2, step 3: ``--chain chain.json`` gives the same estimates as the nine
    values pasted with ``--set``, and ``--set`` wins over the file."""
    common = ["identify", log, "--fmus", fmus, "--set", "estimator=1", "--json"]
    code, by_file, _ = run(capsys, *common, "--chain", chain_file, "--masses", "3")
    assert code == 0  # --masses that agrees with the file's 3 masses
    code, _, err = run(capsys, *common, "--chain", chain_file, "--masses", "2")
    assert code == 2 and "--masses 2 but --chain" in err and "holds 3" in err
    code, pasted, _ = run(capsys, *common, *as_sets(CHAIN))
    assert code == 0
    assert json.loads(by_file) == json.loads(pasted)
    assert "theta_hat[3]" in json.loads(by_file)
    stiffer = ["--set", f"k[1]={2 * CHAIN['k[1]']!r}"]
    code, winning, _ = run(capsys, *common, "--chain", chain_file, *stiffer)
    code2, expected, _ = run(capsys, *common, *as_sets(CHAIN), *stiffer)
    assert code == code2 == 0
    assert json.loads(winning) == json.loads(expected) != json.loads(by_file)


def test_chain_gives_output_error_its_inertias(capsys, fmus, log, chain_file) -> None:
    common = ["identify", log, "--method", "output-error", "--start-k", "0.2", "--json"]
    code, by_file, err = run(capsys, *common, "--chain", chain_file)
    assert code == 0, err
    known = ("J[1]", "J[2]", "J[3]", "D_m", "f_c")  # what output error uses of a chain
    code, pasted, _ = run(
        capsys, *common, *(a for k in known for a in ("--set", f"{k}={CHAIN[k]!r}"))
    )
    assert code == 0
    assert json.loads(by_file)["k_hat"] == json.loads(pasted)["k_hat"]


def test_chain_is_refused_where_the_chain_is_fitted(capsys, log, chain_file) -> None:
    code, _, err = run(capsys, "identify", log, "--method", "whole-chain", "--chain", chain_file)
    assert code == 2 and "--method whole-chain fits it" in err


# -- status on stderr, never on stdout ----------------------------------------------------


@pytest.mark.slow
def test_whole_chain_json_stays_json_with_its_status_on_stderr(capsys, tmp_path) -> None:
    """The sample log, step 2 of quick start 2 with ``--json``: stdout parses as one JSON
    object, stderr says what the seconds of fitting are."""
    counts = 2.0 * math.pi / 2000
    code, out, err = run(
        capsys,
        "identify",
        ROOT / "examples" / "data" / "belt_drive.csv",
        *("--scale", "i_a=0.001", "--scale", f"theta_m={counts!r}"),
        *("--scale", f"omega_m={counts!r}"),
        *("--set", "k_to=0.0406", "--set", "J_mo=2.09e-5", "--set", "encoder_cpr=2000"),
        *("--method", "whole-chain", "--masses", "2", "--json", "--out", tmp_path / "c.json"),
    )
    assert code == 0, err
    report = json.loads(out)
    assert report["masses"] == 2
    assert "fitting the whole chain" in err
    assert json.loads((tmp_path / "c.json").read_text()) == report


def test_a_first_build_says_so_on_stderr(capsys, tmp_path, monkeypatch) -> None:
    """The FMUs' first build (seconds) is announced on stderr; stdout stays clean."""
    import arcosim.build.builder as builder

    monkeypatch.setattr(builder, "build_locked", lambda n, target: None)
    monkeypatch.setattr(builder, "is_current", lambda target, n: False)
    builder.ensure_built(2, tmp_path / "fmus")
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"building the FMUs for 2 masses into {tmp_path / 'fmus'}" in captured.err


@pytest.mark.slow
def test_a_sweep_says_dask_is_starting_on_stderr(capsys, build_fmus, tmp_path) -> None:
    """Dask takes seconds to start before the first run: a line on stderr says so;
    ``--no-progress`` drops it with the bar."""
    build_fmus(3)
    spec = tmp_path / "spec.toml"
    spec.write_text(SWEEP)
    common = ["sweep", spec, "--workers", "1"]
    code, out, err = run(capsys, *common, "--out", tmp_path / "a")
    assert code == 0, err
    assert "tiny: starting a local Dask cluster (1 workers) for 2 runs" in err
    assert "starting" not in out
    code, _, err = run(capsys, *common, "--out", tmp_path / "b", "--no-progress")
    assert code == 0 and "starting" not in err


#: The smallest sweep: two runs of a second each.
SWEEP = """
name = "tiny"
scenario = "selfid"
duration = 0.2
runs = 2
seed = 3
metrics = ["runtime"]
[vary]
"observer.g_dist" = { distribution = "choice", values = [100.0, 200.0] }
"""
