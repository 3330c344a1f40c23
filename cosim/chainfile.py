"""A chain file: the JSON report of a whole-chain fit, read back as the chain it holds.

``arcosim identify LOG.csv --method whole-chain --out chain.json`` (or ``--json``) writes
every load inertia ``J[i]``, stiffness ``k[i]`` and damping ``B[i]`` under the observer's
own parameter names, with ``masses`` and, when fitted, the motor friction ``D_m``,
``f_c``, and their standard errors under ``std``. :func:`read_chain` reads those values
back as a :class:`~arcosim.fmu.flexchain.chain.Chain` (``arcosim identify --method
load-torque --chain chain.json`` does), ignoring the rest of the report (evidence,
assumptions); a chain's :meth:`~arcosim.fmu.flexchain.chain.Chain.to_json` writes the
same keys.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

from arcosim.build.recipes import MAX_MASSES, MIN_MASSES
from arcosim.errors import UserError
from arcosim.fmu.flexchain.chain import INDEXED, Chain
from arcosim.logs import read_text_file

#: The chain's parameters, ``J[i]``, ``k[i]``, ``B[i]``, by their name before ``[``.
CHAIN_PARAMETERS = INDEXED
#: The other values a chain file may carry: the number of masses, the motor inertia and
#: friction.
OTHER_VALUES = ("masses", "J_m", "D_m", "f_c")


class ChainFileError(UserError):
    """A chain file that is not a JSON object of finite numbers with every J[i], k[i], B[i]."""


def read_chain(path: str | Path) -> Chain:
    """The chain of a whole-chain report: ``J[i]``, ``k[i]``, ``B[i]`` and ``masses``.

    Parameters
    ----------
    path : str or Path
        A UTF-8 JSON file holding one object, as ``arcosim identify --method whole-chain
        --out FILE.json`` (or :meth:`Chain.to_json <arcosim.fmu.flexchain.chain.Chain.to_json>`)
        writes it: ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]`` (N·m·s/rad) for i = 1 …
        n, and optionally ``masses`` (n, a count), the motor inertia ``J_m`` (kg·m²), the
        motor friction ``D_m`` (N·m·s/rad), ``f_c`` (N·m) and ``std``, their standard
        errors by the same names. Other keys are ignored.

    Returns
    -------
    Chain
        The values, copied exactly; n from ``masses`` (counted from the ``J[i]`` when the
        file does not give it).

    Raises
    ------
    ChainFileError
        When the file is not JSON, not an object, a value is not a finite number, or
        ``masses`` is not a whole number or not a supported number of masses (1 to
        20), or a ``J[i]``, ``k[i]`` or ``B[i]`` is missing, or a ``J[i]``, ``k[i]`` or
        ``J_m`` is not positive or a ``B[i]``, ``D_m`` or ``f_c`` negative, or ``masses =
        0`` beside ``J[i]``, or a standard error is not a number ≥ 0, or the report is a
        rigid drive's (masses = 0: the message gives the ``--set`` for the observer
        instead), or it holds no ``J[i]`` at all (an output-error
        report: the message names the whole-chain fit that writes a chain); the message
        starts with the file's name.
    UserError
        When the file is missing, a folder or not UTF-8 text
        (:func:`arcosim.logs.read_text_file`).

    Examples
    --------
    >>> import json, tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "chain.json"
    >>> report = {"J[1]": 1e-4, "k[1]": 50.0, "B[1]": 1e-3, "std": {"J[1]": 1e-6}}
    >>> _ = path.write_text(json.dumps(report))
    >>> chain = arcosim.read_chain(path)
    >>> chain.n, chain.J, chain.k, chain.B, chain.J_std
    (1, (0.0001,), (50.0,), (0.001,), (1e-06,))
    """
    path = Path(path)
    try:
        data = json.loads(read_text_file(path, "chain"))
    except ValueError as error:
        raise ChainFileError(f"{path}: cannot read it as JSON ({error})") from None
    if not isinstance(data, dict):
        raise ChainFileError(f"{path}: expected a JSON object with J[i], k[i], B[i]")
    data = _bracketed(data)
    chain = {k: v for k, v in data.items() if _is_chain_value(k)}
    for key, value in chain.items():
        _check_number(path, key, value)
    inertias = sum(k.startswith("J[") for k in chain)
    masses = chain.get("masses", inertias)
    if masses != int(masses):
        raise ChainFileError(f"{path}: masses = {masses} is not a whole number")
    if masses == 0 and inertias:
        raise ChainFileError(
            f"{path}: masses = 0 (a rigid drive) but it holds J[1]"
            + (f" … J[{inertias}]" if inertias > 1 else "")
            + f": write masses = {inertias} to read its chain, or remove the J[i], k[i], B[i]"
        )
    if masses == 0 and isinstance(data.get("J_load"), (int, float)):
        raise ChainFileError(
            f"{path}: a rigid drive (masses = 0) has no chain: give the observer its load "
            f"inertia and friction, --set dJm={data['J_load']:.6g} "
            + " ".join(f"--set {k}={data[k]:.6g}" for k in ("D_m", "f_c") if k in data)
            + " (the DOB's tau_reac_hat is then the load torque)"
        )
    if masses == 0:
        raise ChainFileError(f"{path}: {_no_chain(data)}")
    if not MIN_MASSES <= masses <= MAX_MASSES:
        raise ChainFileError(
            f"{path}: masses = {int(masses)}: the number of load masses must be "
            f"{MIN_MASSES} to {MAX_MASSES}"
        )
    n = int(masses)
    missing = [
        f"{p}[{i}]" for p in CHAIN_PARAMETERS for i in range(1, n + 1) if f"{p}[{i}]" not in chain
    ]
    if missing:
        raise ChainFileError(f"{path}: missing {', '.join(missing)}")
    for key, value in chain.items():
        _check_sign(path, key, value)
    std = _bracketed(data["std"]) if isinstance(data.get("std"), dict) else {}
    try:
        return Chain.from_json({**chain, "masses": n, "std": std})
    except ValueError as error:  # a standard error that is not a number >= 0
        raise ChainFileError(f"{path}: std: {str(error).removeprefix('Chain: ')}") from None


def _bracketed(data: dict) -> dict:
    """A report written with ``--tool-names`` under the observer's names: J_1 as J[1]."""
    return {re.sub(r"^([JkB])_(\d+)$", r"\1[\2]", k): v for k, v in data.items()}


