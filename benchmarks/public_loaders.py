"""Readers of public measured drive records, each into the project's log format.

No record is part of the repository: each reader takes the file as its source
publishes it (a MATLAB ``.mat`` file) and returns the columns of a drive log
(``time`` s, ``i_a`` A, ``omega_m`` rad/s, ``theta_m`` rad, as ``docs/identification.md``
defines them), the extra columns the record holds (a reference, a load encoder), their
units and the ``--set`` values the record's documentation gives for the drive.

- :func:`load_emps`: the EMPS (Janot, Gautier, Brunot 2019), a rigid ball-screw axis
  in a position loop. A **linear** axis: the log's "rad" column holds metres, "rad/s"
  metres per second, the "current" the controller's voltage, so that ``k_to`` is the
  drive gain in N/V, ``J_mo`` and every inertia a mass in kg, ``D_m`` a viscous
  friction in N·s/m and ``f_c`` a force in N (the equations are the same with x for θ).
- :func:`load_hsm150`: the HSM150 motor (Slovak University of Technology), a rigid
  rotary drive turning one way, torque stepped; current and encoder logged.
- :func:`load_motor_bench`: the KU Leuven motor bench with a flexible coupling (the
  FdiTools toolbox's two-mass data set), a Schroeder multi-sine of current in open
  loop, motor and load encoders.
- :func:`two_mass_reference`: what the bench's *two* encoders say about its chain
  (a frequency-domain fit the sensorless method cannot make), the reference its
  identification is compared against.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.io import loadmat
from scipy.optimize import least_squares

from arcosim import UserError

#: EMPS: the motor encoder's 12500 lines in quadrature on the load side, one count in m.
EMPS_COUNT = 5e-8
#: HSM150: the encoder's counts per revolution after quadrature (its 2500 lines × 4).
HSM150_CPR = 10000
#: Motor bench: counts per revolution the encoder's 6-digit angles resolve (2^20).
BENCH_CPR = 2**20


@dataclass(frozen=True)
class Converted:
    """A public record as a drive log.

    Parameters
    ----------
    columns : dict of str to ndarray
        ``time`` (s), ``i_a`` (A), ``omega_m`` (rad/s), ``theta_m`` (rad), each of shape
        ``(N,)``, and the record's extra columns (shape ``(N,)``).
    units : dict of str to str
        Each column's unit (FMI names).
    settings : tuple of str
        ``NAME=VALUE`` for ``--set``: the drive's figures from the record's documentation.
    note : str
        How the record's signals map onto the log's names.
    """

    columns: dict[str, np.ndarray]
    units: dict[str, str]
    settings: tuple[str, ...]
    note: str
    extra: dict[str, float] = field(default_factory=dict)


def _read_mat(path: Path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The variables ``names`` of MATLAB file ``path`` as float arrays; a column or row
    vector (or a scalar) flattened to shape ``(N,)``, a matrix kept."""
    try:
        data = loadmat(path)
    except (OSError, ValueError) as error:
        raise UserError(f"{path}: not a MATLAB .mat file this reader knows ({error})") from None
    missing = [n for n in names if n not in data]
    if missing:
        raise UserError(f"{path}: no variable {', '.join(missing)}; is it the documented file?")
    arrays = {n: np.asarray(data[n], dtype=float) for n in names}
    return {n: a if min(a.shape, default=1) > 1 else a.ravel() for n, a in arrays.items()}


def _backward_difference(theta: np.ndarray, h: float) -> np.ndarray:
    """The encoder's backward difference (rad/s), 0 at the first sample."""
    return np.concatenate(([0.0], np.diff(theta) / h))


def _uniform_time(t: np.ndarray) -> tuple[np.ndarray, float]:
    """A constant-step time column for logged times ``t`` (s) whose step only jitters
    (a logger's float time): the mean step, to 6 significant digits."""
    h = float(f"{(t[-1] - t[0]) / (len(t) - 1):.6g}")
    if h <= 0.0 or np.max(np.abs(np.diff(t) - h)) > 1e-3 * h:
        raise UserError("the record's time step varies by more than 0.1 %; resample it first")
    return np.arange(len(t)) * h, h


