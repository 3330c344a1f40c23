"""Identify the independent simulator's logs (:mod:`benchmarks.simulators.field_sim`) from tests."""

from __future__ import annotations

from arcosim.identification.drive_identification import DriveIdentification, identify_drive
from benchmarks.simulators import field_sim


def identify_log(
    d: field_sim.Drive,
    log: field_sim.Log,
    friction_given: bool = True,
    J_m: float | None = None,
    **kw: object,
) -> DriveIdentification:
    """:func:`~arcosim.identification.drive_identification.identify_drive` on ``log`` of drive
    ``d``:
    its k_t and encoder counts given, J_m the drive's unless ``J_m`` (kg·m²) is, the
    friction D_m, f_c given when ``friction_given``; ``kw`` passed on (``masses``,
    ``load``, …)."""
    friction = {"D_m": d.D_m, "f_c": d.f_c} if friction_given else {}
    return identify_drive(
        log.time,
        log.i_a,
        log.omega_m,
        log.theta_m,
        k_t=d.k_t,
        J_m=d.J_m if J_m is None else J_m,
        encoder_cpr=d.counts,
        **friction,
        **kw,
    )
