"""The CLI never loses a file and never answers with a traceback.

One test per case: every refusal is one line on stderr, ``arcosim:
error: …`` naming the input, with exit status 2; no input file is ever changed.
"""

from __future__ import annotations

import json
import os
import re
import zipfile
from pathlib import Path

import pytest

from arcosim.cli import EXIT_INTERNAL, main
from tests.cli_runs import run


def refused(capsys, *argv: str) -> str:
    """Run ``argv``, assert a one-line refusal with exit 2, and return that line."""
    code, _, err = run(capsys, *argv)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("arcosim: error: "), err
    assert "Traceback" not in err and "np.float64" not in err
    return lines[0]


def snapshot(path: Path) -> tuple[bytes, int]:
    return path.read_bytes(), path.stat().st_mtime_ns


@pytest.fixture(scope="module")
def log(fmus, tmp_path_factory) -> Path:
    """A 1 s log of the flexible maneuver (as `arcosim simulate --out` writes it)."""
    path = tmp_path_factory.mktemp("log") / "flexible.csv"
    assert main(["simulate", "--fmus", str(fmus), "--duration", "1", "--out", str(path)]) == 0
    return path


# -- data loss -------------------------------------------------------------------------


def test_identify_refuses_its_own_log_as_output_even_with_force(capsys, fmus, log) -> None:
    before = snapshot(log)
    for force in ([], ["--force"]):
        line = refused(capsys, "identify", log, "--fmus", fmus, "--out", log, *force)
        assert "that is an input of this command" in line
    # the same file under another name (a hard link) is the same input
    other = log.with_name("same-log.csv")
    os.link(log, other)
    try:
        line = refused(capsys, "identify", log, "--fmus", fmus, "--out", other, "--force")
        assert "that is an input" in line
    finally:
        other.unlink()
    assert snapshot(log) == before


@pytest.mark.parametrize("command", ["identify", "simulate", "ssp"])
def test_out_never_replaces_a_file_without_force(capsys, fmus, log, tmp_path, command) -> None:
    out = tmp_path / "result.csv"
    out.write_text("the user's own data\n")
    argv = {
        "identify": ["identify", log, "--fmus", fmus],
        "simulate": ["simulate", "--fmus", fmus, "--duration", "0.05"],
        "ssp": ["ssp", fmus / "ActionReaction.ssp", "--stop", "0.05"],
    }[command]
    line = refused(capsys, *argv, "--out", out)
    assert f"--out {out}: the file exists; add --force" in line
    assert out.read_text() == "the user's own data\n"
    code, stdout, err = run(capsys, *argv, "--out", out, "--force")
    assert code == 0, err
    assert out.read_text().startswith("time,") and f"wrote {out}" in stdout
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["result.csv", "result.units.json"]  # no temporary left; the units beside


def test_simulate_never_writes_over_an_fmu_it_runs(capsys, fmus) -> None:
    plant = fmus / "MotorChainPlant.fmu"
    before = snapshot(plant)
    line = refused(capsys, "simulate", "--fmus", fmus, "--out", plant, "--force")
    assert "that is an input" in line
    assert snapshot(plant) == before


def test_output_error_writes_its_report_as_json(capsys, fmus, log, tmp_path) -> None:
    line = refused(
        capsys, "identify", log, "--fmus", fmus, "--method", "output-error", "--out", "k.csv"
    )
    assert "writes its report as JSON; name a .json file" in line
    out = tmp_path / "fit.json"
    code, stdout, err = run(
        capsys, "identify", log, "--fmus", fmus, "--method", "output-error", "--out", out
    )
    assert code == 0, err
    report = json.loads(out.read_text())
    assert report["method"] == "output-error" and report["k_hat"] > 0
    assert set(report["std"]) == {"k_hat", "B_hat"} and "k_hat" in stdout


def test_whole_chain_refuses_a_csv_out_and_observer_a_json_out(capsys, fmus, log) -> None:
    line = refused(
        capsys, "identify", log, "--fmus", fmus, "--method", "whole-chain", "--out", "x.csv"
    )
    assert "--method whole-chain writes its report as JSON" in line
    for method in ("observer", "load-torque"):
        line = refused(
            capsys, "identify", log, "--fmus", fmus, "--method", method, "--out", "x.json"
        )
        assert f"--method {method} writes its outputs over time as CSV" in line


