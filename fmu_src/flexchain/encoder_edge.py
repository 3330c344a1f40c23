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
edge (a dither). Measured on ``arcosim bench control``'s chains (docs/development.md):
fed to the controller's state feedback and DOB in place of the plain difference, it took
the runs within the residual criterion from 23 to 34 of 36 and the motor's limit cycle
within one count from 0 to 8. The controller uses it only where it cancels Coulomb
friction: on a frictionless motor the plain difference's kick at an edge is what holds
the motor there.
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
        self.reading, self.edge = theta_m, edge
        return velocity