def load_emps(path: str | Path) -> Converted:
    """Read ``DATA_EMPS.mat`` (or ``DATA_EMPS_PULSES.mat``) as a drive log.

    Parameters
    ----------
    path : str or Path
        The file with ``t`` (s), ``qm`` (motor position on the load side, m), ``qg``
        (reference, m), ``vir`` (controller output, V), ``gtau`` (drive gain, N/V),
        ``kp`` (1/s), ``kv`` (V·s/m), as the benchmark's description documents them.

    Returns
    -------
    Converted
        ``i_a`` = ``vir`` (V in the A column), ``theta_m`` = ``qm`` (m),
        ``omega_m`` its backward difference (m/s), ``q_ref`` = ``qg`` (m); settings
        ``k_to`` = ``gtau`` (N/V), ``encoder_cpr`` = 2π/(50 nm) (one count is 50 nm),
        ``omega_min`` 5 mm/s (mode 0's stopped-motor speed, in m/s).

    Raises
    ------
    UserError
        When the file lacks a documented variable or its step is not constant.

    Examples
    --------
    >>> import tempfile
    >>> from scipy.io import savemat
    >>> f = Path(tempfile.mkdtemp()) / "DATA_EMPS.mat"
    >>> t = np.arange(5)[:, None] * 1e-3
    >>> savemat(f, {"t": t, "qm": t, "qg": t, "vir": t, "gtau": 35.0, "kp": 1.0, "kv": 1.0})
    >>> load_emps(f).settings[0]
    'k_to=35'
    """
    v = _read_mat(Path(path), ("t", "qm", "qg", "vir", "gtau", "kp", "kv"))
    time, h = _uniform_time(v["t"])
    columns = {
        "time": time,
        "i_a": v["vir"],
        "omega_m": _backward_difference(v["qm"], h),
        "theta_m": v["qm"],
        "q_ref": v["qg"],
    }
    units = {"time": "s", "i_a": "V", "omega_m": "m/s", "theta_m": "m", "q_ref": "m"}
    settings = (
        f"k_to={float(v['gtau'][0]):.10g}",
        f"encoder_cpr={round(2.0 * np.pi / EMPS_COUNT)}",
        "omega_min=0.005",
    )
    note = (
        "linear axis: theta_m = qm (m), omega_m its backward difference (m/s), i_a = vir (V), "
        f"k_to = gtau (N/V); position loop kp = {v['kp'][0]:g} 1/s, kv = {v['kv'][0]:g} V·s/m"
    )
    return Converted(columns, units, settings, note)


def load_hsm150(path: str | Path, current: str = "measured") -> Converted:
    """Read an HSM150 identification record (``idf_SIGN_INPUT_NUMBER.mat``) as a drive log.

    Parameters
    ----------
    path : str or Path
        The file with ``data`` (columns: time s, position reference rad, position rad,
        velocity rad/s, input torque N·m, torque measurement N·m, motor current A, as
        the repository's README documents them) and ``Cu`` (the torque constant, N·m/A).
    current : {"measured", "command"}
        ``i_a`` from the measured motor current, or the input torque over ``Cu`` (the
        torque the drive was told to give: what the source's own fit used).

    Returns
    -------
    Converted
        ``theta_m`` and ``omega_m`` as logged (the velocity is the encoder's backward
        difference), ``torque_command`` (N·m) beside them; settings ``k_to`` = ``Cu``,
        ``encoder_cpr`` 10000, ``J_mo`` the catalog inertia the file stores (``J``).

    Raises
    ------
    UserError
        When the file lacks a documented variable, or ``current`` is neither choice.

    Examples
    --------
    >>> import tempfile
    >>> from scipy.io import savemat
    >>> f = Path(tempfile.mkdtemp()) / "idf_pos_0.065_2.mat"
    >>> data = np.column_stack([np.arange(4) * 1e-3] + [np.ones(4)] * 6)
    >>> savemat(f, {"data": data, "Cu": 0.0458, "J": 1.2e-4, "B": 7.03e-5})
    >>> sorted(load_hsm150(f, "command").columns)[:3]
    ['i_a', 'omega_m', 'theta_m']
    """
    if current not in ("measured", "command"):
        raise UserError(f"current={current!r}: choose 'measured' or 'command'")
    v = _read_mat(Path(path), ("data", "Cu", "J", "B"))
    data = v["data"]
    if data.ndim != 2 or data.shape[1] != 7:
        raise UserError(f"{path}: data has shape {data.shape}; the README documents 7 columns")
    time, _ = _uniform_time(data[:, 0])
    k_t = float(v["Cu"][0])
    i_a = data[:, 6] if current == "measured" else data[:, 4] / k_t
    columns = {
        "time": time,
        "i_a": i_a,
        "omega_m": data[:, 3],
        "theta_m": data[:, 2],
        "torque_command": data[:, 4],
    }
    units = {"time": "s", "i_a": "A", "omega_m": "rad/s", "theta_m": "rad"}
    units["torque_command"] = "N.m"
    settings = (f"k_to={k_t:g}", f"J_mo={float(v['J'][0]):g}", f"encoder_cpr={HSM150_CPR}")
    what = "measured motor current" if current == "measured" else "input torque / Cu"
    note = f"i_a = {what} (A), k_to = Cu; J_mo = the catalog J stored in the file"
    extra = {"catalog_J": float(v["J"][0]), "catalog_B": float(v["B"][0])}
    return Converted(columns, units, settings, note, extra)