def test_load_torque_never_writes_over_its_chain(capsys, fmus, log, tmp_path) -> None:
    chain = tmp_path / "chain.csv"
    chain.write_text('{"J[1]": 1}')
    before = snapshot(chain)
    line = refused(
        capsys,
        "identify",
        log,
        "--fmus",
        fmus,
        "--method",
        "load-torque",
        "--chain",
        chain,
        "--out",
        chain,
        "--force",
    )
    assert "that is an input of this command" in line and snapshot(chain) == before
    for text, phrase in (
        (b'{"J[1]": "heavy", "k[1]": 1, "B[1]": 0}', "J[1] = 'heavy' is not a number"),
        (b'{"masses": 2.5}', "masses = 2.5 is not a whole number"),
        (b'{"masses": 99}', "masses = 99: the number of load masses must be 1 to 20"),
        (b'\xef\xbb\xbf{"masses": 1, "J[1]": 1}', "missing k[1], B[1]"),
        (b"\xff{}", "byte 0xff is not UTF-8"),
    ):
        bad = tmp_path / "bad.json"
        bad.write_bytes(text)
        line = refused(
            capsys, "identify", log, "--fmus", fmus, "--method", "load-torque", "--chain", bad
        )
        assert phrase in line, line


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path) -> None:
    from arcosim.outputs import atomic_output

    out = tmp_path / "kept.csv"
    out.write_text("old\n")
    with pytest.raises(RuntimeError), atomic_output(out, force=True) as f:
        f.write("half of the new")
        raise RuntimeError("the command died here")
    assert out.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["kept.csv"]


def test_a_full_disk_is_one_line_and_keeps_the_old_file(tmp_path, monkeypatch) -> None:
    import arcosim.outputs
    from arcosim.errors import UserError

    out = tmp_path / "kept.csv"
    out.write_text("old\n")

    def full(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(arcosim.outputs.os, "fsync", full)
    with pytest.raises(UserError, match="No space left on device"):
        arcosim.outputs.write_text(out, "new\n", force=True)
    assert out.read_text() == "old\n" and len(list(tmp_path.iterdir())) == 1


@pytest.mark.parametrize(
    ("out", "phrase"),
    [
        ("{tmp}", "is a folder; name a file in it"),
        ("/proc/x", "cannot write in /proc"),
        ("/dev/full", "not a regular file"),
    ],
)
def test_out_paths_that_cannot_take_a_file(capsys, fmus, tmp_path, out, phrase) -> None:
    out = out.format(tmp=tmp_path)
    line = refused(capsys, "simulate", "--fmus", fmus, "--duration", "0.05", "--out", out)
    assert phrase in line
    assert os.path.exists("/dev/full") and not os.path.isfile("/dev/full")


# -- numbers ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "phrase"),
    [
        (["--step", "1e-12"], "argument --step: '1e-12' is not a finite number >= 1e-09"),
        (["--step", "1e-8"], "steps in 10 s, more than 10,000,000"),
        (["--step", "100"], "longer than the run (--duration 10 s), so not one step"),
        (["--step", "nan"], "argument --step: 'nan' is not a finite number"),
        (["--duration", "inf"], "argument --duration: 'inf' is not a finite number > 0"),
        (["--duration", "-1"], "argument --duration: '-1' is not a finite number > 0"),
        (["--masses", "2.5"], "argument --masses: '2.5' is not a whole number from 1 to 20"),
        (["--set", "plant.k[1]=inf"], "plant.k[1] must be a finite number"),
        (["--set", "plant.encoder_cpr=1e3"], "takes a whole number"),
        (["--set", "plant.encoder_cpr=9999999999"], "from -2147483648 to 2147483647"),
    ],
)
def test_simulate_numbers_are_checked_where_they_enter(capsys, fmus, args, phrase) -> None:
    assert phrase in refused(capsys, "simulate", "--fmus", fmus, *args)


def test_a_chain_too_stiff_for_the_step_is_refused_not_reported(capsys, fmus) -> None:
    """k = 1e15 gave NaN and 1e12 finite garbage (1.4e4 rad/s where a passive chain
    reaches at most 1.2e4): the plant now refuses both at initialization."""
    for k in ("1e15", "1e12"):
        line = refused(capsys, "simulate", "--fmus", fmus, "--set", f"plant.k[{1}]={k}")
        assert "MotorChainPlant.fmu refused its parameters" in line and "k[1]" in line


