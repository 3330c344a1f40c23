"""The sensorless loop's poles, from the controller's and the plant's own code
(:mod:`arcosim.control.sensorless_loop`: an exact encoder, no Coulomb friction, so the loop
is linear, differentiated by finite differences), on the chains of
``benchmarks/control_margins.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.control.model_errors import corners
from arcosim.control.sensorless_loop import sensorless_decay, sensorless_jacobian, sensorless_loop
from arcosim.fmu.flexchain import defaults
from benchmarks.control_margins import CHAINS, H, params

#: How near the plant the refit takes a 10 % wrong model on every J_i and k_i (in log):
#: the linear loop's move is noise-free and the chain model holds the plant, so only the
#: prior (REFINE_MASS_SPREAD, 7.5 %, about common factors that the move pins) keeps the
#: fit off the plant: a tenth of the model's error.
REFIT_TOLERANCE = 0.01
#: The test ids (ASCII) → the corners' names (:func:`arcosim.control.model_errors.corners`).
CORNERS = {"J +10 %, k -10 %": "J +10 %, k −10 %", "J -10 %, k +10 %": "J −10 %, k +10 %"}


def test_an_exact_model_puts_the_state_feedbacks_poles_in_the_loop() -> None:
    """Separation: with the model exact, the loop's poles are the state feedback's
    (eig(F − g K)) and the estimator's; the finite differences (relative step 1e-6 on a
    linear map) leave each within 1e-6 of its own."""
    chain = params(CHAINS["bench, two masses"])
    loop = sensorless_loop(chain, chain, h=H)
    design = loop.controller.design
    feedback = np.linalg.eigvals(np.array(design.F) - np.outer(design.g, design.K))
    poles = np.linalg.eigvals(sensorless_jacobian(loop))
    assert len(poles) > len(feedback)
    assert max(np.abs(poles - pole).min() for pole in feedback) < 1e-6


CASES = [
    pytest.param(name, corner, id=f"{name}, {corner}") for name in CHAINS for corner in CORNERS
]


@pytest.mark.slow
@pytest.mark.parametrize("hold", [False, True], ids=["moving", "hold"])
@pytest.mark.parametrize(("name", "corner"), CASES)
def test_the_sensorless_loop_is_stable_with_the_model_ten_percent_off(
    name: str, corner: str, hold: bool
) -> None:
    """Every pole of the sensorless loop inside the unit circle (a decay > 0) with the
    model's J all 10 % off one way and its k the other; also at rest with the hold's
    dither running (its observer's angle and velocity fed back). On the wrong model
    alone (``without={"move_refit"}``) the five-mass J +10 %, k −10 % corner grew at
    its top modes, where the estimator rang; the move's refit takes the model back to
    the chain."""
    chain = params(CHAINS[name])
    error = next(e for e in corners(CHAINS[name].n) if e.name == CORNERS[corner])
    decay, _ = sensorless_decay(chain, error.apply(chain), h=H, hold=hold)
    assert decay > 0.0


def test_the_hold_is_linearized_with_its_dither_running_and_decays_on_the_exact_model() -> None:
    """hold=True: the dither runs at the linearized state, the dither's own path is not
    a state (no pole at 1 from it), and with the model exact every pole decays."""
    chain = params(CHAINS["bench, two masses"])
    loop = sensorless_loop(chain, chain, h=H, hold=True)
    assert loop.controller.dither is not None
    poles = np.linalg.eigvals(sensorless_jacobian(loop))
    assert np.abs(poles).max() < 1.0 - 1e-4


@pytest.mark.parametrize(
    "factors",
    [(1.0, 1.0), (1.1, 0.9), (0.9, 1.1)],
    ids=["model exact", "J +10 %, k -10 %", "J -10 %, k +10 %"],
)
def test_the_move_refits_the_model_to_the_chain(factors) -> None:
    """The controller designed on the five-mass chain with every J × a and every k × b
    (whose top modes the wrong model failed): over one move of the linear loop the
    estimator's chain is refitted to the plant, within REFIT_TOLERANCE on every J_i and
    k_i; the exact model predicts the move within the noise and is kept as it is."""
    chain = params(CHAINS["five masses"])
    scale = {"J[": factors[0], "k[": factors[1]}
    model = {key: v * scale.get(key[:2], 1.0) for key, v in chain.items()}
    estimator = sensorless_loop(chain, model, h=H).controller.estimator
    found = estimator.filter
    truth = [chain[f"{name}[{i}]"] for name in ("J", "k") for i in range(1, len(found.J) + 1)]
    if factors == (1.0, 1.0):
        assert not estimator.refined and list(found.J + found.k) == truth
        return
    assert estimator.refined
    assert np.abs(np.log(np.array(found.J + found.k) / truth)).max() < REFIT_TOLERANCE


def test_at_rest_the_estimator_runs_the_holds_gain_until_the_next_move() -> None:
    """Once the hold has kept the controlled mass near its target, the estimator runs the
    hold's gain (unmodelled torque × HOLD_TORQUE_NOISE_SCALE: it corrects less from
    τ̂_reac); a new target gives back the move's gain, the one designed at the start, bit
    for bit, and the estimates carry on from where they were."""
    chain = params(CHAINS["bench, two masses"])
    loop = sensorless_loop(chain, chain, h=H, hold=True)
    controller = loop.controller
    estimator = controller.estimator
    assert estimator.quiet
    est = estimator.filter
    hold_gain = np.array(est.model(H).K)
    scale = est.noise.torque_noise_std / estimator.move_noise.torque_noise_std
    assert scale == pytest.approx(defaults.HOLD_TORQUE_NOISE_SCALE, rel=1e-12)
    assert hold_gain.tolist() == list(est.design(H).K)  # designed on the scaled noise
    state = list(est.s)
    estimator.set_quiet(False)
    assert est.s == state  # the estimates carry on
    move_gain = np.array(est.model(H).K)
    assert move_gain.tolist() == list(est.design(H).K)
    assert np.linalg.norm(hold_gain) < np.linalg.norm(move_gain)
    estimator.set_quiet(True)
    controller.step(H, 2.0, *loop.signals[:3])  # a new target: a move starts
    assert not estimator.quiet
    assert np.array(est.model(H).K).tolist() == move_gain.tolist()
    estimator.set_quiet(True)
    assert np.array(est.model(H).K).tolist() == hold_gain.tolist()


def test_the_holds_gain_waits_for_the_mass_to_be_still_and_leaves_for_a_load_step() -> None:
    """RefinedEstimator.settle: the hold's gain after HOLD_QUIET_TIME within HOLD_QUIET_ANGLE
    of the target (not sooner, the clock restarting whenever the estimate strays), the
    move's back as soon as it is more than HOLD_QUIET_LEAVE off."""
    chain = params(CHAINS["bench, two masses"])
    estimator = sensorless_loop(chain, chain, h=H).controller.estimator
    near, far = 0.5 * defaults.HOLD_QUIET_ANGLE, 1.5 * defaults.HOLD_QUIET_LEAVE
    steps = round(defaults.HOLD_QUIET_TIME / H)
    for _ in range(steps - 2):
        estimator.settle(H, near)
    estimator.settle(H, 2.0 * defaults.HOLD_QUIET_ANGLE)  # strays: the clock restarts
    for _ in range(steps - 2):
        estimator.settle(H, near)
    assert not estimator.quiet
    for _ in range(3):
        estimator.settle(H, near)
    assert estimator.quiet
    estimator.settle(H, 0.5 * (defaults.HOLD_QUIET_ANGLE + defaults.HOLD_QUIET_LEAVE))
    assert estimator.quiet  # between the two: kept
    estimator.settle(H, far)
    assert not estimator.quiet


def test_the_jacobian_leaves_the_loop_as_it_was() -> None:
    """The copies it steps share the loop's designs (frozen) but change nothing of it:
    every float of the loop, and every design, is the same after as before."""
    from arcosim.control.sensorless_loop import _leaves

    chain = params(CHAINS["bench, two masses"])
    loop = sensorless_loop(chain, chain, h=H)
    paths = _leaves(loop, skip=frozenset())
    before = [_value(loop, p) for p in paths]
    est = loop.controller.estimator.filter
    models = dict(est._models)
    sensorless_jacobian(loop)
    assert [_value(loop, p) for p in paths] == before
    assert est._models == models and all(est._models[h] is models[h] for h in models)


def _value(root, path):
    for key in path:
        root = root[key] if isinstance(root, (dict, list)) else getattr(root, key)
    return root
