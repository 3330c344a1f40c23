"""``ActionReactionController``: sensorless motion and vibration control as an FMI 2.0
co-simulation FMU.

Inputs are the target of the controlled mass and the motor's measured current,
velocity and angle at t_k (the observer's timing contract, docs/method.md); after
``doStep(t_k, h)`` the output ``i_ref`` is the current to hold over [t_k, t_k + h]: a
sequential master steps the controller, then the plant with that command (zero delay);
a parallel master applies it one step later, which the design tolerates with the same
gains. The gains are computed at initialization from the chain and the goals
(:mod:`arcosim.fmu.flexchain.control.design`); all algorithms live in
:mod:`flexchain`, this class maps FMU variables to them.
"""

from __future__ import annotations

from typing import ClassVar

from ..flexchain import defaults
from ..flexchain.control.controller import MotionController
from ..flexchain.control.design import MOVE_BANDWIDTH_PRODUCT, design_controller, goals
from ..fmukit import FmuSlave, Variable, array, indexed, inp, out, par, range_problems
from ..fmukit.checks import chain_rate_problems


class ActionReactionController(FmuSlave):
    """Moves a load mass to a target and damps the chain, from current and encoder only."""

    model_text: ClassVar[str] = (
        "Sensorless motion and vibration control of a motor driving n masses on springs: "
        "moves a chosen load mass to theta_ref along a shaped path and actively damps every "
        "mode, from the motor's current and encoder only (state feedback on the "
        "action-reaction observer's model-based estimates, with its load-torque state)."
    )

    @classmethod
    def declare(cls) -> list[Variable]:
        n = cls.n_masses
        J = defaults.inertias(n)
        return [
            inp(
                "theta_ref",
                0.0,
                "rad",
                "Target of the controlled mass; a change starts a shaped point-to-point move",
            ),
            inp("i_a", 0.0, "A", "Measured motor current: the mean over the step ending at t_k"),
            inp(
                "omega_m",
                0.0,
                "rad/s",
                "Measured motor velocity at t_k (unused with encoder_cpr > 0 and f_c > 0)",
            ),
            inp("theta_m", 0.0, "rad", "Measured motor angle at t_k"),
            par("J_mo", defaults.J_M, "kg.m2", "Motor inertia (nominal)"),
            par("k_to", defaults.K_T, "N.m/A", "Torque constant (nominal)"),
            par("D_m", defaults.D_M, "N.m.s/rad", "Motor viscous friction"),
            par("f_c", defaults.F_C, "N.m", "Motor Coulomb friction (cancelled by the controller)"),
            *array(par, "J", J, "kg.m2", lambda i: f"Inertia of load mass {i}"),
            *array(par, "k", [defaults.K] * n, "N.m/rad", lambda i: f"Stiffness of spring {i}"),
            *array(par, "B", [defaults.B] * n, "N.m.s/rad", lambda i: f"Damping of spring {i}"),
            par(
                "encoder_cpr",
                defaults.ENCODER_CPR,
                "",
                "Counts per revolution of the motor encoder (0 = angle not quantized); the "
                "estimates take the angle at the middle of its count",
            ),
            par(
                "g_dist",
                defaults.G_DIST,
                "rad/s",
                "Bandwidth of the disturbance observer G(s) = g/(s+g) behind the estimates",
            ),
            par("control_mass", n, "", f"The load mass moved to theta_ref, 1 … {n}"),
            par("i_max", defaults.I_MAX, "A", "Current limit of i_ref (with anti-windup)"),
            par(
                "bandwidth",
                defaults.BANDWIDTH,
                "rad/s",
                "Feedback bandwidth; 0 = set by move_time (exactly one of the two > 0; "
                f"bandwidth * move_time = {MOVE_BANDWIDTH_PRODUCT:g})",
            ),
            par(
                "move_time",
                defaults.MOVE_TIME,
                "s",
                "Duration of a shaped move; 0 = set by bandwidth (exactly one of the two > 0)",
            ),
            par(
                "hold_dither",
                defaults.HOLD_DITHER,
                "1",
                "Dither at rest, in encoder counts peak to peak of the motor (0 = off): a "
                "square current at about 125 Hz from half a move time after a move, so that "
                "the encoder tells where the motor sits inside its count",
            ),
            out("i_ref", "A", "Current command to hold over the step that starts at t_k"),
            out("theta_hat_ctrl", "rad", "Estimated angle of the controlled mass at t_k"),
            out("i_ff", "A", "Feedforward part of i_ref (the reference model's current)"),
            out(
                "i_fb",
                "A",
                "Feedback part of i_ref, before the limit (friction and the hold's dither "
                "included)",
            ),
        ]

    def check_parameters(self) -> list[str]:
        n = self.n_masses
        v = self.value
        problems = range_problems(
            v,
            positive=["J_mo", "k_to", "g_dist", "i_max", *indexed("J", n), *indexed("k", n)],
            non_negative=[
                "D_m",
                "f_c",
                "encoder_cpr",
                "bandwidth",
                "move_time",
                "hold_dither",
                *indexed("B", n),
            ],
        )
        if not 1 <= v("control_mass") <= n:
            problems.append(
                f"parameter control_mass = {v('control_mass')} is not allowed (use a load "
                f"mass 1 to {n})"
            )
        if not problems:
            try:
                goals(v("move_time"), v("bandwidth"))
            except ValueError as error:
                problems.append(str(error))
        if not problems:
            problems += chain_rate_problems(
                v, "J_mo", indexed("J", n), indexed("k", n), indexed("B", n)
            )
        return problems

    def parameters(self) -> dict[str, float]:
        """The chain under the observer's names, as the design takes it."""
        n = self.n_masses
        names = ["J_mo", "k_to", "D_m", "f_c", "g_dist", "encoder_cpr"]
        names += [*indexed("J", n), *indexed("k", n), *indexed("B", n)]
        return {name: self.value(name) for name in names}

    def initialize(self) -> None:
        v = self.value
        design = design_controller(
            self.parameters(),
            h=self.experiment[2],
            control_mass=v("control_mass"),
            move_time=v("move_time"),
            bandwidth=v("bandwidth"),
            i_max=v("i_max"),
            hold_dither=v("hold_dither"),
        )
        self.controller = MotionController(design)
        self.controller.reset(v("theta_m"))
        self.hot = tuple(self.indices(["theta_ref", "i_a", "omega_m", "theta_m"]))
        self.outs = tuple(self.indices(["i_ref", "theta_hat_ctrl", "i_ff", "i_fb"]))
        out_v = self.v
        out_v[self.outs[0]] = out_v[self.outs[2]] = out_v[self.outs[3]] = 0.0
        out_v[self.outs[1]] = self.controller.theta_hat_ctrl

    def step(self, t: float, h: float) -> None:
        v = self.v
        ref, i_a, omega, theta = self.hot
        ctrl = self.controller
        i_ref = ctrl.step(h, v[ref], v[i_a], v[omega], v[theta])
        o_ref, o_theta, o_ff, o_fb = self.outs
        v[o_ref] = i_ref
        v[o_theta] = ctrl.theta_hat_ctrl
        v[o_ff] = ctrl.i_ff
        v[o_fb] = ctrl.i_fb
