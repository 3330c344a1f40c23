"""The bank's reach diagnosis (``benchmarks/bank_reach.py``): its fixed member stays
fixed, its controller without d̂ feeds no load torque back, its counts are the table's."""

from __future__ import annotations

from arcosim.experiments.motion.experiment import sensorless
from arcosim.experiments.motion.findings import UPPER_BOUND_FACTOR
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.noise import quantize
from arcosim.plant.motorchain.physics import PlantPhysics
from benchmarks.bank_reach import WithoutLoadTorque, fixed, markdown
from tests.control_runs import ACTUATOR, BENCH_2, observer_params

H = 1e-3


def corner_params() -> dict[str, float]:
    """The bench's two-mass chain with every J +10 % and every k −10 %, as designed on."""
    J = tuple(1.1 * j for j in BENCH_2["J"])
    k = tuple(0.9 * x for x in BENCH_2["k"])
    params = observer_params(J, k, BENCH_2["B"], **ACTUATOR)
    return {**params, "encoder_cpr": defaults.ENCODER_CPR, "g_dist": defaults.G_DIST}


def picks(controller, stop: float = 2.0) -> list[tuple]:
    """The member the controller takes, and its model (J, k), at each sample of a 1 rad
    move of the bench's two-mass chain (the Python plant, a 2000-count encoder, no
    current noise)."""
    p = {**ACTUATOR, **BENCH_2}
    physics = PlantPhysics(p["J_m"], p["k_t"], p["D_m"], p["f_c"], p["J"], p["k"], p["B"])
    theta, omega, i_a, out = quantize(0.0, defaults.ENCODER_CPR), 0.0, 0.0, []
    for _ in range(round(stop / H)):
        command = controller.step(H, 1.0, i_a, omega, theta)
        chosen = controller.bank.chosen
        out.append((controller.bank.pick, chosen.J, chosen.k))
        physics.advance(H, command, [0.0, 0.0])
        i_a = physics.step_average_current(H)
        new = quantize(physics.x[0], defaults.ENCODER_CPR)
        omega, theta = (new - theta) / H, new
    return out


def test_fixed_member_is_kept_where_the_bank_would_move():
    params = corner_params()  # every J +10 %, every k −10 %: the bank moves off its model
    shipped = picks(sensorless(params))
    assert shipped[-1][1:] != shipped[0][1:]  # to another member, or refined (move_fit)
    kept = picks(fixed(params, 4))
    assert set(kept) == {kept[0]} and kept[0][0] == 4


def test_without_load_torque_feeds_none_back():
    shipped = sensorless(corner_params())
    without = WithoutLoadTorque(shipped.design)
    x = [0.0] * (2 * shipped.design.n + 2)
    # a load torque estimate changes the shipped command, not the diagnosis's
    assert shipped._command(H, shipped.theta0, list(x), 1e-3) != 0.0
    assert without._command(H, without.theta0, list(x), 1e-3) == 0.0


def test_counts_within_the_bound():
    rows = [
        dict(seed=0, model="identified", bound=1.0, shipped=1.2, chosen=(1.0, 1.0), best=1.2,
             best_member=(1.0, 1.0), without_d=1.4),
        dict(seed=0, model="random", bound=1.0, shipped=1.5, chosen=(1.0, 1.0),
             best=UPPER_BOUND_FACTOR, best_member=(0.93, 1.0), without_d=1.0),
    ]  # fmt: skip
    text = markdown(rows)
    assert "of 2: as shipped 1, the best fixed member 2, without d̂ 1." in text
    assert UPPER_BOUND_FACTOR == 1.3  # the controller's criterion