def load_motor_bench(path: str | Path) -> Converted:
    """Read the FdiTools motor bench's ``MultisineTypeA.mat`` as a drive log.

    Parameters
    ----------
    path : str or Path
        The file with ``time`` (µs), ``iq_adx`` (the measured q-axis current, A),
        ``theta_mx`` (motor angle, rad), ``theta_my`` (load angle, rad), ``fs`` (Hz),
        ``nrofs`` (samples per period), ``fl``, ``fh`` (the multi-sine's band, Hz), as
        the toolbox's examples read them.

    Returns
    -------
    Converted
        ``i_a`` = ``iq_adx``, ``theta_m`` = ``theta_mx``, ``omega_m`` its backward
        difference, ``theta_load`` = −``theta_my`` (the examples' sign); settings
        ``k_to`` = 1 (k_t is not published: every torque, inertia, stiffness and
        damping is then per N·m/A of the true k_t), ``encoder_cpr`` 2^20, ``g_dist`` 1000
        rad/s (its mode lies above the default band); ``extra`` the period (samples) and
        the band (Hz).

    Raises
    ------
    UserError
        When the file lacks a documented variable.

    Examples
    --------
    >>> import tempfile
    >>> from scipy.io import savemat
    >>> f = Path(tempfile.mkdtemp()) / "MultisineTypeA.mat"
    >>> t = np.arange(6)[:, None] * 400.0
    >>> z = np.zeros((6, 1))
    >>> savemat(f, {"time": t, "iq_adx": z, "theta_mx": z, "theta_my": z,
    ...             "fs": 2500, "nrofs": 3, "fl": 11, "fh": 250})
    >>> float(load_motor_bench(f).columns["time"][1])
    0.0004
    """
    names = ("time", "iq_adx", "theta_mx", "theta_my", "fs", "nrofs", "fl", "fh")
    v = _read_mat(Path(path), names)
    h = 1.0 / float(v["fs"][0])
    time = np.arange(len(v["time"])) * h
    if not np.allclose(v["time"] * 1e-6, time, rtol=0.0, atol=1e-3 * h):
        raise UserError(f"{path}: time (µs) is not the constant step 1/fs; resample it first")
    columns = {
        "time": time,
        "i_a": v["iq_adx"],
        "omega_m": _backward_difference(v["theta_mx"], h),
        "theta_m": v["theta_mx"],
        "theta_load": -v["theta_my"],
    }
    units = {"time": "s", "i_a": "A", "omega_m": "rad/s", "theta_m": "rad", "theta_load": "rad"}
    settings = ("k_to=1", f"encoder_cpr={BENCH_CPR}", "g_dist=1000")
    extra = {"period": float(v["nrofs"][0]), "f_low": float(v["fl"][0])}
    extra["f_high"] = float(v["fh"][0])
    note = "i_a = iq_adx (A), theta_m = theta_mx; k_t not published: k_to = 1 (per unit k_t)"
    return Converted(columns, units, settings, note, extra)


