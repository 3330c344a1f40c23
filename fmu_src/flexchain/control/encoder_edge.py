"""The encoder's last crossed edge: a motor velocity that a dither across one edge leaves at 0.

An incremental encoder read at the sample gives the count the motor is in; its backward
difference is one count per step (3.1 rad/s at 2000 counts and 1 ms) on every step the
count changes. A motor held still on an edge crosses it back and forth, and that
difference reads ±3.1 rad/s for a motion of a fraction of a count: a controller with a
velocity gain turns each such hop into a current kick (0.25 A on the control benchmark's
two-mass chain, five times its friction's current) that keeps the motor hopping.

Where the motor was last known exactly is the edge it last crossed: the lower edge of
the count it rose into, the upper edge of the count it fell into. Its backward difference
counts a count for a crossing that goes on in the same direction (as the plain
difference does while the motor moves) and nothing for one that returns over the same
edge (a dither). Measured on ``arcosim bench control``'s chains
(docs/design/encoder-edge-velocity.md): fed to the controller's state feedback and DOB in
place of the plain difference, it took
the runs within the residual criterion from 23 to 34 of 36 and the motor's limit cycle
within one count from 0 to 8. The controller uses it only where it cancels Coulomb
friction: on a frictionless motor the plain difference's kick at an edge is what holds
the motor there.

The edges also tell which way a slow motor slides (:meth:`CrossedEdge.sliding`): one that
crosses new edges one way, each within ``defaults.SLIDING_INTERVAL`` of the last, is
moving that way until the next edge is due. Below a count per step its velocity reads 0
on most steps, and a DOB that took it as stuck knew the reaction torque only within the
band ±f_c of static friction; told the heading, it removes the kinetic friction instead.
:meth:`CrossedEdge.heading` weighs them against a heading assumed otherwise (the
reference's during a move), which an edge crossed the other way overrules
(docs/control.md).
"""

from __future__ import annotations


class CrossedEdge:
    """The last encoder edge the motor crossed (rad) and the velocity from it (rad/s).

    The encoder reads the lower edge of the count the motor is in (its angle rounded
    down to a whole count), the convention of the plant FMU and of
    :meth:`~arcosim.fmu.flexchain.observer.ObserverSettings.angle_offset`.

    Parameters
    ----------
    theta_m0 : float
        The encoder's reading at the start (rad).
    half_count : float
        Half a count (rad); 0 for an exact angle, which makes :meth:`step` the plain
        backward difference.

    Attributes
    ----------
    edge : float
        The last crossed edge (rad); the middle of the first count until the motor
        leaves it.
    direction : float
        The way the edge last moved: +1, −1, or 0 before it has.
    interval : float
        Time between the edge's last two moves when both went the same way (s); 0
        otherwise, and once the reading has gone back over the last edge.
    since : float
        Time since the edge last moved (s).

    Examples
    --------
    >>> count = 1.0
    >>> e = CrossedEdge(0.0, count / 2)
    >>> [e.step(1.0, reading) for reading in (1.0, 0.0, 1.0, 2.0, 1.0)]  # rad/s
    [0.5, 0.0, 0.0, 1.0, 0.0]
    """

    def __init__(self, theta_m0: float, half_count: float) -> None:
        self.half_count = half_count
        self.reading = theta_m0
        self.edge = theta_m0 + half_count
        self.direction = 0.0
        self.interval = 0.0
        self.since = 0.0

    def step(self, h: float, theta_m: float) -> float:
        """Take the encoder's reading at the sample; return the edge's velocity over the step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        theta_m : float
            The encoder's reading (rad, whole counts).

        Returns
        -------
        float
            (edge − previous edge) / h (rad/s).
        """
        edge = self.edge
        if theta_m > self.reading:
            edge = theta_m
        elif theta_m < self.reading:
            edge = theta_m + 2.0 * self.half_count
        velocity = (edge - self.edge) / h
        self.since += h
        # a new edge is at least half a count away; back over the same edge it may differ
        # by rounding (a reading plus a count against the next reading)
        if abs(edge - self.edge) > 0.5 * self.half_count:
            direction = 1.0 if edge > self.edge else -1.0
            self.interval = self.since if direction == self.direction else 0.0
            self.direction, self.since = direction, 0.0
        elif (theta_m - self.reading) * self.direction < 0.0:
            self.interval = 0.0  # back over the same edge: the motor turned, no longer a slide
        self.reading, self.edge = theta_m, edge
        return velocity

    def sliding(self, within: float, late: float = 0.0) -> float:
        """The way the motor slides (+1 or −1), or 0 when the edges do not show it.

        It slides the way the edge last moved when that move followed one the same way
        at most ``within`` earlier, until as long again, and ``late`` more, has passed
        without another.

        Parameters
        ----------
        within : float
            The longest time between two edges of a slide (s); a count over it is the
            slowest speed taken as sliding.
        late : float
            How much later than the last interval the next edge may come and the motor
            still be taken as sliding (s, ≥ 0; default 0). The samples see each edge up
            to a step after it is crossed, so at a constant speed the intervals they
            read differ by a step, and a time since equal to the interval may fall
            either side of it by the steps' last bits: ``late = 2 h`` keeps a steady or
            slowing slide sliding.

        Returns
        -------
        float
            −1, 0 or +1.

        Examples
        --------
        >>> e = CrossedEdge(0.0, 0.5)
        >>> [(e.step(1.0, reading), e.sliding(2.0)) for reading in (1.0, 2.0, 2.0, 2.0)]
        [(0.5, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
        """
        since = self.since
        if 0.0 < self.interval and _within(self.interval, within) and since <= self.interval + late:
            return self.direction
        return 0.0

    def heading(self, expected: float, within: float) -> float:
        """The way the motor moves, the edges weighed against the heading ``expected``.

        The edges' slide where they show one (:meth:`sliding`); else 0 for ``within``
        after the edge moved against ``expected`` (the motor turned round: the samples
        decide); else ``expected``.

        Parameters
        ----------
        expected : float
            The heading otherwise assumed (−1, 0 or +1), e.g. the reference's.
        within : float
            As in :meth:`sliding` (s).

        Returns
        -------
        float
            −1, 0 or +1.

        Examples
        --------
        >>> e = CrossedEdge(0.0, 0.5)
        >>> _ = e.step(1.0, -1.0)  # an edge against the expected +1: the motor turned round
        >>> [e.heading(1.0, 2.0)] + [(e.step(1.0, -1.0), e.heading(1.0, 2.0))[1] for _ in range(3)]
        [0.0, 0.0, 0.0, 1.0]
        """
        edges = self.sliding(within)
        if edges != 0.0:
            return edges
        if expected != 0.0 and self.direction == -expected and _within(self.since, within):
            return 0.0
        return expected


def _within(time: float, limit: float) -> bool:
    """``time ≤ limit`` (s), a float sum of whole steps up to the limit counting as within."""
    return time <= limit + 1e-9
