"""``ReactionTorqueObserver``: the action-reaction observer as an FMI 2.0 co-simulation FMU.

Inputs are the motor's measured current, velocity and angle (timing contract of
docs/method.md: the sample at ``t + h`` when the master steps the plant first,
the sample at ``t`` with Jacobi ordering). All algorithms live in
:mod:`flexchain`; this class maps FMU variables to them.
"""

from __future__ import annotations

from typing import ClassVar

from ..flexchain import defaults
from ..flexchain.codes import Mode
from ..flexchain.dob import Actuator
from ..flexchain.least_squares import MIN_ROWS, RCOND_MIN
from ..flexchain.link_observer import StarLink
from ..flexchain.load_observer import SMOOTHING_RATIO
from ..flexchain.observer import Observer, ObserverSettings
from ..flexchain.self_identification import SETTLE
from ..fmukit import (
    FmuSlave,
    Variable,
    array,
    indexed,
    inp,
    out,
    par,
    range_problems,
)
from ..fmukit.checks import FASTEST_RATE, chain_rate_problems

#: Outputs of modes 0 and 1, solved from the normal equations only when read.
IDENTIFICATION_OUTPUTS = (
    "dkt_hat",
    "dJm_hat",
    "D_m_hat",
    "f_c_hat",
    "self_id_rank_deficient",
    "k_hat",
    "B_hat",
    "theta_rigid_hat",
    "id_valid",
)


