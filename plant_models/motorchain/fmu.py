"""``MotorChainPlant``: the FMI 2.0 co-simulation plant of a motor driving n masses.

The build (``arcosim build --masses N``) generates a tiny script that fixes
``n_masses`` and gives the class a model identifier carrying n
(``MotorChainPlant_n3``), so plants for several n load in one process.
"""

from __future__ import annotations

from typing import ClassVar

from ...fmu.flexchain import defaults
from ...fmu.flexchain.noise import gaussian, quantize
from ...fmu.fmukit import FmuSlave, Variable, array, indexed, inp, out, par, range_problems
from ...fmu.fmukit.checks import chain_rate_problems
from .physics import PlantPhysics


class MotorChainPlant(FmuSlave):
    """Motor, n load masses joined by springs, an encoder and a current sensor."""

    model_text: ClassVar[str] = (
        "Motor driving a chain of n inertias joined by springs (Khalil & Sabanovic bench "
        "by default), with an incremental encoder and a noisy current sensor. Outputs "
        "follow the timing contract: after doStep(t, h) they are the sample at t + h, "
        "whose current is the one that acted over [t, t + h]."
    )

    @classmethod
    def declare(cls) -> list[Variable]:
        n = cls.n_masses
        J = defaults.inertias(n)
        v: list[Variable] = [
            inp("i_ref", 0.0, "A", "Current command; held over each communication step"),
            *array(inp, "tau_ext", [0.0] * n, "N.m", lambda i: f"External torque on load mass {i}"),
            par("J_m", defaults.J_M, "kg.m2", "Motor (rotor) inertia"),
            par("k_t", defaults.K_T, "N.m/A", "Motor torque constant"),
            par("D_m", defaults.D_M, "N.m.s/rad", "Motor viscous friction coefficient"),
            par(
                "f_c",
                defaults.F_C,
                "N.m",
                "Motor Coulomb friction; the motor sticks while |drive torque| <= f_c",
            ),
            *array(par, "J", J, "kg.m2", lambda i: f"Inertia of load mass {i}"),
            *array(
                par,
                "k",
                [defaults.K] * n,
                "N.m/rad",
                lambda i: f"Stiffness of spring {i} (mass {i - 1} to {i})",
            ),
            *array(
                par,
                "B",
                [defaults.B] * n,
                "N.m.s/rad",
                lambda i: f"Damping of spring {i} (mass {i - 1} to {i})",
            ),
            par(
                "attached",
                True,
                "",
                "Load attached; false decouples spring 1 so the motor runs free "
                "(actuator self-identification)",
            ),
            par(
                "encoder_cpr",
                defaults.ENCODER_CPR,
                "",
                "Encoder counts per revolution after quadrature (0 = ideal: exact angle "
                "and true velocity)",
            ),
            par(
                "i_noise_std",
                defaults.I_NOISE_STD,
                "A",
                "Standard deviation of the current sensor noise",
            ),
            par("seed", 1, "", "Seed of the current-noise sequence (same seed, same noise)"),
            par(
                "current_bandwidth",
                0.0,
                "rad/s",
                "Bandwidth of the first-order current loop (0 = ideal: i = i_ref)",
            ),
            out("i_a", "A", "Measured current: mean over the step just finished, plus noise"),
            out("theta_m", "rad", "Measured motor angle (encoder, floored to whole counts)"),
            out(
                "omega_m",
                "rad/s",
                "Measured motor velocity: backward difference of theta_m over the step "
                "(true velocity when encoder_cpr = 0)",
            ),
            out("theta_m_true", "rad", "True motor angle (verification only)"),
            out("omega_m_true", "rad/s", "True motor velocity (verification only)"),
            *array(
                out, "theta", n, "rad", lambda i: f"True angle of load mass {i} (verification only)"
            ),
            *array(
                out,
                "omega",
                n,
                "rad/s",
                lambda i: f"True velocity of load mass {i} (verification only)",
            ),
            out(
                "tau_reac",
                "N.m",
                "True reaction torque tau_1 = k_1 (theta_m - theta_1) + B_1 (omega_m - omega_1)",
            ),
            out(
                "tau_reac_mean",
                "N.m",
                "True reaction torque averaged over the step just finished",
            ),
            out("i_true", "A", "True current averaged over the step just finished"),
            out("twist", "rad", "True deflection of spring 1: theta_m - theta_1"),
        ]
        return v

    # -- parameters ------------------------------------------------------------------

    def check_parameters(self) -> list[str]:
        n = self.n_masses
        problems = range_problems(
            self.value,
            positive=["J_m", *indexed("J", n)],
            non_negative=[
                "D_m",
                "f_c",
                *indexed("k", n),
                *indexed("B", n),
                "i_noise_std",
                "current_bandwidth",
            ],
            finite=["k_t"],
        )
        if self.value("encoder_cpr") < 0:
            problems.append(
                f"parameter encoder_cpr = {self.value('encoder_cpr')} must be >= 0 (0 = ideal)"
            )
        if not problems:
            motor = "J_m" if self.value("attached") else None
            problems += chain_rate_problems(
                self.value, motor, indexed("J", n), indexed("k", n), indexed("B", n)
            )
        return problems

    def initialize(self) -> None:
        n = self.n_masses
        self.physics = PlantPhysics(
            J_m=self.value("J_m"),
            k_t=self.value("k_t"),
            D_m=self.value("D_m"),
            f_c=self.value("f_c"),
            J=self.values(indexed("J", n)),
            k=self.values(indexed("k", n)),
            B=self.values(indexed("B", n)),
            attached=bool(self.value("attached")),
            current_bandwidth=self.value("current_bandwidth"),
        )
        self.cpr = int(self.value("encoder_cpr"))
        self.noise_std = float(self.value("i_noise_std"))
        self.seed = int(self.value("seed"))
        self.sample = 0
        self.theta_measured = quantize(0.0, self.cpr)
        self.in_i_ref = self.vr["i_ref"]
        self.in_tau_ext = self.indices(indexed("tau_ext", n))
        self.out_theta = self.indices(indexed("theta", n))
        self.out_omega = self.indices(indexed("omega", n))
        self._write_outputs(h=None)

    # -- stepping --------------------------------------------------------------------

    def step(self, t: float, h: float) -> None:
        v = self.v
        self.physics.advance(h, v[self.in_i_ref], [v[i] for i in self.in_tau_ext])
        self.sample += 1
        self._write_outputs(h)

    def _write_outputs(self, h: float | None) -> None:
        v, vr, p = self.v, self.vr, self.physics
        x, n = p.x, self.n_masses
        theta_q = quantize(x[0], self.cpr)
        if h is None:  # the sample at t0: no step has acted yet
            i_true, omega_q, tau_mean = 0.0, x[n + 1], p.reaction_torque()
        else:
            i_true = p.step_average_current(h)
            omega_q = (theta_q - self.theta_measured) / h if self.cpr > 0 else x[n + 1]
            tau_mean = p.step_average_reaction(h)
        noise = self.noise_std * gaussian(self.seed, self.sample) if h is not None else 0.0
        self.theta_measured = theta_q
        v[vr["i_a"]] = i_true + noise
        v[vr["theta_m"]] = theta_q
        v[vr["omega_m"]] = omega_q
        v[vr["theta_m_true"]] = x[0]
        v[vr["omega_m_true"]] = x[n + 1]
        for j, i in enumerate(self.out_theta, start=1):
            v[i] = x[j]
        for j, i in enumerate(self.out_omega, start=1):
            v[i] = x[n + 1 + j]
        v[vr["tau_reac"]] = p.reaction_torque()
        v[vr["tau_reac_mean"]] = tau_mean
        v[vr["i_true"]] = i_true
        v[vr["twist"]] = x[0] - x[1]