def periodic_frf(
    columns: dict[str, np.ndarray], period: int, band: tuple[float, float], output: str
) -> tuple[np.ndarray, np.ndarray]:
    """The response of ``output`` to ``i_a`` at the excited lines, averaged over periods.

    Parameters
    ----------
    columns : dict of str to ndarray
        A log's columns (``time`` s, ``i_a`` A and ``output``), shape ``(N,)`` each.
    period : int
        Samples per period of the excitation (a count); the first period is dropped
        (transient) and the rest averaged.
    band : tuple of float
        (low, high) of the excitation (Hz).
    output : str
        The column to relate to the current (rad).

    Returns
    -------
    w : ndarray
        The lines (rad/s), shape ``(L,)``.
    frf : ndarray
        ``output/i_a`` at the lines (rad/A, complex), shape ``(L,)``.
    """
    h = float(columns["time"][1] - columns["time"][0])
    periods = len(columns["i_a"]) // period
    blocks = slice(period, periods * period)
    i_f = np.fft.rfft(columns["i_a"][blocks].reshape(periods - 1, period), axis=1).mean(0)
    y_f = np.fft.rfft(columns[output][blocks].reshape(periods - 1, period), axis=1).mean(0)
    f = np.fft.rfftfreq(period, h)
    lines = (f >= band[0]) & (f <= band[1]) & (np.abs(i_f) > 0.05 * np.abs(i_f).max())
    return 2.0 * np.pi * f[lines], y_f[lines] / i_f[lines]


def two_mass_frf(w: np.ndarray, J_m: float, J_L: float, k: float, c: float, delay: float):
    """Motor and load angle per unit torque of a two-mass chain at ``w`` (rad/s).

    Parameters
    ----------
    w : ndarray
        Frequencies (rad/s), shape ``(L,)``.
    J_m, J_L : float
        Motor and load inertia (kg·m²).
    k, c : float
        Coupling stiffness (N·m/rad) and damping (N·m·s/rad).
    delay : float
        A pure delay of the torque (s): the current loop and the sampling.

    Returns
    -------
    tuple of ndarray
        θ_m/τ and θ_L/τ (rad/(N·m), complex), shape ``(L,)`` each.
    """
    s = 1j * w
    coupling = c * s + k
    det = (J_m * s**2 + coupling) * (J_L * s**2 + coupling) - coupling**2
    lag = np.exp(-s * delay)
    return lag * (J_L * s**2 + coupling) / det, lag * coupling / det


def two_mass_reference(converted: Converted) -> dict[str, float]:
    """The motor bench's chain from its motor *and* load encoders (frequency domain).

    A least-squares fit of :func:`two_mass_frf` to both measured responses (relative
    complex error), per unit k_t; the sensorless identification sees only the motor's.

    Parameters
    ----------
    converted : Converted
        :func:`load_motor_bench`'s result.

    Returns
    -------
    dict of str to float
        ``J_m``, ``J[1]`` (kg·m² per N·m/A), ``k[1]`` (N·m/rad per N·m/A), ``B[1]``
        (N·m·s/rad per N·m/A), ``delay`` (s), ``clamped_mode`` √(k/J_L) and
        ``resonance`` (rad/s), ``rms_relative_error`` (the fit's rms of
        |model − measured|/|measured| over both responses, a ratio).
    """
    band = (converted.extra["f_low"], converted.extra["f_high"])
    period = int(converted.extra["period"])
    w, motor = periodic_frf(converted.columns, period, band, "theta_m")
    _, load = periodic_frf(converted.columns, period, band, "theta_load")
    # Starts: J_m from the motor's high-frequency asymptote, J_total from its lowest line.
    J_m0 = float(np.median(1.0 / (w[-20:] ** 2 * np.abs(motor[-20:]))))
    J_t0 = float(1.0 / (w[0] ** 2 * np.abs(motor[0])))
    ratio_peak = w[np.argmax(np.abs(load / motor))]
    J_L0 = max(J_t0 - J_m0, 0.1 * J_m0)
    x0 = np.log([J_m0, J_L0, J_L0 * ratio_peak**2, 1e-3 * J_L0 * ratio_peak])

    def residual(x: np.ndarray) -> np.ndarray:
        J_m, J_L, k, c = np.exp(x[:4])
        m, lo = two_mass_frf(w, J_m, J_L, k, c, x[4])
        r = np.concatenate(((m - motor) / np.abs(motor), (lo - load) / np.abs(load)))
        return np.concatenate((r.real, r.imag))

    fit = least_squares(residual, np.append(x0, 0.0), x_scale="jac")
    J_m, J_L, k, c = (float(x) for x in np.exp(fit.x[:4]))
    return {
        "J_m": J_m,
        "J[1]": J_L,
        "k[1]": k,
        "B[1]": c,
        "delay": float(fit.x[4]),
        "clamped_mode": float(np.sqrt(k / J_L)),
        "resonance": float(np.sqrt(k * (J_m + J_L) / (J_m * J_L))),
        "rms_relative_error": float(np.sqrt(np.mean(fit.fun**2) * 2.0)),
    }
