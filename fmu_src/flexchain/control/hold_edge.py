"""Where the hold keeps the motor's mean: near an encoder edge, not half way between two.

At rest the hold's dither (:mod:`~arcosim.fmu.flexchain.control.hold_dither`) moves the motor
over ``defaults.HOLD_DITHER`` = 0.7 count peak to peak about the angle the chain needs
it at. Near an edge the dither crosses that edge and the reading takes two values (one
count); half way between two edges it reaches both on its peaks, the more so as that
angle wanders with the load estimate, and the reading takes three (two counts: the
limit cycle the controller must not hold). Measured on `arcosim bench control` with the
target half way between two edges (``--target-offset 0.19``): the two-mass chain within
one count at rest on 28 of 42 runs, and with the shift below on all 42
(docs/benchmarks.md).

:class:`HoldEdge` moves the hold's target by the least that brings the motor's mean
within ``near`` counts of an edge, the edge kept until the needed angle is more than
``0.5 + switch`` counts from it. The whole chain moves with it (no spring changes its
torque), so the controlled mass rests up to ``0.5 + switch − near`` counts off its target
(0.3 count, 0.94 mrad at 2000 counts, with the defaults; at most 0.2 count while the
edge is kept on its near side): the price of the one-count hold, stated in
docs/control.md.
"""

from __future__ import annotations

import math

from .. import defaults
from ..filters import lowpass_pole


class HoldEdge:
    """The shift of the hold's target (rad) that keeps the motor near one encoder edge.

    Parameters
    ----------
    count : float
        One encoder count (rad), > 0.
    near : float
        How near an edge the motor's mean is kept (counts), in [0, 0.5]; 0.5 or more
        turns the shift off (``defaults.HOLD_EDGE_NEAR``).
    switch : float
        How far past the middle of the count the needed angle goes before the other edge
        is taken (counts), ≥ 0 (``defaults.HOLD_EDGE_SWITCH``).
    bandwidth : float
        The needed angle's low-pass (rad/s), > 0: the shift follows the load estimate's
        drift, not its noise (``defaults.HOLD_EDGE_BANDWIDTH``).

    Attributes
    ----------
    shift : float
        The last shift (rad): add it to every angle of the hold's target.
    edge : float or None
        The edge kept (rad, in the angles given), None before :meth:`step`.
    needed : float
        The needed angle, low-passed (rad).

    Examples
    --------
    >>> q = 2 * math.pi / 2000  # rad
    >>> edge = HoldEdge(q, near=0.3, switch=0.1, bandwidth=1e9)
    >>> round(edge.step(1e-3, 318.45 * q, 0.0) / q, 3)  # needed 0.45 count past edge 318
    -0.15
    >>> round(edge.step(1e-3, 318.55 * q, 0.0) / q, 3)  # past the middle: edge 318 kept
    -0.25
    >>> round(edge.step(1e-3, 318.65 * q, 0.0) / q, 3)  # 0.65 past it: edge 319 taken
    0.05
    """

    def __init__(self, count: float, near: float, switch: float, bandwidth: float) -> None:
        self.count = count
        self.near = near
        self.switch = switch
        self.bandwidth = bandwidth
        self.reset()

    def reset(self) -> None:
        """Forget the edge and the needed angle; the shift is 0 again."""
        self.shift = 0.0
        self.edge: float | None = None
        self.needed = 0.0

    def step(self, h: float, needed: float, any_edge: float) -> float:
        """The shift for the next step (rad).

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        needed : float
            Where the hold would hold the motor without the shift (rad).
        any_edge : float
            The angle of one of the encoder's edges (rad, in the same angles): the others
            lie whole counts from it.

        Returns
        -------
        float
            The shift (rad), also kept as :attr:`shift`; always 0 with ``near`` ≥ 0.5.
        """
        if self.near >= 0.5:  # off: the mean is never further from an edge
            return self.shift
        q = self.count
        if self.edge is None:  # the low-pass starts at the first value
            self.needed = needed
        else:
            self.needed += (needed - self.needed) * (1.0 - lowpass_pole(self.bandwidth, h))
        if self.edge is None or abs(self.needed - self.edge) > (0.5 + self.switch) * q:
            self.edge = any_edge + q * round((self.needed - any_edge) / q)
        off = self.needed - self.edge
        beyond = abs(off) - self.near * q
        self.shift = -math.copysign(beyond, off) if beyond > 0.0 else 0.0
        return self.shift


def hold_edge(encoder_cpr: int) -> HoldEdge | None:
    """The hold's :class:`HoldEdge` for an encoder of ``encoder_cpr`` counts per
    revolution, with ``defaults.HOLD_EDGE_NEAR``, ``HOLD_EDGE_SWITCH`` and
    ``HOLD_EDGE_BANDWIDTH``; None without an encoder (``encoder_cpr`` 0).

    Examples
    --------
    >>> hold_edge(0) is None, hold_edge(2000).near
    (True, 0.3)
    """
    if encoder_cpr <= 0:
        return None
    return HoldEdge(
        2.0 * math.pi / encoder_cpr,
        defaults.HOLD_EDGE_NEAR,
        defaults.HOLD_EDGE_SWITCH,
        defaults.HOLD_EDGE_BANDWIDTH,
    )
