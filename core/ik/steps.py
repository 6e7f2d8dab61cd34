"""One joint update of each Jacobian method: (J, e) -> dq, batched.

``jac`` is (B, m, n) (m = 3 for position targets, 6 for pose targets, linear rows
first), ``err`` is (B, m): the task-space error, position [m] then rotation vector [rad].
Every rule is finite for any finite input: singular Jacobians give a bounded (possibly
zero) step, never an exception.
"""

from __future__ import annotations

import numpy as np


CHOLESKY_MIN_BATCH = 512
"""Batch from which :func:`cholesky_solve` factorises entry by entry: measured at k = 5-7, it took 1.3x
``np.linalg.solve``'s time at 300 matrices and 0.4-0.5x at 10,000."""


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.solve(a, b[..., None])[..., 0]


def full_rank(jac: np.ndarray, rcond: float) -> np.ndarray:
    """(B,) True where J has rank min(m, n): sigma_min > rcond * sigma_max > 0."""
    sigma = np.linalg.svd(jac, compute_uv=False)
    return sigma[:, -1] > rcond * sigma[:, 0]


def jacobian_inverse_step(jac: np.ndarray, err: np.ndarray, rcond: float) -> np.ndarray:
    """dq = J^-1 e for square J; 0 where J is singular (sigma_min <= rcond sigma_max)."""
    dq = np.zeros(jac.shape[::2])
    ok = full_rank(jac, rcond)
    if np.any(ok):
        dq[ok] = _solve(jac[ok], err[ok])
    return dq


def pseudo_inverse_step(jac: np.ndarray, err: np.ndarray, rcond: float) -> np.ndarray:
    """dq = J+ e with the lecture's forms of J+, chosen by the shape and rank of J.

    - m >= n (tall or square) and rank n: left form (J^T J)^-1 J^T, the slide's;
    - m < n (wide, a redundant chain) and rank m: right form J^T (J J^T)^-1, the form of
      the slide's control expression;
    - rank < min(m, n) (sigma_min <= rcond sigma_max): the SVD pseudo-inverse with the
      singular values at or below rcond sigma_max dropped.

    All three are the Moore-Penrose pseudo-inverse where they apply. The Gram matrices
    square the condition number, so ``rcond`` ~ 1e-6 keeps their solves at ~1e-12
    relative accuracy.
    """
    b, m, n = jac.shape
    dq = np.empty((b, n))
    ok = full_rank(jac, rcond)
    j, e = jac[ok], err[ok]
    jt = np.swapaxes(j, 1, 2)
    if m >= n:
        dq[ok] = _solve(jt @ j, np.einsum("bnm,bm->bn", jt, e))
    else:
        dq[ok] = np.einsum("bnm,bm->bn", jt, _solve(j @ jt, e))
    if not np.all(ok):
        dq[~ok] = np.einsum("bnm,bm->bn", np.linalg.pinv(jac[~ok], rcond=rcond), err[~ok])
    return dq


def transpose_step(jac: np.ndarray, err: np.ndarray) -> np.ndarray:
    """dq = alpha J^T e with Buss' step alpha = <e, J J^T e> / <J J^T e, J J^T e>.

    alpha minimises |e - alpha J J^T e|, the linearised error after the step, so the
    step neither overshoots nor crawls; alpha = 0 where J J^T e = 0.
    """
    grad = np.einsum("bmn,bm->bn", jac, err)
    jjte = np.einsum("bmn,bn->bm", jac, grad)
    denom = np.sum(jjte * jjte, axis=1)
    alpha = np.sum(err * jjte, axis=1) / np.where(denom > 0, denom, 1.0)
    return np.where(denom > 0, alpha, 0.0)[:, None] * grad


def positive_definite(sym: np.ndarray) -> np.ndarray:
    """(B,) True where the symmetric (B, k, k) matrix has a Cholesky factorisation (all pivots > 0).

    The factorisation runs column by column over the whole batch at once: ~k^3 / 6 element-wise
    operations on (B,) arrays, where a batched eigenvalue solver pays LAPACK's overhead per matrix.
    """
    k = sym.shape[-1]
    lower = np.zeros_like(sym)
    ok = np.ones(len(sym), bool)
    for j in range(k):
        pivot = sym[:, j, j] - np.einsum("bi,bi->b", lower[:, j, :j], lower[:, j, :j])
        ok &= pivot > 0
        root = np.sqrt(np.where(ok, pivot, 1.0))
        lower[:, j, j] = root
        below = sym[:, j + 1:, j] - np.einsum("bri,bi->br", lower[:, j + 1:, :j], lower[:, j, :j])
        lower[:, j + 1:, j] = below / root[:, None]
    return ok


