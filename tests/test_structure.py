"""Structure chosen by evidence: the rigid drive (n = 0), the selection rule on
the final fit, parameters at a bound, and decisions that do not flip when the user
restates a value the tool fitted. The independent simulator
(:mod:`benchmarks.simulators.field_sim`) writes every log."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.fmu.flexchain import defaults
from arcosim.identification.drive_identification import identify_drive
from arcosim.identification.errors import IdentificationError
from benchmarks.simulators import field_sim
from tests.field_runs import identify_log

LINES = np.geomspace(3.0, 150.0, 40)
#: A ball-screw axis: the table's inertia rigidly on the motor, no mode in the band.
J_LOAD = 6e-4


def rigid(**kw) -> field_sim.Drive:
    base = dict(J_m=defaults.J_M + J_LOAD, k_t=defaults.K_T, D_m=defaults.D_M, f_c=defaults.F_C)
    base.update(J=(), k=(), B=(), current_noise=0.005)
    base.update(kw)
    return field_sim.Drive(**base)


def identify(d: field_sim.Drive, log: field_sim.Log, friction_given=False, **kw):
    return identify_log(d, log, friction_given, J_m=defaults.J_M, **kw)


@pytest.fixture(scope="module")
def rigid_log() -> tuple[field_sim.Drive, field_sim.Log]:
    d = rigid()
    return d, field_sim.simulate(d, 1e-3, 10.0, current=field_sim.multisine(LINES, 3.0))


def test_a_rigid_drive_is_n_0_with_its_load_inertia_and_friction(rigid_log) -> None:
    """auto includes n = 0: no refusal "excite every mode"; J_total − J_m within 0.5 %,
    f_c within 5 % (its 2σ: the test below)."""
    d, log = rigid_log
    result = identify(d, log)
    assert result.masses == 0
    values, std = result.parameters, result.std
    assert values["J_load"] == pytest.approx(J_LOAD, rel=5e-3) and std["J_load"] > 0
    bounds = result.report()["bounds"]
    assert "f_c" not in bounds and values["f_c"] == pytest.approx(d.f_c, rel=0.05)
    # the observer takes the load as motor inertia (no chain to estimate)
    assert result.observer_parameters()["dJm"] == values["J_load"]


@pytest.mark.xfail(
    strict=True,
    reason="measured on this 10 s record: the rule leaves D_m out (Coulomb only), its "
    "bound 1.55e-5 < 2e-5 and f_c +2.6 % ± 1.2 %; the fit of both reads D_m 1.0e-5 ± "
    "2.8e-6: the friction's sign in slow slides and stops is still biased (on the 20 s "
    "benchmark row the reversals' lag is gone and J_load is unbiased); open",
)
def test_the_rigid_drive_friction_is_covered(rigid_log) -> None:
    """D_m and f_c within 2σ, or the truth inside the bound reported."""
    d, log = rigid_log
    result = identify(d, log)
    bounds, values, std = result.report()["bounds"], result.parameters, result.std
    for name, truth in (("D_m", d.D_m), ("f_c", d.f_c)):
        if name in bounds:
            assert truth <= bounds[name], name
        else:
            assert abs(values[name] - truth) <= 2 * std[name], name


def test_masses_0_is_accepted(rigid_log) -> None:
    d, log = rigid_log
    result = identify(d, log, friction_given=True, masses=0)
    assert result.masses == 0 and "J_load" in result.report()


def test_masses_below_0_are_refused(rigid_log) -> None:
    d, log = rigid_log
    with pytest.raises(IdentificationError, match="≥ 0"):
        identify(d, log, masses=-1)


THREE = dict(J=(3e-4, 5e-4, 4e-4), k=(0.25, 0.4, 0.15), B=(1.2e-5, 1.5e-5, 6e-6))


def chain(**kw) -> field_sim.Drive:
    base = dict(J_m=defaults.J_M, k_t=defaults.K_T, D_m=defaults.D_M, f_c=defaults.F_C)
    base.update(THREE, current_noise=0.005)
    base.update(kw)
    return field_sim.Drive(**base)


@pytest.mark.slow
def test_restating_the_fitted_friction_never_changes_the_decision() -> None:
    """The flexible link's flip: accepted with the friction fitted, refused when the
    user passed back the D_m, f_c the tool fitted. Here: the same n either way, and the
    friction form and the candidates' scores in the report."""
    d = chain()
    log = field_sim.simulate(d, 1e-3, 10.0, current=field_sim.multisine(LINES, 3.0))
    fitted = identify_drive(
        log.time, log.i_a, log.omega_m, log.theta_m, k_t=d.k_t, J_m=d.J_m, encoder_cpr=d.counts
    )
    friction = {k: fitted.parameters[k] for k in ("D_m", "f_c") if k in fitted.parameters}
    friction = {"D_m": 0.0, "f_c": 0.0} | friction
    restated = identify_drive(
        log.time,
        log.i_a,
        log.omega_m,
        log.theta_m,
        k_t=d.k_t,
        J_m=d.J_m,
        encoder_cpr=d.counts,
        **friction,
    )
    assert fitted.masses == restated.masses == 3
    selection = fitted.report()["selection"]
    assert set(selection["friction"]["candidates"]) == {"none", "viscous", "coulomb", "both"}
    assert "BIC on the effective sample count" in selection["rule"]
    np.testing.assert_allclose([restated.parameters[f"k[{i}]"] for i in (1, 2, 3)], d.k, rtol=5e-3)