def _no_chain(data: dict) -> str:
    """What a file with no ``J[i]`` holds instead, and the fit that writes a chain."""
    method = data.get("method")
    kind = f"an {method} report" if method == "output-error" else "no J[1], k[1], B[1]"
    what = " (the uniform chain's k_hat, B_hat)" if method == "output-error" else ""
    return (
        f"{kind}{what}, not a chain: write one with "
        "arcosim identify LOG.csv --method whole-chain --out chain.json"
    )


def _is_chain_value(key: str) -> bool:
    """Whether a report's key is one :func:`read_chain` keeps: ``J[…]``, ``k[…]``,
    ``B[…]`` or one of :data:`OTHER_VALUES`."""
    indexed = key.split("[")[0] in CHAIN_PARAMETERS and key.endswith("]")
    return indexed or key in OTHER_VALUES


def _check_number(path: Path, key: str, value: object) -> None:
    """Refuse a value that is not a finite JSON number (a Boolean is not one)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ChainFileError(f"{path}: {key} = {value!r:.40} is not a number")
    if not math.isfinite(value):
        raise ChainFileError(f"{path}: {key} = {value} is not a finite number")


def _check_sign(path: Path, key: str, value: float) -> None:
    """Refuse a value no physical chain has: an inertia or stiffness not above zero, a
    damping or friction below zero."""
    name = key.split("[")[0]
    if name in ("J", "k") and not value > 0:
        raise ChainFileError(f"{path}: {key} = {value:g} must be > 0")
    if name == "J_m" and not value > 0:
        raise ChainFileError(f"{path}: {key} = {value:g} must be > 0")
    if name in ("B", "D_m", "f_c") and not value >= 0:
        raise ChainFileError(f"{path}: {key} = {value:g} must be >= 0")