def test_a_result_no_passive_chain_can_give_is_refused() -> None:
    """The second line of defence behind the FMUs' own checks: a recording whose
    velocity exceeds what the motor's torque can give the chain in the run's time, or
    that is not finite, is refused (simulate's check_passive)."""
    import numpy as np

    from arcosim.cli.simulate import check_passive
    from arcosim.errors import UserError
    from arcosim.experiments.scenarios import SCENARIOS
    from arcosim.host.master import Recording

    scenario = SCENARIOS["flexible"]  # 10 s, at most 0.48 A
    plant = {"k_t": 0.0254, "J_m": 2.09e-5, "J[1]": 6e-4}
    t = np.arange(11) * 1.0
    # bound: 2 k_t i_max T / sqrt(J_m J_i) = 2 * 0.0254 * 0.48 * 10 / sqrt(2.09e-5 * 6e-4)
    bound = 2 * 0.0254 * 0.48 * 10 / np.sqrt(2.09e-5 * 6e-4)
    fine = Recording(t, {"plant.omega[1]": np.full(11, 0.5 * bound)})
    check_passive(fine, scenario, plant, 1, 1e-3, [])
    for series, phrase in (
        (np.full(11, 2.0 * bound), "more than a passive chain driven by at most"),
        (np.array([0.0] * 5 + [np.nan] * 6), "plant.omega[1] is not finite from t = 5 s"),
    ):
        with pytest.raises(UserError, match=re.escape(phrase)):
            check_passive(Recording(t, {"plant.omega[1]": series}), scenario, plant, 1, 1e-3, [])


@pytest.mark.parametrize("value", ["0", "nan", "inf", "-3", "1e300", "1e-300"])
def test_start_k_outside_the_band_the_log_shows(capsys, fmus, log, value) -> None:
    line = refused(
        capsys, "identify", log, "--fmus", fmus, "--method", "output-error", "--start-k", value
    )
    if value in ("1e300", "1e-300"):
        assert f"--start-k {float(value):g}: give a stiffness from" in line
        low, high = (float(x) for x in line.split("from ")[1].split(" N.m/rad")[0].split(" to "))
        assert 0 < low < 1 < high < 1e9  # the band of this 1 s log at 1 ms, bench J
    else:
        assert "argument --start-k" in line


def test_options_of_another_method_are_refused(capsys, fmus, log) -> None:
    line = refused(capsys, "identify", log, "--fmus", fmus, "--start-k", "0.2")
    assert "--start-k is for --method output-error" in line


@pytest.mark.parametrize(
    ("args", "phrase"),
    [
        (["--stop", "-1"], "argument --stop: '-1' is not a finite number > 0"),
        (["--stop", "nan"], "argument --stop: 'nan'"),
        (["--stop", "inf"], "argument --stop: 'inf'"),
        (["--step", "1e-12"], "argument --step: '1e-12'"),
        (["--stop", "1", "--step", "2"], "gives 0 steps"),
    ],
)
def test_ssp_numbers(capsys, fmus, args, phrase) -> None:
    assert phrase in refused(capsys, "ssp", fmus / "ActionReaction.ssp", *args)


