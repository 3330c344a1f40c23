"""Serialized FMU states and status answers, alike on the three FMUs.

Each FMU is probed in its own process (tests/hosts/state_probe.py), so a crash shows
as the process dying: truncated bytes, random bytes, ``{}``, a flipped byte, another
FMU's state (the plant's; the n = 5 observer's for the n = 3 observer) and no bytes
are refused with fmi2Error and a message, and the instance then steps, terminates and
frees. fmi2GetBooleanStatus(fmi2Terminated): false after a refused step (the state is
unchanged, the master may retry), true once the parameters were refused at
exitInitializationMode, which returns fmi2Error.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.system

PROBE = Path(__file__).parent / "hosts" / "state_probe.py"
FMI_ERROR, FMI_DISCARD = 3, 2

#: FMU, the FMU whose state it is offered, a parameter that must be > 0
CASES = {
    "observer": ("ReactionTorqueObserver", 5, "ReactionTorqueObserver", "J_mo"),
    "source": ("ExcitationSource", 3, "MotorChainPlant", "frequency"),
    "plant": ("MotorChainPlant", 3, "ReactionTorqueObserver", "J_m"),
}


def probe(build_fmus, tmp_path: Path, case: str) -> dict:
    name, other_n, other, parameter = CASES[case]
    out = tmp_path / "probe.json"
    result = subprocess.run(
        [
            sys.executable,
            str(PROBE),
            str(build_fmus(3) / f"{name}.fmu"),
            str(build_fmus(other_n) / f"{other}.fmu"),
            str(out),
            json.dumps([parameter]),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-3000:]}"
    return json.loads(out.read_text())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
@pytest.mark.parametrize("case", list(CASES))
def test_bad_states_are_refused_and_the_instance_stays_usable(build_fmus, tmp_path, case):
    report = probe(build_fmus, tmp_path, case)
    for kind, result in report["states"].items():
        if kind == "good":
            assert result["step"] == 0
            continue
        assert result["status"] == FMI_ERROR, (kind, result)
        assert result["log"], f"{kind}: refused without a message"
        assert result["step"] == 0, f"{kind}: the instance did not step after the refusal"
    assert report["freed"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
@pytest.mark.parametrize("case", list(CASES))
def test_terminated_and_refused_parameters_answer_alike(build_fmus, tmp_path, case):
    report = probe(build_fmus, tmp_path, case)
    assert report["terminated_at_start"] == [0, False]
    assert report["bad_step"] == FMI_DISCARD
    assert report["terminated_after_refused_step"] == [0, False]
    bad = report["bad_parameters"]
    assert bad["exit_status"] == FMI_ERROR
    assert bad["terminated"] == [0, True]
    assert bad["step"] == FMI_DISCARD
    assert bad["terminated_after_step"] == [0, True]
