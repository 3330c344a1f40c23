"""Small dense linear algebra on lists of lists (standard library only).

Matrices are ``list[list[float]]`` (row-major), vectors ``list[float]``. Sizes here
are tens, not thousands; the point is to need nothing but Python.
"""

from __future__ import annotations

import math
from operator import mul

Matrix = list[list[float]]
Vector = list[float]


def zeros(rows: int, cols: int) -> Matrix:
    """A ``rows × cols`` matrix of zeros."""
    return [[0.0] * cols for _ in range(rows)]


def identity(n: int) -> Matrix:
    """The ``n × n`` identity."""
    m = zeros(n, n)
    for i in range(n):
        m[i][i] = 1.0
    return m


def transpose(a: Matrix) -> Matrix:
    """``aᵀ``."""
    return [list(col) for col in zip(*a)]


def matmul(a: Matrix, b: Matrix) -> Matrix:
    """``a @ b`` for ``(r × k) @ (k × c)``."""
    columns = list(zip(*b))
    return [[math.fsum(map(mul, row, col)) for col in columns] for row in a]


def matvec(a: Matrix, x: Vector) -> Vector:
    """``a @ x``."""
    return [math.fsum(map(mul, row, x)) for row in a]


def add(a: Matrix, b: Matrix, scale_b: float = 1.0) -> Matrix:
    """``a + scale_b * b``."""
    return [[p + scale_b * q for p, q in zip(ra, rb)] for ra, rb in zip(a, b)]


def scaled(a: Matrix, s: float) -> Matrix:
    """``s * a``."""
    return [[s * p for p in row] for row in a]


def norm_inf(a: Matrix) -> float:
    """Largest absolute row sum."""
    return max((math.fsum(abs(p) for p in row) for row in a), default=0.0)


def solve(a: Matrix, b: Matrix) -> Matrix:
    """Solve ``a @ x = b`` by Gaussian elimination with partial pivoting.

    Parameters
    ----------
    a : Matrix
        Shape ``(n, n)``.
    b : Matrix
        Right-hand sides, shape ``(n, m)``.

    Returns
    -------
    Matrix
        ``x``, shape ``(n, m)``.

    Raises
    ------
    ValueError
        If ``a`` is singular to working precision.
    """
    lu = [row[:] for row in a]
    x = [row[:] for row in b]
    _eliminate(lu, x)
    _substitute_back(lu, x)
    return x


def _eliminate(lu: Matrix, x: Matrix) -> None:
    """Forward elimination with partial pivoting, in place: ``lu`` becomes upper
    triangular and ``x`` the right-hand sides that go with it.

    Raises
    ------
    ValueError
        If ``lu`` is singular to working precision.
    """
    n = len(lu)
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(lu[r][col]))
        if lu[pivot][col] == 0.0 or not math.isfinite(lu[pivot][col]):
            raise ValueError("matrix is singular to working precision")
        if pivot != col:
            lu[col], lu[pivot] = lu[pivot], lu[col]
            x[col], x[pivot] = x[pivot], x[col]
        inv = 1.0 / lu[col][col]
        for r in range(col + 1, n):
            f = lu[r][col] * inv
            if f != 0.0:
                row_r, row_c = lu[r], lu[col]
                for c in range(col, n):
                    row_r[c] -= f * row_c[c]
                xr, xc = x[r], x[col]
                for c in range(len(xr)):
                    xr[c] -= f * xc[c]


def _substitute_back(lu: Matrix, x: Matrix) -> None:
    """Back substitution in place: ``x`` becomes the solution of the upper triangular
    ``lu @ x = x``."""
    n = len(lu)
    for col in range(n - 1, -1, -1):
        inv = 1.0 / lu[col][col]
        xc = x[col]
        for c in range(len(xc)):
            xc[c] *= inv
        for r in range(col):
            f = lu[r][col]
            if f != 0.0:
                xr = x[r]
                for c in range(len(xr)):
                    xr[c] -= f * xc[c]


def expm(a: Matrix) -> Matrix:
    """Matrix exponential by scaling and squaring with a (6, 6) Padé approximant.

    Golub & Van Loan, *Matrix Computations*, Algorithm 11.3.1: scale so that
    ``‖a‖∞ / 2^s ≤ 1/2``, where the approximant's relative error is below 1e-16.

    Parameters
    ----------
    a : Matrix
        Shape ``(n, n)``, finite (dimensionless: a time step is already in it).

    Returns
    -------
    Matrix
        ``e^a``, shape ``(n, n)``.

    Raises
    ------
    ValueError
        If ``a`` has a non-finite entry.
    """
    n = len(a)
    norm = norm_inf(a)
    if not math.isfinite(norm):
        raise ValueError("matrix exponential of a matrix with non-finite entries")
    s = max(0, math.ceil(math.log2(norm / 0.5))) if norm > 0.5 else 0
    a = scaled(a, 0.5**s)
    q = 6
    c = 0.5
    x = a
    num = add(identity(n), a, c)
    den = add(identity(n), a, -c)
    positive = True
    for k in range(2, q + 1):
        c = c * (q - k + 1) / (k * (2 * q - k + 1))
        x = matmul(a, x)
        num = add(num, x, c)
        den = add(den, x, c if positive else -c)
        positive = not positive
    e = solve(den, num)
    for _ in range(s):
        e = matmul(e, e)
    return e


def hold(A: Matrix, E: Matrix, h: float) -> tuple[Matrix, Matrix]:
    """The zero-order hold: ``s ← F s + Γ w`` for ``ṡ = A s + E w`` with w held over a step.

    ``F = e^{A h}`` and its input integral ``Γ = ∫_0^h e^{A t} dt · E`` from one matrix
    exponential of the augmented ``[[A h, E h], [0, 0]]`` (Van Loan 1978); the one
    pure-Python home of the hold (numpy's:
    :func:`arcosim.identification.fit.linear_model.hold`).

    Parameters
    ----------
    A : Matrix
        Shape ``(m, m)``, per second (1/s, 1/s², …).
    E : Matrix
        Shape ``(m, p)``, the state's rate per unit of each input.
    h : float
        Step (s). Give 1 when ``A`` and ``E`` carry the step already (``A h``, ``E h``):
        the products by 1 are exact.

    Returns
    -------
    tuple of (Matrix, Matrix)
        ``F``, shape ``(m, m)`` (dimensionless), and ``Γ``, shape ``(m, p)`` (the state's
        unit per unit of input).

    Examples
    --------
    A rigid body (θ, ω) under a torque held for 0.1 s: Γ = [h²/2, h].

    >>> F, G = hold([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]], 0.1)
    >>> F[0][1], [round(g[0], 15) for g in G]
    (0.1, [0.005, 0.1])
    """
    m, p = len(A), len(E[0])
    M = zeros(m + p, m + p)
    for r in range(m):
        M[r][:m] = [h * a for a in A[r]]
        M[r][m:] = [h * e for e in E[r]]
    X = expm(M)
    return [row[:m] for row in X[:m]], [row[m:] for row in X[:m]]