def test_an_ssp_with_a_truncated_fmu_inside(capsys, fmus, tmp_path) -> None:
    broken = tmp_path / "broken.ssp"
    with zipfile.ZipFile(fmus / "ActionReaction.ssp") as z, zipfile.ZipFile(broken, "w") as out:
        for item in z.infolist():
            data = z.read(item)
            if item.filename.endswith("ReactionTorqueObserver.fmu"):
                data = data[: len(data) // 2]
            out.writestr(item, data)
    line = refused(capsys, "ssp", broken, "--stop", "0.1")
    assert "component observer (ReactionTorqueObserver.fmu): not a complete FMU" in line


def test_an_ssp_without_its_system_structure_or_a_folder_is_named(capsys, tmp_path) -> None:
    """Not a raw OS error with a temporary path, not "no such file" for a folder."""
    empty = tmp_path / "other.ssp"
    with zipfile.ZipFile(empty, "w") as z:
        z.writestr("readme.txt", "no system here")
    line = refused(capsys, "ssp", empty)
    assert f"{empty} is not an SSP: no SystemStructure.ssd" in line
    assert "arcosim_ssp_" not in line and "Errno" not in line
    folder = tmp_path / "unpacked.ssp"
    folder.mkdir()
    line = refused(capsys, "ssp", folder)
    assert "is a folder" in line and "no such file" not in line
    text = tmp_path / "notes.ssp"
    text.write_text("time,i_a\n0,1\n")
    assert "not an SSP (not a zip file)" in refused(capsys, "ssp", text)


def test_validate_calls_a_csv_named_ssp_what_it_is(capsys, tmp_path) -> None:
    """The zip's magic decides, not the name: a CSV named .ssp is no SSP system."""
    text = tmp_path / "run.ssp"
    text.write_text("time,i_a\n0,1\n")
    line = refused(capsys, "validate", text)
    assert "not an FMU (not a zip file)" in line and "SSP system" not in line
    folder = tmp_path / "model.fmu"
    folder.mkdir()
    assert "is a folder" in refused(capsys, "validate", folder)


# -- files that are not what they should be ---------------------------------------------


def test_validate_refuses_files_that_are_not_fmus(capsys, fmus, tmp_path) -> None:
    cases = {
        "text.fmu": b"hello\n",
        "empty.fmu": b"",
    }
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
    with zipfile.ZipFile(tmp_path / "nomd.fmu", "w") as z:
        z.writestr("readme.txt", "no model description")
    whole = (fmus / "ReactionTorqueObserver.fmu").read_bytes()
    (tmp_path / "truncated.fmu").write_bytes(whole[: len(whole) // 2])
    for name, phrase in (
        ("text.fmu", "not an FMU (not a zip file)"),
        ("empty.fmu", "an empty file, not an FMU"),
        ("nomd.fmu", "a zip file without modelDescription.xml"),
        ("truncated.fmu", "not an FMU (not a zip file)"),
    ):
        assert phrase in refused(capsys, "validate", tmp_path / name)
    assert "an SSP system, not an FMU" in refused(capsys, "validate", fmus / "ActionReaction.ssp")


@pytest.mark.slow
def test_a_corrupt_fmu_found_later_is_rebuilt(build_fmus, tmp_path) -> None:
    import shutil

    from arcosim.build.builder import ensure_built
    from arcosim.build.cache import fmu_problem, is_current

    folder = tmp_path / "n1"
    shutil.copytree(build_fmus(1), folder)
    observer = folder / "ReactionTorqueObserver.fmu"
    data = bytearray(observer.read_bytes())
    data[len(data) // 3] ^= 0xFF  # one flipped byte: a bad CRC-32 or deflate stream
    observer.write_bytes(bytes(data))
    plant = folder / "MotorChainPlant.fmu"
    plant.write_bytes(plant.read_bytes()[:1000])  # and one truncated
    assert not is_current(folder, 1)  # the digest still matches: the files are checked
    ensure_built(1, folder)
    assert is_current(folder, 1)
    assert fmu_problem(observer) is None and fmu_problem(plant) is None


@pytest.mark.parametrize(
    ("data", "phrase"),
    [
        ("time,i_a,omega_m,théta_m\n0,0,0,0\n".encode("latin-1"), "byte 0xe9 is not UTF-8"),
        ("time,i_a,omega_m,theta_m\n".encode("utf-16"), "is UTF-16 text; save it as UTF-8"),
        (b"time,i_a,omega_m,theta_m\n0,0\x00,0,0\n", "a NUL byte"),
        (b"time,i_a,omega\xe2\x80\x8b_m,theta_m\n0,0,0,0\n1,0,0,0\n", "'omega\\u200b_m'"),
    ],
)
def test_log_encodings_are_named(capsys, fmus, tmp_path, data, phrase) -> None:
    path = tmp_path / "log.csv"
    path.write_bytes(data)
    assert phrase in refused(capsys, "identify", path, "--fmus", fmus)
    assert path.read_bytes() == data


def test_a_log_with_a_byte_order_mark_is_read(capsys, fmus, log, tmp_path) -> None:
    with_bom = tmp_path / "bom.csv"
    with_bom.write_bytes(b"\xef\xbb\xbf" + log.read_bytes())
    code, out, err = run(capsys, "identify", with_bom, "--fmus", fmus, "--json")
    assert code == 0, err
    assert json.loads(out)["tau_reac_hat"] == pytest.approx(
        json.loads(run(capsys, "identify", log, "--fmus", fmus, "--json")[1])["tau_reac_hat"]
    )
    broken = tmp_path / "bom-missing.csv"
    broken.write_bytes(b"\xef\xbb\xbftime,i_a,omega_m\n0,0,0\n")
    line = refused(capsys, "identify", broken, "--fmus", fmus)
    assert "the header has: time, i_a, omega_m)" in line and "\ufeff" not in line


SPEC = """
name = "tiny"
scenario = "selfid"
duration = 0.5
runs = 2
seed = 3
metrics = ["D_m_error"]
[vary]
"observer.g_dist" = { distribution = "uniform", low = 100.0, high = 200.0 }
"""


@pytest.mark.parametrize(
    ("line", "phrase"),
    [
        ('runs = "ten"', "runs = 'ten': a whole number from 1"),
        ("runs = 2.5", "runs = 2.5: a whole number from 1"),
        ("runs = 0", "runs = 0: a whole number from 1"),
        ('masses = "abc"', "masses = 'abc': a whole number from 1 to 20"),
        ("seed = -1", "seed = -1: a whole number from 0"),
        ("duration = inf", "duration = inf: a finite number > 0"),
        ("duration = nan", "duration = nan: a finite number > 0"),
        ("step = 1e-12", "step = 1e-12: a finite number >= 1e-09"),
        ('name = "../../x"', "name = '../../x': use letters, digits"),
        ('name = ".."', "name = '..'"),
        ("ideal = 1", "ideal = 1: write true or false"),
    ],
)
def test_sweep_spec_fields_are_typed(capsys, tmp_path, line, phrase) -> None:
    key = line.split(" = ")[0]
    text = "\n".join(row for row in SPEC.splitlines() if not row.startswith(f"{key} ="))
    spec = tmp_path / "spec.toml"
    spec.write_text(line + "\n" + text)
    before = snapshot(spec)
    assert phrase in refused(capsys, "sweep", spec, "--out", tmp_path / "out", "--no-progress")
    assert snapshot(spec) == before
    assert not (tmp_path / "out").exists() and not (tmp_path.parent / "x").exists()


# -- the model-based observer's design ----------------------------------------------------


@pytest.mark.parametrize(
    ("torque", "tau", "accepted"),
    [
        (0.0, 0.0, False),
        (1e-4, 0.0, False),
        (0.0, 1.5e-3, False),
        (1e6, 1e-5, False),
        (1e-9, 1e-1, True),
        (1e-4, 1.5e-3, True),
    ],
)
def test_model_based_observer_refuses_noise_it_cannot_design_for(
    fmus, torque, tau, accepted
) -> None:
    """Refused at initialization (fmi2Error from exitInitializationMode), naming both
    parameters, instead of a traceback (singular matrix, Riccati) at the first step."""
    from arcosim.errors import UserError
    from arcosim.host.instance import FmuInstance

    settings = {"mode": 2, "estimator": 1, "torque_noise_std": torque, "tau_noise_std": tau}
    with FmuInstance(fmus / "ReactionTorqueObserver.fmu", "noise") as observer:
        if accepted:
            observer.initialize(settings)
            assert observer.do_step(0.0, 1e-3) == 0 and not observer.messages
            return
        with pytest.raises(UserError) as refusal:
            observer.initialize(settings)
    said = str(refusal.value)
    assert "refused its parameters" in said
    assert "parameters torque_noise_std" in said and "tau_noise_std" in said
    assert "Traceback" not in said and "Riccati" not in said and "singular" not in said


# -- no traceback, ever -----------------------------------------------------------------


def test_an_internal_error_is_one_line_naming_the_details_file(capsys, monkeypatch) -> None:
    import arcosim.cli.validate

    def broken(args):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(arcosim.cli.validate, "_execute", broken)
    code, _, err = run(capsys, "validate", "x.fmu")
    assert code == EXIT_INTERNAL
    (line,) = err.strip().splitlines()
    assert line.startswith("arcosim: internal error: ZeroDivisionError: a bug (details in ")
    report = Path(line.split("details in ")[1].split(";")[0])
    try:
        text = report.read_text()
        assert "Traceback (most recent call last)" in text and "command: arcosim validate" in text
    finally:
        report.unlink()


def test_argument_errors_are_one_line(capsys) -> None:
    for argv in (["simulate", "--ordering", "sideways"], ["nonsense"], ["identify"]):
        line = refused(capsys, *argv)
        assert line.endswith("--help`)")


def test_no_message_shows_a_numpy_repr(log) -> None:
    """An observer that refuses the second sample: the time in the message is a plain
    number (the log's times are numpy floats), not ``np.float64(0.001)``."""
    from arcosim.errors import UserError
    from arcosim.host.replay import replay_log
    from arcosim.logs import read_log

    class Refusing:  # the part of FmuInstance that replay_log uses
        def __init__(self) -> None:
            self.messages = ["discard: observer: step refused"]

        def real_writer(self, names):
            return lambda values: None

        def reader(self, names):
            return lambda: [0.0] * len(names)

        def initialize(self, parameters, start_time):
            pass

        def do_step(self, t, h):
            return 2

    with pytest.raises(UserError) as refusal:
        replay_log(Refusing(), read_log(log), outputs=["d_hat"])
    assert "sample at t = 0.001 s: the observer refused it" in str(refusal.value)
    assert "np.float64" not in str(refusal.value)


# -- every input counts ----------------------------------------------------------------

ROWS = "".join(f"{k * 1e-3},{0.1 * (k % 7)},{0.01 * k},{1e-5 * k * k}\n" for k in range(50))


def small_log(folder: Path, header: str = "time,i_a,omega_m,theta_m", sep: str = ",") -> Path:
    path = folder / "drive.csv"
    path.write_text(header + "\n" + ROWS.replace(",", sep), encoding="utf-8")
    return path


@pytest.mark.parametrize("command", ["identify", "check"])
def test_a_scale_the_units_sidecar_contradicts_is_refused(capsys, tmp_path, command) -> None:
    """The sidecar says i_a is in A already: --scale i_a=0.001 (mA to A) cannot both hold."""
    log = small_log(tmp_path)
    sidecar = tmp_path / "drive.units.json"
    sidecar.write_text(json.dumps({"time": "s", "i_a": "A", "omega_m": "rad/s", "theta_m": "rad"}))
    line = refused(capsys, command, log, "--scale", "i_a=0.001")
    assert "--scale i_a=0.001" in line and str(sidecar) in line and "'A'" in line


def test_a_scale_of_one_or_on_a_log_without_a_sidecar_is_taken(tmp_path) -> None:
    from arcosim.logs import read_log

    log = small_log(tmp_path)
    assert read_log(log, {"i_a": 1e-3}).columns["i_a"][1] == pytest.approx(1e-4)
    (tmp_path / "drive.units.json").write_text(json.dumps({"i_a": "A"}))
    assert read_log(log, {"i_a": 1.0}).columns["i_a"][1] == pytest.approx(0.1)
    assert read_log(log, {"theta_m": 2.0}).columns["theta_m"][1] == pytest.approx(2e-5)
    # a sign is no unit: the current turned against the encoder, as the torque balance asks
    assert read_log(log, {"i_a": -1.0}).columns["i_a"][1] == pytest.approx(-0.1)


def test_a_sidecar_that_is_not_json_is_named(capsys, tmp_path) -> None:
    log = small_log(tmp_path)
    (tmp_path / "drive.units.json").write_text("{not json")
    assert "drive.units.json" in refused(capsys, "check", log)


def test_a_log_with_a_column_twice_is_refused_naming_it(capsys, tmp_path) -> None:
    log = tmp_path / "drive.csv"
    log.write_text("time,i_a,omega_m,i_a,theta_m\n" + ROWS.replace("\n", ",0\n"))
    line = refused(capsys, "check", log)
    assert "i_a" in line and "twice" in line


@pytest.mark.parametrize("sep", [";", "\t"])
def test_a_log_separated_by_semicolons_names_the_separator(capsys, tmp_path, sep) -> None:
    line = refused(
        capsys,
        "identify",
        small_log(tmp_path, sep.join(["time", "i_a", "omega_m", "theta_m"]), sep),
    )
    assert f"separated by {sep!r}" in line and "give a comma-separated CSV" in line


def test_chain_and_masses_that_disagree_are_refused(capsys, tmp_path) -> None:
    chain = tmp_path / "chain.json"
    chain.write_text(json.dumps({"masses": 1, "J[1]": 1e-4, "k[1]": 50.0, "B[1]": 1e-3}))
    log = small_log(tmp_path)
    line = refused(capsys, "identify", log, "--chain", chain, "--masses", "2")
    assert "--masses 2" in line and f"--chain {chain} holds 1" in line


def test_a_sidecar_unit_that_is_not_si_asks_for_its_scale(capsys, tmp_path) -> None:
    log = small_log(tmp_path)
    (tmp_path / "drive.units.json").write_text(json.dumps({"i_a": "mA"}))
    line = refused(capsys, "check", log)
    assert "says i_a is in 'mA'" in line and "--scale i_a=" in line