class ReactionTorqueObserver(FmuSlave):
    """Disturbance and reaction torque observers, identification and state estimation."""

    model_text: ClassVar[str] = (
        "Action-reaction observer (Khalil & Sabanovic) for a motor driving n masses on "
        "springs, from the motor's current and encoder only: disturbance and reaction "
        "torque observers, actuator self-identification (mode 0), chain stiffness and "
        "damping from a rigid maneuver (mode 1), load angles (mode 2), the chain tracked in "
        "service with a drift alarm (mode 2, tracking = 1)."
    )

    @classmethod
    def declare(cls) -> list[Variable]:
        n = cls.n_masses
        J = defaults.inertias(n)
        return [
            inp(
                "i_a",
                0.0,
                "A",
                "Measured motor current: the mean over the step ending at the sample",
            ),
            inp("omega_m", 0.0, "rad/s", "Measured motor velocity at the sample"),
            inp("theta_m", 0.0, "rad", "Measured motor angle at the sample"),
            par(
                "mode",
                int(defaults.MODE),
                "",
                "0 = actuator self-identification (load detached), 1 = chain identification "
                "from a rigid maneuver, 2 = state estimation",
            ),
            par("J_mo", defaults.J_M, "kg.m2", "Nominal motor inertia"),
            par("k_to", defaults.K_T, "N.m/A", "Nominal torque constant"),
            par(
                "g_dist",
                defaults.G_DIST,
                "rad/s",
                "Bandwidth of the disturbance observer G(s) = g/(s+g)",
            ),
            par(
                "g_lpf",
                defaults.G_LPF,
                "rad/s",
                "Bandwidth of the filter on later stages of the recursion",
            ),
            par("dkt", 0.0, "N.m/A", "Torque-constant error k_t - k_to (result of mode 0)"),
            par("dJm", 0.0, "kg.m2", "Motor inertia error J_m - J_mo (result of mode 0)"),
            par("D_m", 0.0, "N.m.s/rad", "Motor viscous friction (result of mode 0)"),
            par("f_c", 0.0, "N.m", "Motor Coulomb friction (result of mode 0)"),
            *array(par, "J", J, "kg.m2", lambda i: f"Known inertia of load mass {i}"),
            *array(
                par,
                "k",
                [defaults.K] * n,
                "N.m/rad",
                lambda i: f"Stiffness of spring {i}, used in mode 2",
            ),
            *array(
                par,
                "B",
                [defaults.B] * n,
                "N.m.s/rad",
                lambda i: f"Damping of spring {i}, used in mode 2",
            ),
            par(
                "kappa_correction",
                defaults.KAPPA_CORRECTION,
                "",
                "Mode 1: multi-mass correction kappa (docs/method.md); false gives the "
                "paper's literal eq. 21",
            ),
            par(
                "estimator",
                int(defaults.ESTIMATOR),
                "",
                "Mode 2: 0 = the paper's recursion (eq. 22-26); 1 = model-based observer "
                "(chain model driven by theta_m, Kalman-corrected by tau_reac_hat)",
            ),
            par(
                "encoder_cpr",
                defaults.ENCODER_CPR,
                "",
                "Counts per revolution of the motor encoder (0 = angle not quantized). Mode 2 "
                "takes the angle at the middle of its count (+pi/cpr); estimator 1 designs its "
                "gain for the quantization noise 2*pi/cpr/sqrt(12) rad",
            ),
            par(
                "torque_noise_std",
                defaults.TORQUE_NOISE_STD,
                "N.m",
                "Estimator 1: unmodelled white torque on each load mass (Kalman design)",
            ),
            par(
                "tau_noise_std",
                defaults.TAU_NOISE_STD,
                "N.m",
                "Estimator 1: white noise on tau_reac_hat (Kalman design)",
            ),
            par(
                "load_mass",
                defaults.LOAD_MASS,
                "",
                "Estimator 1: 0 = off; i = also estimate the external torque on load mass i "
                "(one mass: constant torques on several masses show only as their sum)",
            ),
            par(
                "load_torque_bandwidth",
                defaults.LOAD_TORQUE_BANDWIDTH,
                "rad/s",
                "Estimator 1 with load_mass > 0: bandwidth of the load torque estimate "
                "(random-walk noise of the Kalman design; the output is smoothed by a "
                f"second-order low-pass at {SMOOTHING_RATIO:g} times it)",
            ),
            par(
                "omega_min",
                defaults.OMEGA_MIN,
                "rad/s",
                "Mode 0: speed below which the motor counts as stopped; such samples and the "
                f"{SETTLE:g}/g_dist + {SETTLE:g}/g_id s after them are left out of the fit",
            ),
            par(
                "g_id",
                defaults.G_ID,
                "rad/s",
                "Mode 0: bandwidth of an extra low-pass on the fit's target and regressors "
                "(reduces encoder noise in the acceleration); 0 = off",
            ),
            out("d_hat", "N.m", "Estimated disturbance d (eq. 9, DOB)"),
            out("tau_reac_hat", "N.m", "Estimated reaction torque (eq. 16)"),
            out("alpha_m_hat", "rad/s2", "Motor acceleration through G(s)"),
            out("dkt_hat", "N.m/A", "Mode 0: estimated k_t - k_to (0 when it had to be fixed)"),
            out("dJm_hat", "kg.m2", "Mode 0: estimated J_m - J_mo"),
            out("D_m_hat", "N.m.s/rad", "Mode 0: estimated motor viscous friction"),
            out("f_c_hat", "N.m", "Mode 0: estimated motor Coulomb friction"),
            out(
                "self_id_rank_deficient",
                "",
                "Mode 0: the fit cannot separate k_t from J_m (free motor: collinear "
                "regressors, or a fitted k_t outside [k_to/2, 2 k_to]), so k_t = k_to was fixed",
                "Boolean",
            ),
            out("k_hat", "N.m/rad", "Mode 1: estimated spring stiffness"),
            out("B_hat", "N.m.s/rad", "Mode 1: estimated spring damping"),
            out("theta_rigid_hat", "rad", "Mode 1: estimated rigid motion (eq. 20)"),
            *array(
                out, "theta_hat", n, "rad", lambda i: f"Mode 2: estimated angle of load mass {i}"
            ),
            *array(
                out,
                "omega_hat",
                n,
                "rad/s",
                lambda i: f"Mode 2: estimated velocity of load mass {i}",
            ),
            out(
                "tau_load_hat",
                "N.m",
                "Mode 2, estimator 1, load_mass > 0: estimated external torque on load mass "
                "load_mass (positive accelerates it, as the plant's tau_ext); 0 otherwise",
            ),
            out(
                "id_valid",
                "",
                f"Mode 0/1: the fit has at least {MIN_ROWS} samples and its scaled normal matrix a "
                f"reciprocal condition number >= {RCOND_MIN:g} (mode 1: and k_hat > 0)",
                "Boolean",
            ),
            *cls.link_variables(),
            *cls.tracking_variables(n),
        ]

    @staticmethod
    def tracking_variables(n: int) -> list[Variable]:
        """Tracking the chain in service (declared after the link's, so the earlier
        variables keep their value references)."""
        return [
            par(
                "tracking",
                defaults.TRACKING,
                "",
                "Mode 2 on a chain: 0 = off; 1 = track k, B, f_c and D_m while the drive "
                "works; theta_hat and omega_hat then come from the tracked chain (the "
                "model-based observer's predictor, whatever estimator says)",
            ),
            par(
                "tracking_time",
                defaults.TRACKING_TIME,
                "s",
                "Tracking: the memory (samples weigh exp(-age/tracking_time))",
            ),
            par(
                "drift_threshold",
                defaults.DRIFT_THRESHOLD,
                "1",
                "Tracking: the relative change from the commissioning value (J, k, B, f_c, "
                "D_m) that counts as drift",
            ),
            *array(out, "k_track", n, "N.m/rad", lambda i: f"Tracking: stiffness of spring {i}"),
            *array(
                out,
                "k_track_std",
                n,
                "N.m/rad",
                lambda i: f"Tracking: standard deviation of k_track[{i}]",
            ),
            *array(out, "B_track", n, "N.m.s/rad", lambda i: f"Tracking: damping of spring {i}"),
            *array(
                out,
                "B_track_std",
                n,
                "N.m.s/rad",
                lambda i: f"Tracking: standard deviation of B_track[{i}]",
            ),
            out("f_c_track", "N.m", "Tracking: motor Coulomb friction"),
            out("f_c_track_std", "N.m", "Tracking: standard deviation of f_c_track"),
            out("D_m_track", "N.m.s/rad", "Tracking: motor viscous friction"),
            out("D_m_track_std", "N.m.s/rad", "Tracking: standard deviation of D_m_track"),
            out(
                "drift_alarm",
                "",
                "Tracking: 1 while tracking_valid, after tracking_time, and a tracked "
                "parameter differs from its commissioning value by more than drift_threshold "
                "of it and 3 standard deviations",
                "Integer",
            ),
            out(
                "tracking_valid",
                "",
                "Tracking: 1 when the motion so far has taught every k and f_c (each one's "
                "variance at most a quarter of the prior's), 0 while it cannot tell them "
                "apart (e.g. at rest, or f_c at constant speed)",
                "Integer",
            ),
        ]

    @staticmethod
    def link_variables() -> list[Variable]:
        """The flexible link's modal model and the tip's estimates (declared last, so the
        chain's variables keep their value references)."""
        m = defaults.LINK_MODES_MAX
        return [
            par(
                "link_modes",
                defaults.LINK_MODES,
                "",
                f"Estimator 1: 0 = the chain of J, k, B; 1 to {m} = a flexible link's first "
                "hub-locked modes (omega_link, zeta_link, b_link, phi_tip, J_link_rigid, "
                "L_link, as arcosim identify --method beam reports them); theta_hat and "
                "omega_hat are then not written",
            ),
            *array(
                par,
                "omega_link",
                list(defaults.LINK_OMEGA),
                "rad/s",
                lambda i: f"Link mode {i}: hub-locked (clamped) frequency",
            ),
            *array(
                par,
                "zeta_link",
                list(defaults.LINK_ZETA),
                "1",
                lambda i: f"Link mode {i}: damping ratio",
            ),
            *array(
                par,
                "b_link",
                list(defaults.LINK_PARTICIPATION),
                "1",
                lambda i: (
                    f"Link mode {i}: hub participation b (sqrt(kg).m: kg.m per unit of "
                    "the mass-normalized modal coordinate; the mode's inertia on the hub is b^2)"
                ),
            ),
            *array(
                par,
                "phi_tip",
                list(defaults.LINK_TIP_SHAPE),
                "1",
                lambda i: (
                    f"Link mode {i}: tip shape value (m of tip deflection per unit of the "
                    "mass-normalized modal coordinate, 1/sqrt(kg))"
                ),
            ),
            par(
                "J_link_rigid",
                defaults.LINK_J_RIGID,
                "kg.m2",
                "The link's inertia outside its modes, rigid on the hub beyond J_mo",
            ),
            par("L_link", defaults.LINK_L, "m", "Link length: alpha_tip_hat = w_tip_hat / L_link"),
            out("w_tip_hat", "m", "link_modes > 0: estimated tip deflection; 0 otherwise"),
            out(
                "alpha_tip_hat",
                "rad",
                "link_modes > 0: estimated tip deflection angle w_tip_hat / L_link; 0 otherwise",
            ),
        ]

    def check_parameters(self) -> list[str]:
        n = self.n_masses
        problems = range_problems(
            self.value,
            positive=[
                "J_mo",
                "k_to",
                "g_dist",
                "g_lpf",
                *indexed("J", n),
                *indexed("k", n),
                "load_torque_bandwidth",
                "tracking_time",
                "drift_threshold",
            ],
            non_negative=[
                "D_m",
                "f_c",
                *indexed("B", n),
                "omega_min",
                "g_id",
                "encoder_cpr",
                "torque_noise_std",
                "tau_noise_std",
            ],
            finite=["dkt", "dJm"],
        )
        problems += self.link_problems()
        if self.value("tracking") not in (0, 1):
            problems.append(
                f"parameter tracking = {self.value('tracking')} is not allowed (use 0 = off, "
                "1 = track the chain)"
            )
        if not problems and self.value("J_mo") + self.value("dJm") <= 0.0:
            problems.append("parameters J_mo + dJm must be > 0 (the motor inertia)")
        chain = not self.value("link_modes")
        if not problems and chain and self.value("mode") == Mode.STATE_ESTIMATION:
            problems += chain_rate_problems(
                self.value, None, indexed("J", n), indexed("k", n), indexed("B", n)
            )
        # the observer's own rules; its noise levels only once every number is in range
        return problems + self.settings().problems(noise=not problems)

    def link_problems(self) -> list[str]:
        """The link's numbers out of range, one sentence each (none when link_modes = 0)."""
        m = self.value("link_modes")
        if not 0 <= m <= defaults.LINK_MODES_MAX:
            return [
                f"parameter link_modes = {m} is not allowed (use 0 = the chain, or 1 to "
                f"{defaults.LINK_MODES_MAX} link modes)"
            ]
        if not m:
            return []
        problems = range_problems(
            self.value,
            positive=[*indexed("omega_link", m), "L_link"],
            non_negative=[*indexed("zeta_link", m), "J_link_rigid"],
            finite=[*indexed("b_link", m), *indexed("phi_tip", m)],
        )
        problems += [
            f"parameter {name} = 0: a mode the hub does not move is not observable from it; "
            "lower link_modes"
            for name in indexed("b_link", m)
            if self.value(name) == 0.0
        ]
        if problems:
            return problems
        for w, z in zip(indexed("omega_link", m), indexed("zeta_link", m)):
            fastest = max(self.value(w), 2.0 * self.value(z) * self.value(w))  # rad/s, 1/s
            if fastest > FASTEST_RATE:
                problems.append(
                    f"parameters {w} = {self.value(w):g} and {z} = {self.value(z):g} make a "
                    f"mode or decay of {fastest:.3g} 1/s; the FMU integrates up to "
                    f"{FASTEST_RATE:g} (lower link_modes to the modes in band)"
                )
        return problems

    def link(self) -> StarLink | None:
        """The link's modal model of the parameters (None when link_modes = 0)."""
        m = self.value("link_modes")
        if not m:
            return None
        return StarLink(
            *(tuple(self.values(indexed(name, m))) for name in ("omega_link", "zeta_link")),
            *(tuple(self.values(indexed(name, m))) for name in ("b_link", "phi_tip")),
            self.value("J_link_rigid"),
            self.value("L_link"),
        )

    def settings(self) -> ObserverSettings:
        """The parameters as the observer's settings."""
        n = self.n_masses
        v = self.value
        return ObserverSettings(
            mode=v("mode"),
            actuator=Actuator(v("J_mo"), v("k_to"), v("dkt"), v("dJm"), v("D_m"), v("f_c")),
            g_dist=v("g_dist"),
            g_lpf=v("g_lpf"),
            J=tuple(self.values(indexed("J", n))),
            k=tuple(self.values(indexed("k", n))),
            B=tuple(self.values(indexed("B", n))),
            kappa_correction=bool(v("kappa_correction")),
            estimator=v("estimator"),
            omega_min=v("omega_min"),
            g_id=v("g_id"),
            encoder_cpr=v("encoder_cpr"),
            torque_noise_std=v("torque_noise_std"),
            tau_noise_std=v("tau_noise_std"),
            load_mass=v("load_mass"),
            load_torque_bandwidth=v("load_torque_bandwidth"),
            link=self.link() if 0 <= v("link_modes") <= defaults.LINK_MODES_MAX else None,
            tracking=bool(v("tracking")),
            tracking_time=v("tracking_time"),
            drift_threshold=v("drift_threshold"),
        )

    def initialize(self) -> None:
        n = self.n_masses
        v = self.value
        settings = self.settings()
        self.observer = Observer(settings, v("theta_m"), v("omega_m"))
        self.inputs = self.indices(["i_a", "omega_m", "theta_m"])
        self.out_theta = self.indices(indexed("theta_hat", n))
        self.out_omega = self.indices(indexed("omega_hat", n))
        for block in (self.out_theta, self.out_omega):  # step() writes them as slices
            assert block == list(range(block[0], block[0] + n)), "declare arrays contiguously"
        # value references the step uses, in one tuple (unpacked once per step)
        self.hot = (
            *self.inputs,
            *self.indices(["d_hat", "tau_reac_hat", "alpha_m_hat"]),
            self.out_theta[0],
            self.out_theta[0] + n,
            self.out_omega[0],
            self.out_omega[0] + n,
        )
        self.lazy = frozenset(self.indices(IDENTIFICATION_OUTPUTS))
        self.out_load = self.vr["tau_load_hat"] if settings.load_mass else None
        self.out_tip = self.indices(["w_tip_hat", "alpha_tip_hat"]) if settings.link else None

        self.out_track = None
        if settings.tracking:
            names = ["k_track", "B_track", "f_c_track", "D_m_track"]
            stds = ["k_track_std", "B_track_std", "f_c_track_std", "D_m_track_std"]
            values = [*indexed(names[0], n), *indexed(names[1], n), *names[2:]]
            sigmas = [*indexed(stds[0], n), *indexed(stds[1], n), *stds[2:]]
            self.out_track = (
                self.indices(values),
                self.indices(sigmas),
                self.vr["drift_alarm"],
                self.vr["tracking_valid"],
            )
            self.write_tracking()

        if settings.mode == Mode.STATE_ESTIMATION and not settings.link:
            for i, x in zip(self.out_theta, self.observer.estimator.theta):
                self.v[i] = x

    def step(self, t: float, h: float) -> None:
        v = self.v
        i_a, omega, theta, d, tau, alpha, t0, t1, w0, w1 = self.hot
        obs = self.observer
        obs.step(h, v[i_a], v[omega], v[theta])
        dob = obs.dob
        v[d] = dob.d_hat
        v[tau] = dob.tau_reac_hat
        v[alpha] = dob.alpha_hat
        estimator = obs.estimator
        if self.out_tip is not None:
            tip_w, tip_alpha = self.out_tip
            v[tip_w] = estimator.w_tip
            v[tip_alpha] = estimator.alpha_tip
        elif estimator is not None:
            v[t0:t1] = estimator.theta
            v[w0:w1] = estimator.omega
            if self.out_load is not None:
                v[self.out_load] = estimator.tau_load
            elif self.out_track is not None:
                self.write_tracking()
        else:
            self.stale = True  # identification is solved when an output is read

    def write_tracking(self) -> None:
        """The tracker's parameters, their standard deviations, alarm and validity."""
        tracker, v = self.observer.tracker, self.v
        values, sigmas, alarm, valid = self.out_track
        for i, x in zip(values, tracker.values()):
            v[i] = x
        for i, x in zip(sigmas, tracker.stds()):
            v[i] = x
        v[alarm] = int(tracker.alarm)
        v[valid] = int(tracker.valid)

    def refresh(self) -> None:
        obs = self.observer
        obs.estimate()
        ident, v, vr = obs.identifier, self.v, self.vr
        if obs.settings.mode == Mode.SELF_IDENTIFICATION:
            v[vr["dkt_hat"]] = ident.dkt
            v[vr["dJm_hat"]] = ident.dJm
            v[vr["D_m_hat"]] = ident.D_m
            v[vr["f_c_hat"]] = ident.f_c
            v[vr["self_id_rank_deficient"]] = ident.rank_deficient
        elif obs.settings.mode == Mode.RIGID_IDENTIFICATION:
            v[vr["k_hat"]] = ident.k
            v[vr["B_hat"]] = ident.B
            v[vr["theta_rigid_hat"]] = ident.theta_rigid
        v[vr["id_valid"]] = ident.valid
