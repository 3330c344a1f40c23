"""A drive chain assembled from a plant we did not write: Dymola's ``edrive_mass.fmu``.

The masses are instances of ``edrive_mass.fmu`` ("Rotational mass with damper", an FMI 2.0
FMU exported by Dymola 2024x, shipped by OMSimulator's test suite in
``testsuite/tests/resources/dcmotor/resources/``): an inertia ``inertia.J`` (kg·m²) with a
damper ``damper.d`` (N·m·s/rad) to the fixed housing, two flange torques ``M_A``, ``M_B``
(N·m; both accelerate the mass forwards: the FMU's gains ``M_gain.k = −1`` and the
flange's sign cancel, as a run shows and the comparison with the project's plant checks)
and the flanges' angles and speeds ``phiA``, ``wA`` (rad, rad/s). The motor is one
instance (J_m, its viscous friction D_m as the damper), each load mass another (damper 0).

Ours, and only these: the springs and dampers between the masses (τ_i = k_i(φ_{i−1} − φ_i)
+ B_i(ω_{i−1} − ω_i), on the flanges), the actuator (torque k_t·i_ref, held over each step
of h, as the project's plant with its ideal current loop) and the sensors, with the
conventions of the project's plant FMU and logs: the current i_a (A) is the mean current of
the step ending at the sample plus Gaussian noise (the plant's noise stream,
:func:`arcosim.fmu.flexchain.noise.gaussian`), the angle θ_m (rad) whole encoder counts
(floored), the speed ω_m (rad/s) the backward difference of θ_m over h.

The coupling is monolithic, through the FMUs' model-exchange interface: every stage of a
classic Runge–Kutta step sets each instance's states, reads its flange angle and speed,
sets the spring torques and reads its derivatives. No co-simulation coupling delay, hence
no numerical negative damping; the one error is RK4's, per step of length s = h/substeps
at the chain's fastest mode ω: a relative frequency error ≈ (ωs)⁴/120 and a damping error
≈ (ωs)⁵/144 … (ωs)⁶/144 per radian, both far below the chains' 0.1 % damping for ωs ≤ 0.2
(measured against the project's exact plant in :mod:`benchmarks.thirdparty_chain`).

The FMU is not in the repository: name the folder that holds it (:data:`FMU_FILE`, from
:data:`SOURCE`).
"""

from __future__ import annotations

import ctypes
import shutil
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from arcosim import UserError
from arcosim.fmu.flexchain import gaussian, quantize

#: The FMU's file name, in the folder the user names.
FMU_FILE = "edrive_mass.fmu"
#: Where to get it.
SOURCE = (
    "https://github.com/OpenModelica/OMSimulator, folder "
    "testsuite/tests/resources/dcmotor/resources/ (edrive_mass.fmu, Dymola 2024x, FMI 2.0, "
    "linux64 and win64 binaries)"
)
#: The environment variable the test reads the folder from.
ENV = "ARCOSIM_THIRDPARTY_FMUS"

_STATES = 2  # the FMU's continuous states: the damper's relative angle and speed
_INPUTS = ("M_A", "M_B")
_OUTPUTS = ("phiA", "wA")


def where(folder: Path | None) -> str:
    """One line saying what is missing and where to get it (for a skip)."""
    place = f"{folder / FMU_FILE}" if folder else f"a folder named by {ENV}"
    return f"{place} not found; get {FMU_FILE} from {SOURCE}"


