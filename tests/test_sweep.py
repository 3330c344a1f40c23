"""`arcosim sweep`: spec errors, reproducibility, failing runs, resume, external cluster."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from arcosim.build.builder import fmu_variables
from arcosim.cli import main
from arcosim.errors import UserError
from arcosim.sweeps.runner import draw_runs, load_spec, read_results, sweep
from arcosim.sweeps.spec import metric_columns

SMALL = """
name = "small"
scenario = "selfid"
duration = 1.0
runs = 4
seed = 3
metrics = ["D_m_error", "f_c_error", "runtime"]
[vary]
"plant.i_noise_std" = { distribution = "uniform", low = 0.0, high = 0.01 }
"observer.g_dist" = { distribution = "choice", values = [100.0, 200.0] }
"""


@pytest.fixture()
def workdir(build_fmus, tmp_path: Path, monkeypatch) -> Path:
    """The current directory, with the FMUs for n = 3 built into the session cache."""
    build_fmus(3)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def spec_file(folder: Path, text: str, name: str = "spec.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def without_runtime(rows: list[dict[str, str]]) -> list[dict[str, str]]:
    return sorted(
        ({k: v for k, v in r.items() if k != "runtime"} for r in rows), key=lambda r: int(r["run"])
    )


@pytest.mark.parametrize(
    ("change", "phrase"),
    [
        (
            '"observer.g_dist" = { distribution = "wobbly", low = 1, high = 2 }',
            "unknown distribution 'wobbly'",
        ),
        (
            '"observer.g_dist" = { distribution = "uniform", low = 5, high = 2 }',
            "low = 5 must be below high = 2",
        ),
        ('"observer.g_dist" = { distribution = "loguniform", low = 0, high = 2 }', "needs low > 0"),
        ('"observer.g_dist" = { distribution = "normal", mean = 1 }', "needs std"),
        ('"g_dist" = { distribution = "uniform", low = 1, high = 2 }', "name the FMU first"),
        ('"observer.g_dist" = { distribution = "grid", values = [1, 2] }', "cannot be mixed"),
    ],
)
def test_bad_distributions_are_named(tmp_path, change, phrase) -> None:
    text = SMALL.replace(
        '"observer.g_dist" = { distribution = "choice", values = [100.0, 200.0] }', change
    )
    with pytest.raises(UserError, match=None) as error:
        load_spec(spec_file(tmp_path, text))
    assert phrase in str(error.value)


def test_spec_mistakes_are_named(tmp_path) -> None:
    for text, phrase in (
        ('colour = "blue"\n' + SMALL, "unknown key colour"),
        (SMALL.replace('"selfid"', '"loop"'), "scenario 'loop'"),
        (SMALL.replace('"D_m_error", ', '"speed", '), "metric 'speed'"),
        ("name = [", "not valid TOML"),
    ):
        with pytest.raises(UserError) as error:
            load_spec(spec_file(tmp_path, text))
        assert phrase in str(error.value)


def test_unknown_parameter_is_named_before_any_run(workdir) -> None:
    path = spec_file(workdir, SMALL.replace("plant.i_noise_std", "plant.noise_std"))
    assert main(["sweep", str(path), "--out", "out", "--no-progress"]) == 2
    assert not (workdir / "out" / "results.csv").exists()


@pytest.mark.slow
def test_same_seed_same_runs_and_results(workdir) -> None:
    spec = load_spec(spec_file(workdir, SMALL))
    assert draw_runs(spec) == draw_runs(spec)
    first = read_results(sweep(spec, workdir / "a", workers=1, show_progress=False))
    second = read_results(sweep(spec, workdir / "b", workers=1, show_progress=False))
    assert len(first) == 4 and without_runtime(first) == without_runtime(second)
    assert all(not r["error"] and abs(float(r["D_m_error"])) < 5 for r in first)


@pytest.mark.slow
def test_a_failing_run_is_recorded_and_the_sweep_goes_on(workdir) -> None:
    text = SMALL.replace(
        '"plant.i_noise_std" = { distribution = "uniform", low = 0.0, high = 0.01 }\n', ""
    )
    text = text.replace(
        '{ distribution = "choice", values = [100.0, 200.0] }',
        '{ distribution = "grid", values = [100.0, -5.0, 200.0] }',
    )
    rows = read_results(
        sweep(load_spec(spec_file(workdir, text)), workdir / "f", workers=2, show_progress=False)
    )
    by_run = {int(r["run"]): r for r in rows}
    assert len(by_run) == 3
    assert "g_dist = -5.0 must be > 0" in by_run[1]["error"]
    assert not by_run[0]["error"] and not by_run[2]["error"]
    assert "Failed runs" in (workdir / "f" / "summary.md").read_text()


@pytest.mark.slow
def test_resume_keeps_finished_runs_and_repeats_none(workdir) -> None:
    spec = load_spec(spec_file(workdir, SMALL))
    complete = read_results(sweep(spec, workdir / "full", workers=1, show_progress=False))
    interrupted = workdir / "cut"
    interrupted.mkdir()
    with open(workdir / "full" / "results.csv") as f:
        lines = f.readlines()
    # header, 2 finished runs, and a third cut off mid-write
    (interrupted / "results.csv").write_text("".join(lines[:3]) + lines[3][:12])
    kept = read_results(interrupted / "results.csv")
    assert len(kept) == 2
    with pytest.raises(UserError, match="--resume"):
        sweep(spec, interrupted, workers=1, show_progress=False)
    assert (
        main(
            [
                "sweep",
                str(workdir / "spec.toml"),
                "--out",
                str(interrupted),
                "--resume",
                "--workers",
                "1",
                "--no-progress",
            ]
        )
        == 0
    )
    resumed = read_results(interrupted / "results.csv")
    assert sorted(int(r["run"]) for r in resumed) == [0, 1, 2, 3]  # none lost, none repeated
    assert resumed[:2] == kept  # the finished runs were not touched
    assert without_runtime(resumed) == without_runtime(complete)


@pytest.mark.system
@pytest.mark.slow
def test_runs_on_an_existing_cluster(workdir) -> None:
    from dask.distributed import LocalCluster

    spec = load_spec(spec_file(workdir, SMALL))
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        rows = read_results(
            sweep(
                spec, workdir / "remote", scheduler=cluster.scheduler_address, show_progress=False
            )
        )
    assert len(rows) == 4 and all(not r["error"] for r in rows)


def test_example_spec_is_valid() -> None:
    spec = load_spec(Path(__file__).parents[1] / "examples" / "sweep_noise_encoder_gdist.toml")
    assert spec.runs == 200 and len(draw_runs(spec)) == 200
    assert set(spec.vary) == {
        "plant.i_noise_std",
        "plant.encoder_cpr",
        "observer.g_dist",
        "plant.seed",
    }
    with open(Path(__file__).parents[1] / "examples" / "sweep_noise_encoder_gdist.toml") as f:
        assert "arcosim sweep" in f.read()


def test_summary_plots_carry_units_and_leave_the_seed_out(fmus, tmp_path, monkeypatch) -> None:
    """The plots' axes say their units; ``plant.seed`` is no factor."""
    import csv
    import json

    from arcosim.sweeps import summary
    from arcosim.sweeps.runner import result_units

    spec = load_spec(Path(__file__).parents[1] / "examples" / "sweep_noise_encoder_gdist.toml")
    variables = fmu_variables(fmus)
    columns = ["run", *spec.vary, *metric_columns(spec), "error"]
    results = tmp_path / "results.csv"
    rng = np.random.default_rng(1)
    with open(results, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        for run in range(12):
            row = {"run": run, "error": "", "plant.encoder_cpr": 2000, "plant.seed": run + 7}
            row |= {"plant.i_noise_std": rng.uniform(0, 0.02), "observer.g_dist": 100.0}
            row |= {"k_error": rng.normal(), "B_error": rng.normal(), "runtime": 1.0}
            writer.writerow(row)
    units = result_units(spec, variables, columns)
    assert units["plant.i_noise_std"] == "A" and units["observer.g_dist"] == "rad/s"
    assert units["k_error"] == "%" and units["runtime"] == "s" and units["plant.seed"] == "1"
    (tmp_path / "results.units.json").write_text(json.dumps(units))
    labels = []

    def keep_labels(figure, path, **_):
        labels.extend(ax.get_xlabel() for ax in figure.axes)
        return path

    monkeypatch.setattr(summary, "save_figure", keep_labels)
    text = summary.write_summary(spec, results, tmp_path).read_text()
    assert "plant.i_noise_std (A)" in labels and "k_error (%)" in labels
    assert "observer.g_dist (rad/s)" in labels and "runtime (s)" in labels
    assert not any("seed" in label for label in labels)
    assert "| plant.seed" not in text and "plant.seed draws a new noise" in text


@pytest.mark.parametrize("text", ["", "\n# nothing here yet\n"])
def test_an_empty_spec_is_refused_not_run_as_a_default_sweep(tmp_path, capsys, text) -> None:
    path = spec_file(tmp_path, text)
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"{path}: the spec is empty" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def _sweep_with_errors(monkeypatch, errors: list[str]) -> None:
    """Stand in for the runs: ``results.csv`` with one row per entry of ``errors``."""
    import arcosim.cli.sweep as command

    def fake(spec, out, *args, **kwargs) -> Path:
        out.mkdir(parents=True, exist_ok=True)
        rows = "".join(f"{i},1.0,{e}\n" for i, e in enumerate(errors))
        (out / "results.csv").write_text("run,runtime,error\n" + rows)
        return out / "results.csv"

    monkeypatch.setattr(command, "sweep", fake)


@pytest.mark.parametrize(
    ("errors", "code", "phrase"),
    [
        (["", "", ""], 0, None),
        (["", "g_dist = -5.0 must be > 0", ""], 1, "1 of 3 runs failed"),
        (["boom", "boom"], 3, "all 2 runs failed"),
    ],
)
def test_a_sweep_with_failed_runs_exits_non_zero(
    tmp_path, capsys, monkeypatch, errors, code, phrase
) -> None:
    """A sweep whose runs failed does not report success: 1 when some failed, 3 when all
    did, with the count on stderr."""
    _sweep_with_errors(monkeypatch, errors)
    path = spec_file(tmp_path, SMALL)
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == code
    err = capsys.readouterr().err
    if phrase is None:
        assert "failed" not in err
    else:
        assert phrase in err and "results.csv" in err
