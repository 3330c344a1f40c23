"""Accuracy rows of the whole-chain identification (part of ``arcosim bench accuracy``).

Three chains, realistic sensors, the ``identification`` scenario (40 lines 3–150
rad/s, 3 A peak, 20 s), one run per seed; only the actuator is known, the number of
masses is read from the record (``masses="auto"``), through
:func:`~arcosim.identify_drive` as ``arcosim identify`` runs it. Per chain: how often
the verdict was ``trusted`` (the reasons of every untrusted seed kept), how often the
right n was chosen, the largest |error| of any J_i and k_i over the seeds, how often
the B_i lie within 2 standard errors of the truth (all, and the worst B_i over the
seeds), and the identification's time.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

import numpy as np

from arcosim import SCENARIOS, identify_drive
from arcosim.experiments import markdown_table, percent_error
from benchmarks.cases import ACTUATOR, CASES, ENCODER_CPR, G_DIST, Case, run_case

#: The chains: the bench and two with unequal springs (n = 2 and n = 5).
CHAINS = (
    CASES[0],
    Case("two-mass, unequal springs", (4e-4, 8e-4), (0.3, 0.2), (2e-5, 1.5e-5)),
    Case(
        "five-mass, unequal springs",
        (2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4),
        (0.4, 0.3, 0.5, 0.35, 0.45),
        (1.5e-5,) * 5,
    ),
)


def score_chain(case: Case, seeds: Sequence[int], progress: Callable[[str], None]) -> dict:
    """Whole-chain identification of ``case`` over ``seeds`` (JSON-able summary): the
    verdict per seed (``untrusted`` maps each untrusted seed to its reasons), n, the
    errors (%) and the B_i's standard errors (% of the truth)."""
    chosen, J_errors, k_errors, B_errors, B_sigmas, seconds = [], [], [], [], [], []
    verdicts: list[str] = []
    untrusted: dict[str, list[str]] = {}
    for seed in seeds:
        progress(f"whole chain, {case.name}: seed {seed}")
        log = run_case(case, SCENARIOS["identification"], seed)
        started = time.perf_counter()
        result = identify_drive(
            log["time"],
            log["i_a"],
            log["omega_m"],
            log["theta_m"],
            k_t=ACTUATOR.k_to,
            J_m=ACTUATOR.J_mo,
            encoder_cpr=ENCODER_CPR,
            D_m=ACTUATOR.D_m,
            f_c=ACTUATOR.f_c,
            g_dist=G_DIST,
        )
        seconds.append(time.perf_counter() - started)
        choice = result.choice
        verdicts.append(result.verdict.word)
        if not result.verdict.trusted:
            untrusted[str(seed)] = list(result.verdict.reasons)
        chosen.append(choice.n)
        if choice.n != case.n:
            continue
        p, n = choice.fit.values, case.n  # the fit's vector stacks J, k and B
        J, k, B = (list(p[i * n : (i + 1) * n]) for i in range(3))
        B_std = choice.fit.std[2 * case.n :]
        J_errors.append([percent_error(a, b) for a, b in zip(J, case.J)])
        k_errors.append([percent_error(a, b) for a, b in zip(k, case.k)])
        B_errors.append([percent_error(a, b) for a, b in zip(B, case.B)])
        B_sigmas.append([100.0 * s / b for s, b in zip(B_std, case.B)])
    inside = [sum(abs(e[i]) <= 2 * s[i] for e, s in zip(B_errors, B_sigmas)) for i in range(case.n)]
    right = [n == case.n for n in chosen]
    return {
        "seeds": len(seeds),
        "trusted": verdicts.count("trusted"),
        "verdicts": verdicts,
        "untrusted_reasons": untrusted,
        "masses_chosen": chosen,
        "right_n": int(sum(right)),
        "J_error_percent": J_errors,
        "k_error_percent": k_errors,
        "B_error_percent": B_errors,
        "B_std_percent": B_sigmas,
        "B_inside_2_sigma": [int(x) for x in inside],
        "B_count": len(B_errors),
        "seconds": seconds,
    }


def markdown(rows: dict[str, dict]) -> str:
    """The whole-chain table."""
    header = [
        "chain",
        "trusted",
        "n right",
        "max abs J_i error %",
        "max abs k_i error %",
        "B_i within 2σ",
        "worst B_i within 2σ",
        "B_i error % (median abs)",
        "seconds (median / max)",
    ]
    cells = []
    for name, r in rows.items():
        worst = {
            key: f"{np.max(np.abs(r[key])):.2f}" if r[key] else "—"
            for key in ("J_error_percent", "k_error_percent")
        }
        B_median = f"{np.median(np.abs(r['B_error_percent'])):.0f}" if r["B_error_percent"] else "—"
        inside, count = r["B_inside_2_sigma"], r["B_count"]
        cells.append(
            [
                name,
                f"{r['trusted']} of {r['seeds']}",
                f"{r['right_n']} of {r['seeds']}",
                worst["J_error_percent"],
                worst["k_error_percent"],
                f"{sum(inside)} of {count * len(inside)}",
                f"{min(inside, default=0)} of {count}",
                B_median,
                f"{np.median(r['seconds']):.1f} / {np.max(r['seconds']):.1f}",
            ]
        )
    return markdown_table(header, cells) + "\n"