class _Mass:
    """One model-exchange instance of the FMU with raw ctypes calls on fixed buffers."""

    def __init__(self, unzipped: Path, description, name: str, J: float, d: float) -> None:
        from fmpy.fmi2 import FMU2Model

        vr = {v.name: v.valueReference for v in description.modelVariables}
        self.model = FMU2Model(
            guid=description.guid,
            unzipDirectory=str(unzipped),
            modelIdentifier=description.modelExchange.modelIdentifier,
            instanceName=name,
        )
        self.model.instantiate()
        self.model.setupExperiment(startTime=0.0)
        self.model.setReal([vr["inertia.J"], vr["damper.d"]], [J, d])
        self.model.enterInitializationMode()
        self.model.exitInitializationMode()
        while self.model.newDiscreteStates()[0]:  # newDiscreteStatesNeeded
            pass
        self.model.enterContinuousTimeMode()
        dll, self.c = self.model.dll, self.model.component
        self._set_time, self._set_x = dll.fmi2SetTime, dll.fmi2SetContinuousStates
        self._set, self._get = dll.fmi2SetReal, dll.fmi2GetReal
        self._get_dx, self._get_x = dll.fmi2GetDerivatives, dll.fmi2GetContinuousStates
        vrs = ctypes.c_uint * 2
        self.vr_in = vrs(*(vr[k] for k in _INPUTS))
        self.vr_out = vrs(*(vr[k] for k in _OUTPUTS))
        self.x, self.dx = (ctypes.c_double * _STATES)(), (ctypes.c_double * _STATES)()
        self.u, self.y = (ctypes.c_double * 2)(), (ctypes.c_double * 2)()
        self._check(self._get_x(self.c, self.x, _STATES), "fmi2GetContinuousStates")

    def _check(self, status: int, call: str) -> None:
        if status > 1:
            raise UserError(f"{FMU_FILE}: {call} failed (status {status}); use the FMU from "
                            f"{SOURCE}")  # fmt: skip

    def outputs(self, t: float, x: Sequence[float]) -> tuple[float, float]:
        """Set time and states; the flange's angle (rad) and speed (rad/s)."""
        self.x[0], self.x[1] = x[0], x[1]
        self._set_time(self.c, t)
        self._set_x(self.c, self.x, _STATES)
        self._get(self.c, self.vr_out, 2, self.y)
        return self.y[0], self.y[1]

    def derivatives(self, M_A: float, M_B: float) -> tuple[float, float]:
        """Set the flange torques (N·m); the states' derivatives."""
        self.u[0], self.u[1] = M_A, M_B
        self._set(self.c, self.vr_in, 2, self.u)
        self._get_dx(self.c, self.dx, _STATES)
        return self.dx[0], self.dx[1]

    def close(self) -> None:
        """Terminate and free the instance."""
        self.model.terminate()
        self.model.freeInstance()