def test_a_rigid_drive_chain_file_says_what_the_observer_takes(tmp_path) -> None:
    """A rigid drive's report has no chain: reading it as one names the --set that
    gives the observer its load (dJm = J_load) instead of "must be 1 to 20"."""
    import json

    from arcosim.chainfile import ChainFileError, read_chain

    path = tmp_path / "rigid.json"
    path.write_text(json.dumps({"masses": 0, "J_load": 6e-4, "D_m": 2e-5, "f_c": 2e-3}))
    with pytest.raises(ChainFileError, match=r"rigid drive.*--set dJm=0\.0006"):
        read_chain(path)


@pytest.mark.parametrize(
    ("report", "named"),
    [
        ({"k_hat": 0.126, "B_hat": 1.2e-4, "method": "output-error"}, r"output-error report"),
        ({"D_m": 2e-5}, r"no J\[1\], k\[1\], B\[1\]"),
    ],
)
def test_a_report_without_a_chain_names_the_whole_chain_fit(tmp_path, report, named) -> None:
    """An output-error report (the uniform chain's k_hat, B_hat) or any file with no
    J[i] is not a chain of 0 masses: the message names the file's kind and the fit that
    writes a chain, not "--masses 0: must be 1 to 20"."""
    import json

    from arcosim.chainfile import ChainFileError, read_chain

    path = tmp_path / "oe.json"
    path.write_text(json.dumps(report))
    with pytest.raises(ChainFileError, match=named) as caught:
        read_chain(path)
    message = str(caught.value)
    assert "--method whole-chain --out" in message
    assert "--masses 0" not in message


@pytest.mark.slow
def test_the_rigid_drives_printed_next_step_runs(rigid_log, fmus, tmp_path, capsys) -> None:
    """identify prints the observer's settings for the drive it found as the next step; for
    a rigid drive (n = 0) that step must run as printed, not be refused."""
    import shlex

    from arcosim.cli import main
    from arcosim.logs import write_csv

    d, log = rigid_log
    path = write_csv(
        tmp_path / "rigid.csv",
        {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m},
    )
    motor = ["--set", f"k_to={d.k_t!r}", "--set", f"J_mo={defaults.J_M!r}"]
    motor += ["--set", f"encoder_cpr={d.counts}"]
    assert main(["identify", str(path), "--method", "whole-chain", *motor]) == 0
    out = capsys.readouterr().out
    assert "(0 masses)" in out
    step = out.strip().splitlines()[-1].split(": ", 1)[1]
    assert "dJm=" in step
    code = main(["identify", str(path), "--fmus", str(fmus), *motor, *shlex.split(step)])
    assert code == 0, capsys.readouterr().err
