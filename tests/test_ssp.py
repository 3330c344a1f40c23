"""The SSP system: written by the build, read back, run by `arcosim ssp`."""

from __future__ import annotations

import tempfile

import pytest

from arcosim.build.ssp import BENCH, CONNECTIONS
from arcosim.cli import main
from arcosim.errors import UserError
from arcosim.host.ssp import read_ssp, run_ssp


def test_build_writes_an_ssp_with_connections_and_the_bench_set(build_fmus) -> None:
    system = read_ssp(build_fmus(3) / "ActionReaction.ssp")
    try:
        assert set(system.components) == {"source", "plant", "observer"}
        assert all(path.is_file() for path in system.components.values())
        assert system.connections == list(CONNECTIONS)
        assert system.parameter_sets["bench"]["observer"] == BENCH["observer"]
        assert system.stop == 10.0
    finally:
        system.folder.cleanup()


def test_run_ssp_applies_the_parameter_set(build_fmus) -> None:
    recording = run_ssp(build_fmus(3) / "ActionReaction.ssp", "bench", stop=0.2)
    assert len(recording.time) == 201
    assert recording["observer.theta_hat[1]"][-1] != 0.0  # mode 2 from the set
    assert abs(recording["source.i_ref"][50]) > 0.0  # the multi-sine from the set


def test_unknown_parameter_set_is_named(build_fmus) -> None:
    with pytest.raises(UserError, match="no parameter set 'lab'"):
        run_ssp(build_fmus(3) / "ActionReaction.ssp", "lab", stop=0.01)


@pytest.mark.parametrize(
    "parameter_set, stop, h, said",
    [
        ("lab", 0.01, 1e-3, "no parameter set"),
        ("bench", -1.0, 1e-3, "stop time"),
        ("bench", 0.01, 1.0, "steps"),
    ],
)
def test_a_refused_run_leaves_no_unpacked_ssp_behind(
    build_fmus, tmp_path, monkeypatch, parameter_set, stop, h, said
) -> None:
    ssp = build_fmus(3) / "ActionReaction.ssp"
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    try:
        run_ssp(ssp, parameter_set, stop=stop, h=h)
    except UserError as error:
        assert said in str(error)
        # checked while the error (and the runner's frame) is alive: the runner removed
        # the folder itself, not the garbage collector after it
        assert not list(tmp_path.glob("arcosim_ssp_*"))
    else:
        pytest.fail("the run was not refused")


def test_arcosim_ssp_command(build_fmus, tmp_path, capsys) -> None:
    out = tmp_path / "ssp.csv"
    assert (
        main(
            ["ssp", str(build_fmus(3) / "ActionReaction.ssp"), "--stop", "0.05", "--out", str(out)]
        )
        == 0
    )
    assert "50 steps" in capsys.readouterr().out
    assert out.read_text().splitlines()[0].startswith("time,source.i_ref")


def test_a_refused_step_names_the_component_and_its_log(build_fmus, monkeypatch) -> None:
    """As the other hosts say it (``stepping.check_status``): the component, its FMU, the
    time and the FMU's last log lines as text, not a Python list."""
    from arcosim.host.instance import FmuInstance

    step = FmuInstance.do_step

    def refusing(self, t: float, h: float) -> int:
        if "Observer" in self.path.name and t >= 0.005:
            self.messages.append("observer: [fmi2Error] the step went wrong")
            return 3  # fmi2Error
        return step(self, t, h)

    monkeypatch.setattr(FmuInstance, "do_step", refusing)
    with pytest.raises(UserError) as error:
        run_ssp(build_fmus(3) / "ActionReaction.ssp", "bench", stop=0.02)
    said = str(error.value)
    assert said.startswith("observer (") and "refused the step at t = 0.005 s" in said
    assert "the step went wrong" in said and "['" not in said
