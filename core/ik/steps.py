"""One joint update of each Jacobian method: (J, e) -> dq, batched.

``jac`` is (B, m, n) (m = 3 for position targets, 6 for pose targets, linear rows
first), ``err`` is (B, m): the task-space error, position [m] then rotation vector [rad].
Every rule is finite for any finite input: singular Jacobians give a bounded (possibly
zero) step, never an exception.
"""

from __future__ import annotations

import numpy as np


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


def damped_least_squares_step(jac: np.ndarray, err: np.ndarray, threshold: float, damping_max: float) -> np.ndarray:
    """dq = J^T (J J^T + lambda^2 I)^-1 e with damping that adapts near singularities.

    lambda^2 = damping_max^2 (1 - (sigma_min / threshold)^2) while the smallest singular
    value sigma_min of J is below ``threshold``, 0 above it (Nakamura and Hanafusa;
    Chiaverini): the exact pseudo-inverse away from singularities, and near them each
    1 / sigma_i becomes sigma_i / (sigma_i^2 + lambda^2), finite even at sigma_i = 0.
    Computed through the SVD, J^T (J J^T + lambda^2 I)^-1 = V diag(sigma / (sigma^2 +
    lambda^2)) U^T, which also holds for tall J.
    """
    u, sigma, vt = np.linalg.svd(jac, full_matrices=False)
    smin = sigma[:, -1]
    lam2 = np.where(smin < threshold, damping_max**2 * (1 - (smin / threshold) ** 2), 0.0)
    denom = sigma**2 + lam2[:, None]
    gain = np.where(denom > 0, sigma / np.where(denom > 0, denom, 1.0), 0.0)
    return np.einsum("bkn,bk,bmk,bm->bn", vt, gain, u, err)
