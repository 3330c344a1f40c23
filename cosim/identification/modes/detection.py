"""Start values for the whole-chain fit from the record's own modes (offline).

The output-error cost of a lightly damped chain has local minima spaced by about
π / T in each mode's frequency (T the record length), so the fit needs every clamped
frequency to a fraction of a rad/s before it starts. Three linear steps get there
with no search:

1. subspace identification (PO-MOESP; Verhaegen, *Automatica* 30, 1994;
   :mod:`arcosim.identification.modes.subspace`) of the response from the motor angle,
   passed through the DOB's G(s), to τ̂_reac: its poles are the clamped modes p_i and
   their damping ratios;
2. the residues r_i of ``τ/θ_m = k_1 − Σ r_i / (s² + 2ζ_i p_i s + p_i²)`` by
   non-negative least squares on the record, the p_i held;
3. the chain (J_i, k_i) with those modes
   (:func:`arcosim.identification.modes.chain_modes.chain_from_modes`), and spring dampers
   B_i with their damping ratios (:func:`modal_damping`).

:func:`detect_modes` reads the modes from a stabilization diagram (which of them count,
and the weak ones: :class:`DetectedModes`); :func:`record_modes` takes n modes as asked
(:class:`Modes`, the chain's start).

What the record must have (measured on the accuracy benchmark's chains, README):
a broadband excitation with many lines (a multi-sine of 40 log-spaced lines 3–150
rad/s rings all five modes of the five-mass chain; 11 lines do not, the subspace
then takes excitation lines for modes) and modes below min(3·g_dist, 0.3/h)
(:func:`arcosim.identification.excitation.band.search_band`), where G(s) still passes a third of
the torque and the sample rate follows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, signal

from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation.band import search_band
from arcosim.identification.fit.newey_west import newey_west_covariance, newey_west_lag
from arcosim.identification.fit.output_error import through_g
from arcosim.identification.modes.chain_modes import chain_from_modes, clamped_modes
from arcosim.identification.modes.subspace import moesp, observability_matrix
from arcosim.identification.records.record import MotorRecord

#: Block rows of the subspace method's Hankel matrices (decimated samples).
ROWS = 60
#: Damping ratios a clamped mode may show in the subspace model.
DAMPING_RANGE = (-0.05, 0.3)


@dataclass(frozen=True)
class Modes:
    """Clamped modes seen in a record: the whole-chain fit's start.

    Attributes
    ----------
    frequency : ndarray
        Undamped frequencies p_i (rad/s), ascending, shape ``(n,)``.
    damping : ndarray
        Damping ratios ζ_i (dimensionless), shape ``(n,)``.
    residue : ndarray
        Residues r_i (N·m/rad·s⁻²), shape ``(n,)``.
    singular_values : ndarray
        Of the subspace step, relative to the first (dimensionless; evidence for n).
    band : float
        Highest frequency sought (rad/s).
    """

    frequency: np.ndarray
    damping: np.ndarray
    residue: np.ndarray
    singular_values: np.ndarray
    band: float

    def chain(self) -> tuple[np.ndarray, np.ndarray]:
        """``(J, k)`` of the chain with these modes (kg·m², N·m/rad)."""
        return chain_from_modes(self.frequency, self.residue)


def record_modes(record: MotorRecord, n: int) -> Modes:
    """The n clamped modes of the chain in ``record`` and their residues.

    Parameters
    ----------
    record : MotorRecord
        The motor angle (rad) and τ̂_reac (N·m).
    n : int
        Number of modes (load masses) asked for, a count.

    Returns
    -------
    Modes
        The n least damped modes below the band (rad/s), their damping ratios and
        residues.

    Raises
    ------
    IdentificationError
        When the record is too short, shows fewer than n modes, or a mode carries no
        reaction torque.
    """
    band = _band(record)
    u, y, step = _decimated(record, band)
    rows = max(2 * n + 4, min(ROWS, len(u) // 8))
    if len(u) < 8 * (2 * n + 4):
        raise IdentificationError(
            f"the record ({record.duration:g} s) is too short to find {n} modes below "
            f"{band:.0f} rad/s; record at least {8 * (2 * n + 4) * step:.1f} s (20 s advised)"
        )
    frequency, damping, singular = _modes(u, y, n, rows, step, band)
    if len(frequency) < n:
        found = ", ".join(f"{w:.1f}" for w in frequency) or "none"
        raise IdentificationError(
            f"the record shows {len(frequency)} lightly damped mode(s) below {band:.0f} rad/s "
            f"({found} rad/s), {chain_of(n)} has {n}: excite every mode (a multi-sine "
            "with many lines across the band, `arcosim simulate --scenario identification`) "
            "or fit fewer masses"
        )
    residue = residues(record, frequency, damping)
    if np.any(residue <= 0.0):
        missing = ", ".join(f"{w:.1f}" for w in frequency[residue <= 0.0])
        raise IdentificationError(
            f"the mode(s) at {missing} rad/s carry no reaction torque when the record is "
            f"read as {chain_of(n)}: try another number of masses (--masses auto)"
        )
    return Modes(frequency, damping, residue, singular / singular[0], band)


#: Model orders the stabilization diagram runs over: 2 … 2·(largest n + this).
EXTRA_PAIRS = 4
#: Two poles of neighbouring orders are the same mode when their frequencies differ by
#: less than this fraction and their damping ratios by less than
#: :data:`DAMPING_TOLERANCE` (absolute) or half their own.
FREQUENCY_TOLERANCE = 0.02
DAMPING_TOLERANCE = 0.01
#: A mode must be found at this many model orders (of the diagram's) to count.
STABLE_ORDERS = 4
#: A mode's residue must exceed this many of its standard errors to count as excited.
RESIDUE_T = 4.0


@dataclass(frozen=True)
class DetectedModes:
    """The record's modes, read from a stabilization diagram (see :func:`detect_modes`).

    Attributes
    ----------
    frequency : ndarray
        Clamped frequencies p_i of the modes that count (rad/s), ascending, shape
        ``(n,)``.
    damping : ndarray
        Their damping ratios (dimensionless), shape ``(n,)``.
    residue : ndarray
        Their residues (N·m/rad·s⁻²), shape ``(n,)``.
    t_value : ndarray
        Residue / its standard error, per mode that counts (dimensionless), shape
        ``(n,)``.
    weak : list of tuple of float
        Modes found stable but too weakly excited: (frequency rad/s, t value) pairs.
    orders : ndarray
        Per mode that counts, the number of model orders it was found at (a count),
        shape ``(n,)``.
    band : float
        Highest frequency sought (rad/s).
    singular_values : ndarray
        Of the subspace step, relative to the first (dimensionless).
    """

    frequency: np.ndarray
    damping: np.ndarray
    residue: np.ndarray
    t_value: np.ndarray
    weak: list[tuple[float, float]]
    orders: np.ndarray
    band: float
    singular_values: np.ndarray

    @property
    def n(self) -> int:
        """Number of modes that count."""
        return len(self.frequency)

    def modes(self, n: int | None = None) -> Modes:
        """The first ``n`` (default all) as :class:`Modes` for the chain's start."""
        n = self.n if n is None else n
        return Modes(
            self.frequency[:n], self.damping[:n], self.residue[:n], self.singular_values, self.band
        )