def damped_least_squares_step(jac: np.ndarray, err: np.ndarray, threshold: float, damping_max: float) -> np.ndarray:
    """dq = J^T (J J^T + lambda^2 I)^-1 e with damping that adapts near singularities.

    lambda^2 = damping_max^2 (1 - (sigma_min / threshold)^2) while the smallest singular
    value sigma_min of J is below ``threshold``, 0 above it (Nakamura and Hanafusa;
    Chiaverini): the exact pseudo-inverse away from singularities, and near them each
    1 / sigma_i becomes sigma_i / (sigma_i^2 + lambda^2), finite even at sigma_i = 0.
    Computed as J^T (J J^T + lambda^2 I)^-1 e (wide or square J) or (J^T J + lambda^2 I)^-1 J^T e
    (tall J), the same matrix; sigma_min^2 is the smallest eigenvalue of that Gram matrix. The
    damping keeps the Gram matrix's smallest eigenvalue at ~lambda^2 or above (a zero Jacobian gets
    damping_max^2 I), so the solve stays well conditioned; a batched SVD costs several times the Gram
    matrix's eigenvalues and solve. sigma_min is only computed where a Cholesky factorisation of
    J J^T - threshold^2 I fails, i.e. where sigma_min < threshold and the damping depends on it.
    """
    _, m, n = jac.shape
    jt = np.swapaxes(jac, 1, 2)
    wide = m <= n
    gram = jac @ jt if wide else jt @ jac
    smin = np.full(len(gram), np.inf)  # where sigma_min >= threshold its value does not matter
    near = ~positive_definite(gram - threshold**2 * np.eye(gram.shape[-1]))
    if np.any(near):
        smin[near] = np.sqrt(np.maximum(np.linalg.eigvalsh(gram[near])[:, 0], 0.0))
    lam2 = np.where(smin < threshold, damping_max**2 * (1 - (smin / threshold) ** 2), 0.0)
    gram = gram + lam2[:, None, None] * np.eye(gram.shape[-1])
    if wide:
        return np.einsum("bnm,bm->bn", jt, _solve(gram, err))
    return _solve(gram, np.einsum("bnm,bm->bn", jt, err))



def error_damped_least_squares_step(jac: np.ndarray, err: np.ndarray, error_damping: float,
                                    damping_floor: float) -> np.ndarray:
    """dq = J^T (J J^T + lambda^2 I)^-1 e with Levenberg-Marquardt damping lambda^2 = c |e|^2 + floor^2.

    The damping follows the error instead of sigma_min (Sugihara 2011, "Solvability-unconcerned inverse
    kinematics by the Levenberg-Marquardt method"): far from the target the step is damped toward the
    gradient J^T e, which keeps it from jumping across the workspace on a linearisation that no longer
    holds; near the target lambda^2 falls to floor^2 and the step becomes the pseudo-inverse's, which
    converges quadratically. lambda^2 >= floor^2 > 0, so the Gram matrix is positive definite everywhere
    (a zero Jacobian included) and no singular value is computed. As :func:`damped_least_squares_step`,
    solved on the smaller Gram matrix: J J^T (m x m) for a wide or square J, J^T J (n x n) for a tall one
    (an under-actuated chain), the same matrix.

    Parameters
    ----------
    jac : (B, m, n) ndarray
    err : (B, m) ndarray
        Task error, position [m] then rotation vector [rad].
    error_damping : float
        c [1: lambda^2 is in the Jacobian's units squared, |e|^2 in m^2 or rad^2, added unweighted].
    damping_floor : float
        lambda at e = 0 [the Jacobian's units].

    Returns
    -------
    (B, n) ndarray
    """
    _, m, n = jac.shape
    jt = np.swapaxes(jac, 1, 2)
    wide = m <= n
    gram = jac @ jt if wide else jt @ jac
    lam2 = error_damping * np.einsum("bm,bm->b", err, err) + damping_floor**2
    gram += lam2[:, None, None] * np.eye(gram.shape[-1])
    if wide:
        return np.einsum("bnm,bm->bn", jt, cholesky_solve(gram, err))
    return cholesky_solve(gram, np.einsum("bnm,bm->bn", jt, err))


def cholesky_solve(spd: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x = A^-1 b for symmetric positive definite A (B, k, k) and b (B, k), by Cholesky A = L L^T.

    The factorisation and the two triangular solves run entry by entry over the whole batch, on
    contiguous (B,) arrays: ~k^3 / 6 + k^2 element-wise operations, 2-4x less time than
    ``np.linalg.solve``'s LU per matrix at B = 10,000 and k = 3-7; below :data:`CHOLESKY_MIN_BATCH`
    matrices its ~k^3 / 6 NumPy calls cost more than LU, which solves them instead. Positive definiteness is
    the caller's promise (a pivot <= 0 gives non-finite x).
    """
    if len(spd) < CHOLESKY_MIN_BATCH:
        return _solve(spd, rhs)
    k = spd.shape[-1]
    a = np.ascontiguousarray(spd.transpose(1, 2, 0))  # (k, k, B): a[i, j] is one contiguous (B,) array
    lower: list[list[np.ndarray]] = [[] for _ in range(k)]  # lower[i][j] = L_ij, j < i
    inv_diag = []
    for j in range(k):
        pivot = a[j, j] - sum(lower[j][p] * lower[j][p] for p in range(j))
        inv_diag.append(1.0 / np.sqrt(pivot))
        for i in range(j + 1, k):
            lower[i].append((a[i, j] - sum(lower[i][p] * lower[j][p] for p in range(j))) * inv_diag[j])
    b = rhs.T
    y: list[np.ndarray] = []
    for i in range(k):  # L y = b
        y.append((b[i] - sum(lower[i][p] * y[p] for p in range(i))) * inv_diag[i])
    x: list[np.ndarray] = [np.empty(0)] * k
    for i in reversed(range(k)):  # L^T x = y
        x[i] = (y[i] - sum(lower[p][i] * x[p] for p in range(i + 1, k))) * inv_diag[i]
    return np.stack(x, axis=1)
