"""Small dense linear systems solved in place, for the compiled right-hand sides.

The equations of motion of a constrained system solve, at every evaluation, the index-1
(KKT) system ``[[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; r]`` of a few to a few tens of unknowns
(``docs/theory.md``, [L] eq. (6.60)). For such sizes the cost of ``numpy.linalg.solve`` is
its overhead (copies to Fortran order, a LAPACK call, allocations), several times the
arithmetic; this is the textbook algorithm on the caller's storage instead. LAPACK's ``dgesv``
stays the reference it is tested against (``tests/kernels/test_linalg.py``).
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["solve_augmented", "solve_spd_augmented"]


@kernel
def solve_augmented(A, n):
    """Solve ``A[:n, :n] x = A[:n, n]`` in place by Gaussian elimination with partial
    pivoting (Golub & Van Loan, *Matrix Computations*, alg. 3.4.1): ``x`` overwrites
    ``A[:n, n]`` and the matrix is destroyed.

    Parameters
    ----------
    A : (n, ≥ n + 1) float array
        The augmented matrix ``[K | r]``.
    n : int

    Returns
    -------
    bool
        False when a pivot is zero or not finite (a singular or non-finite system; ``x`` is then
        meaningless), True otherwise.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[0.0, 2.0, 4.0], [1.0, 1.0, 3.0]])   # 2y = 4, x + y = 3
    >>> bool(solve_augmented(A, 2)), A[:, 2].tolist()
    (True, [1.0, 2.0])
    """
    for k in range(n):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            a = abs(A[i, k])
            if a > big:
                big = a
                p = i
        if not (big > 0.0 and big < 1e308):  # zero, infinite or NaN
            return False
        if p != k:
            for j in range(k, n + 1):
                tmp = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = tmp
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            factor = A[i, k] * inv
            if factor != 0.0:
                for j in range(k + 1, n + 1):
                    A[i, j] -= factor * A[k, j]
    for k in range(n - 1, -1, -1):
        s = A[k, n]
        for j in range(k + 1, n):
            s -= A[k, j] * A[j, n]
        A[k, n] = s / A[k, k]
    return True


@kernel
def solve_spd_augmented(A, n):
    """Solve ``A[:n, :n] x = A[:n, n]`` for a symmetric positive definite matrix (a mass
    matrix) in place by Cholesky's factorisation ``A = L Lᵀ`` (Golub & Van Loan, alg. 4.2.1),
    half the work of :func:`solve_augmented`: ``x`` overwrites ``A[:n, n]``, ``L`` the lower
    triangle; only the lower triangle of the matrix is read.

    Returns
    -------
    bool
        False when the matrix is not (numerically) positive definite or not finite; ``A`` is
        then partly overwritten.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[4.0, 2.0, 2.0], [2.0, 3.0, 5.0]])   # [[4, 2], [2, 3]] x = [2, 5]
    >>> bool(solve_spd_augmented(A, 2)), A[:, 2].round(12).tolist()
    (True, [-0.5, 2.0])
    """
    for j in range(n):
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        if not (d > 0.0 and d < 1e308):
            return False
        d = np.sqrt(d)
        A[j, j] = d
        inv = 1.0 / d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s * inv
    for i in range(n):  # L z = b
        s = A[i, n]
        for k in range(i):
            s -= A[i, k] * A[k, n]
        A[i, n] = s / A[i, i]
    for i in range(n - 1, -1, -1):  # Lᵀ x = z
        s = A[i, n]
        for k in range(i + 1, n):
            s -= A[k, i] * A[k, n]
        A[i, n] = s / A[i, i]
    return True