def detect_modes(record: MotorRecord, largest: int) -> DetectedModes:
    """The clamped modes a record shows, and which of them it excites enough.

    One PO-MOESP decomposition (:func:`moesp`) gives models of every even order
    2 … 2·(``largest`` + :data:`EXTRA_PAIRS`); a lightly damped pole below the band that
    comes back at neighbouring orders within :data:`FREQUENCY_TOLERANCE` (a physical
    mode does, a pole fitted to noise wanders) is a mode when it does so at
    :data:`STABLE_ORDERS` orders or more. The residues of all such modes are then
    fitted together by least squares (modes held); a mode whose residue is below
    :data:`RESIDUE_T` standard errors (Newey–West) is too weakly excited to count.
    Nothing here depends on the spacing of the modes or the size of their residues.

    Parameters
    ----------
    record : MotorRecord
        The motor angle (rad) and τ̂_reac (N·m).
    largest : int
        The largest chain sought (a count): the diagram runs to order
        2·(``largest`` + :data:`EXTRA_PAIRS`).

    Returns
    -------
    DetectedModes
        The modes that count (rad/s), their damping, residues and t values, and the
        weak ones.

    Raises
    ------
    IdentificationError
        When the record is too short.
    """
    band = _band(record)
    u, y, step = _decimated(record, band)
    top = 2 * (largest + EXTRA_PAIRS)
    rows = max(top + 2, min(ROWS, len(u) // 8))
    if len(u) < 8 * (top // 2 + 4):
        raise IdentificationError(
            f"the record ({record.duration:g} s) is too short to show its modes below "
            f"{band:.0f} rad/s; record at least {8 * (top // 2 + 4) * step:.1f} s (20 s advised)"
        )
    observability, singular = observability_matrix(u, y, rows)
    per_order = []
    for order in range(2, top + 1, 2):
        A = np.linalg.lstsq(observability[:-1, :order], observability[1:, :order], rcond=None)[0]
        eigenvalues = np.linalg.eigvals(A)
        poles = np.log(eigenvalues[eigenvalues.imag > 0].astype(complex)) / step
        frequency = np.abs(poles)
        damping = -poles.real / np.maximum(frequency, 1e-300)
        keep = (frequency < band) & (damping > DAMPING_RANGE[0]) & (damping < DAMPING_RANGE[1])
        per_order.append(np.column_stack([frequency[keep], damping[keep]]))
    clusters = _stable_clusters(per_order)
    if not clusters:
        empty = np.empty(0)
        return DetectedModes(
            empty, empty, empty, empty, [], np.empty(0, int), band, singular / singular[0]
        )
    frequency = np.array([c[0] for c in clusters])
    damping = np.array([c[1] for c in clusters])
    orders = np.array([c[2] for c in clusters])
    regressors = _modal_regressors(record, frequency, damping)  # a column per mode
    residue, std = _residues_of(regressors, record)
    t_value = residue / np.maximum(std, 1e-300)
    counts = t_value >= RESIDUE_T
    weak = [(float(w), float(t)) for w, t, c in zip(frequency, t_value, counts) if not c]
    while np.any(counts) and not np.all(counts):  # refit without the weak ones, until
        residue_c, std_c = _residues_of(regressors[:, counts], record)
        residue[counts], std[counts] = residue_c, std_c
        t_value[counts] = residue_c / np.maximum(std_c, 1e-300)
        still = t_value >= RESIDUE_T
        if np.all(still[counts]):  # every mode kept stands on its own
            break
        weak += [
            (float(w), float(t))
            for w, t in zip(frequency[counts & ~still], t_value[counts & ~still])
        ]
        counts &= still
    return DetectedModes(
        frequency[counts],
        damping[counts],
        residue[counts],
        t_value[counts],
        weak,
        orders[counts],
        band,
        singular / singular[0],
    )


def _stable_clusters(per_order: list[np.ndarray]) -> list[tuple[float, float, int]]:
    """Modes of the stabilization diagram: chains of poles of increasing orders that
    match the chain so far (its median frequency and damping, within tolerance; one
    order may be skipped), at least :data:`STABLE_ORDERS` poles long; each as (median
    frequency, median damping, length), one per frequency."""
    chains: list[list[tuple[float, float]]] = []
    open_chains: list[tuple[list[tuple[float, float]], int]] = []  # (poles, misses)
    for poles in per_order:
        extended: list[tuple[list[tuple[float, float]], int]] = []
        used = np.zeros(len(poles), dtype=bool)
        for chain, misses in open_chains:
            w, z = np.median(np.array(chain), axis=0)
            if len(poles):
                df = np.abs(poles[:, 0] - w) / w
                dz = np.abs(poles[:, 1] - z)
                ok = (
                    (df < FREQUENCY_TOLERANCE)
                    & (dz < np.maximum(DAMPING_TOLERANCE, 0.5 * np.abs(z)))
                    & ~used
                )
                if np.any(ok):
                    j = int(np.flatnonzero(ok)[np.argmin(df[ok])])
                    used[j] = True
                    chain.append((float(poles[j, 0]), float(poles[j, 1])))
                    extended.append((chain, 0))
                    continue
            if misses == 0:
                extended.append((chain, 1))  # one order without it: keep it open
            else:
                chains.append(chain)
        for j in np.flatnonzero(~used):
            extended.append(([(float(poles[j, 0]), float(poles[j, 1]))], 0))
        open_chains = extended
    chains += [chain for chain, _ in open_chains]
    found = []
    for chain in chains:
        if len(chain) >= STABLE_ORDERS:
            tail = np.array(chain[-STABLE_ORDERS:])  # the highest orders: least biased
            found.append((float(np.median(tail[:, 0])), float(np.median(tail[:, 1])), len(chain)))
    found.sort()
    merged: list[tuple[float, float, int]] = []
    for mode in found:  # one mode per frequency: two chains of one mode merge
        if merged and abs(mode[0] - merged[-1][0]) < FREQUENCY_TOLERANCE * mode[0]:
            if mode[2] > merged[-1][2]:
                merged[-1] = mode
            continue
        merged.append(mode)
    return merged


def _band(record: MotorRecord) -> float:
    """:func:`~arcosim.identification.excitation.band.search_band` of the record (rad/s)."""
    return search_band(record.g_dist, record.h)


def chain_of(n: int) -> str:
    """``"a chain of 1 mass"``, ``"a chain of 3 masses"``."""
    return f"a chain of {n} mass{'es' if n != 1 else ''}"


def _decimated(record: MotorRecord, band: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Motor angle through G(s) and τ̂_reac, both low-passed (zero phase) and decimated
    so that the Nyquist frequency is about ``band``; and the new step (s)."""
    u = through_g(record.theta_m - record.theta_m[0], record.g_dist, record.h)
    y = record.tau_hat
    factor = max(1, int(np.pi / (band * record.h)))
    if factor > 1:
        b, a_ = signal.butter(4, 0.8 / factor)
        u, y = (signal.filtfilt(b, a_, x)[::factor] for x in (u, y))
    return u, y, factor * record.h


def _modes(
    u: np.ndarray, y: np.ndarray, n: int, rows: int, step: float, band: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lightly damped complex poles below ``band`` of a subspace model of order 2n
    (then 2n + 2, 2n + 4 if spurious poles took some of the order): the n least damped,
    by frequency. Returns (frequency, damping, singular values)."""
    best: tuple[np.ndarray, np.ndarray] = (np.empty(0), np.empty(0))
    singular = np.empty(0)
    for order in (2 * n, 2 * n + 2, 2 * n + 4):
        eigenvalues, sv = moesp(u, y, order, rows)
        if order == 2 * n:
            singular = sv
        poles = np.log(eigenvalues[eigenvalues.imag > 0].astype(complex)) / step
        frequency = np.abs(poles)
        damping = -poles.real / frequency
        keep = (frequency < band) & (damping > DAMPING_RANGE[0]) & (damping < DAMPING_RANGE[1])
        frequency, damping = frequency[keep], damping[keep]
        chosen = np.argsort(np.abs(damping))[:n]
        chosen = chosen[np.argsort(frequency[chosen])]
        if len(chosen) > len(best[0]):
            best = (frequency[chosen], damping[chosen])
        if len(chosen) == n:
            break
    return best[0], best[1], singular


def residues(record: MotorRecord, frequency: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """Residues r_i ≥ 0 of the modal model on the record, the modes held (shape (n,)).

    Each regressor is the motor angle through ``1/p² − 1/(s² + 2ζps + p²)`` and G(s)
    (so the static torque k_1 − Σ r_i / p_i² is zero, as it is for a free load chain);
    0 means the mode does not explain the record.
    """
    X, norms = _normalized(_modal_regressors(record, frequency, damping))
    r, _ = optimize.nnls(X, record.tau_hat)
    return r / norms


def _modal_regressors(
    record: MotorRecord, frequency: np.ndarray, damping: np.ndarray
) -> np.ndarray:
    """The motor angle through ``1/p² − 1/(s² + 2ζps + p²)`` and G(s), per mode (N, n)."""
    h = record.h
    u = record.theta_m - record.theta_m[0]
    columns = []
    for p, zeta in zip(frequency, np.clip(damping, 1e-4, None)):
        numerator = [1.0, 2.0 * zeta * p, 0.0]
        denominator = [p**2, 2.0 * zeta * p**3, p**4]
        b, a_, _ = signal.cont2discrete((numerator, denominator), h, method="bilinear")
        columns.append(through_g(signal.lfilter(b.ravel(), a_, u), record.g_dist, h))
    return np.array(columns).T


def _normalized(regressors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The regressors (N, n) scaled to unit norm per column, and the norms (n,); a
    column of zeros keeps the norm 1."""
    norms = np.linalg.norm(regressors, axis=0)
    norms[norms == 0.0] = 1.0
    return regressors / norms, norms


def _residues_of(regressors: np.ndarray, record: MotorRecord) -> tuple[np.ndarray, np.ndarray]:
    """Residues r_i of the modal model (:func:`_modal_regressors`, shape (N, n)) on the
    record, the modes held, by ordinary least squares (any sign), and their Newey–West
    standard errors (shapes (n,))."""
    X, norms = _normalized(regressors)
    r = np.linalg.lstsq(X, record.tau_hat, rcond=None)[0]
    residual = record.tau_hat - X @ r
    cov = newey_west_covariance(X, residual, newey_west_lag(residual, record))
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return r / norms, std / norms


def modal_damping(J: np.ndarray, k: np.ndarray, modes: Modes) -> np.ndarray:
    """Spring dampers B_i ≥ 0 whose clamped modal damping matches the modes' (first
    order in the damping: 2 ζ_i p_i = Σ_j B_j (φ_ji − φ_(j−1)i)², φ the mass-normalized
    clamped mode shapes, φ_0 = 0), shape (n,); a floor of 1e-3 of their mean."""
    n = len(J)
    eigenvalues, phi = clamped_modes(J, k)
    stretch = np.diff(np.vstack([np.zeros(n), phi]), axis=0) ** 2  # (spring j, mode i)
    target = 2.0 * np.clip(modes.damping, 1e-4, 0.2) * np.sqrt(eigenvalues)
    B, _ = optimize.nnls(stretch.T, target)
    floor = 1e-3 * max(float(np.mean(B)), 1e-12)
    return np.maximum(B, floor)