class ThirdPartyChain:
    """A motor and its load chain made of ``edrive_mass.fmu`` instances, with our springs,
    actuator and sensors, stepped at ``h`` with the current held over each step.

    Parameters
    ----------
    folder : Path
        The folder holding ``edrive_mass.fmu``.
    J_m, D_m : float
        Motor inertia (kg·m²) and viscous friction (N·m·s/rad, the motor instance's damper).
    J, k, B : sequence of float
        Load inertias (kg·m²), stiffnesses (N·m/rad) and spring dampings (N·m·s/rad),
        shape ``(n,)`` each.
    k_t : float
        Torque constant (N·m/A).
    encoder_cpr : int
        Encoder counts per revolution (0 = exact angle and true speed).
    i_noise_std : float
        Standard deviation of the current-sensor noise (A).
    seed : int
        Seed of the noise stream.
    h : float
        The step (s).
    substeps : int
        Runge–Kutta steps per step (a count).

    Raises
    ------
    UserError
        When the FMU is missing or refuses a call.

    Examples
    --------
    >>> import os; from pathlib import Path
    >>> folder = Path(os.environ.get(ENV, "/nonexistent"))
    >>> if (folder / FMU_FILE).is_file():
    ...     with ThirdPartyChain(folder, 2e-5, 0.0, [5e-4], [0.3], [0.0], 0.04, 0, 0.0, 1) as p:
    ...         _ = p.step(1.0)
    """

    def __init__(
        self,
        folder: Path,
        J_m: float,
        D_m: float,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        k_t: float,
        encoder_cpr: int,
        i_noise_std: float,
        seed: int,
        h: float = 1e-3,
        substeps: int = 1,
    ) -> None:
        from fmpy import extract, read_model_description

        path = Path(folder) / FMU_FILE
        if not path.is_file():
            raise UserError(where(Path(folder)))
        description = read_model_description(str(path))
        self._unzipped = Path(extract(str(path)))
        self.n, self.k, self.B = len(J), list(map(float, k)), list(map(float, B))
        self.k_t, self.cpr, self.noise, self.seed = k_t, int(encoder_cpr), i_noise_std, seed
        self.h, self.substeps = h, int(substeps)
        self.masses = [_Mass(self._unzipped, description, "motor", J_m, D_m)]
        self.masses += [
            _Mass(self._unzipped, description, f"mass{i}", Ji, 0.0) for i, Ji in enumerate(J, 1)
        ]
        self.X = np.array([list(m.x) for m in self.masses]).ravel()
        self.t, self.sample = 0.0, 0
        self.tau_ext = 0.0  # an external torque on the last mass (N·m)
        angles, speeds = self._flanges(self.t, self.X)
        self.theta_measured = quantize(angles[0], self.cpr)
        self.i_a, self.theta_m = 0.0, self.theta_measured
        self.omega_m = speeds[0]

    def __enter__(self) -> ThirdPartyChain:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Free the instances and the unzipped FMU."""
        for mass in self.masses:
            mass.close()
        self.masses = []
        shutil.rmtree(self._unzipped, ignore_errors=True)

    def _flanges(self, t: float, X: np.ndarray) -> tuple[list[float], list[float]]:
        """Angles (rad) and speeds (rad/s) of the motor and every mass at states ``X``."""
        read = [m.outputs(t, X[2 * j : 2 * j + 2]) for j, m in enumerate(self.masses)]
        return [a for a, _ in read], [w for _, w in read]

    def derivative(self, t: float, X: np.ndarray, torque: float) -> np.ndarray:
        """dX/dt with the motor torque ``torque`` (N·m): the FMUs' derivatives under our
        springs' torques."""
        phi, w = self._flanges(t, X)
        tau = [self.k[i] * (phi[i] - phi[i + 1]) + self.B[i] * (w[i] - w[i + 1])
               for i in range(self.n)]  # fmt: skip
        tau.append(-self.tau_ext)
        out = np.empty_like(X)
        left = torque
        for j, mass in enumerate(self.masses):
            out[2 * j : 2 * j + 2] = mass.derivatives(left, -tau[j])
            left = tau[j]
        return out

    def step(self, i_ref: float) -> None:
        """Advance one step ``h`` with the current ``i_ref`` (A) held; update the sensors."""
        torque, s = self.k_t * i_ref, self.h / self.substeps
        X, t = self.X, self.t
        for _ in range(self.substeps):
            k1 = self.derivative(t, X, torque)
            k2 = self.derivative(t + s / 2, X + s / 2 * k1, torque)
            k3 = self.derivative(t + s / 2, X + s / 2 * k2, torque)
            k4 = self.derivative(t + s, X + s * k3, torque)
            X = X + s / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            t += s
        self.X, self.t = X, self.t + self.h
        theta = self.angles()[0]
        theta_q = quantize(theta, self.cpr)
        self.omega_m = (theta_q - self.theta_measured) / self.h if self.cpr else self.speeds()[0]
        self.theta_m = self.theta_measured = theta_q
        self.i_a = i_ref + self.noise * gaussian(self.seed, self.sample)
        self.sample += 1

    def angles(self) -> list[float]:
        """True angles of the motor and masses 1 … n (rad), shape ``(n + 1,)``."""
        return self._flanges(self.t, self.X)[0]

    def speeds(self) -> list[float]:
        """True speeds of the motor and masses 1 … n (rad/s), shape ``(n + 1,)``."""
        return self._flanges(self.t, self.X)[1]

    def jacobian(self, eps: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
        """The linear map of the assembled chain at rest, by central differences through
        the FMUs: ``(A, C)`` with dX/dt = A X (current 0) and (angles, speeds) = C X."""
        X0, size = np.zeros_like(self.X), len(self.X)
        A, C = np.empty((size, size)), np.empty((2 * (self.n + 1), size))
        for j in range(size):
            e = np.zeros(size)
            e[j] = eps
            A[:, j] = self.derivative(0.0, X0 + e, 0.0) - self.derivative(0.0, X0 - e, 0.0)
            C[:, j] = np.subtract(np.ravel(self._flanges(0.0, X0 + e)),
                                  np.ravel(self._flanges(0.0, X0 - e)))  # fmt: skip
        self._flanges(self.t, self.X)
        return A / (2 * eps), C / (2 * eps)
