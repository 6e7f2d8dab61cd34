"""The lecture's secondary task: joint-space goals moved into the Jacobian's null space.

The control expression is

    theta_dot = J+ V + (J+ J - I) grad H,    H = sum_i alpha_i |theta_i - theta_c_i|^Psi,

where J+ is the pseudo-inverse. J (J+ J - I) = J J+ J - J = 0, so the second term moves
the joints without moving the end effector, and since (J+ J - I) = -(I - J+ J) with
I - J+ J an orthogonal projector, it descends H: the joints are pulled toward theta_c.
The slide writes (theta_i - theta_c_i)^Psi; for an odd or non-integer Psi that is not a
penalty (it is negative or undefined on one side), so H uses the absolute value, and
grad H = Psi alpha_i |d_i|^(Psi - 1) sign(d_i) with d = theta - theta_c. For an even
integer Psi the two agree. Psi >= 1 keeps grad H finite.

Joint limits can be one more term of H: Liegeois' penalty
sum_i beta ((theta_i - m_i) / (u_i - l_i))^2 with m_i the mid-range, for limited joints.
"""

from __future__ import annotations

import numpy as np


def penalty(q: np.ndarray, center: np.ndarray, gain, exponent: float = 2.0) -> np.ndarray:
    """H = sum_i gain_i |q_i - center_i|^exponent. (B, n) -> (B,)."""
    return np.sum(np.asarray(gain) * np.abs(np.asarray(q) - center) ** exponent, axis=-1)


def penalty_gradient(q: np.ndarray, center: np.ndarray, gain, exponent: float = 2.0) -> np.ndarray:
    """grad H of :func:`penalty`, ``exponent`` >= 1. (B, n) -> (B, n)."""
    if exponent < 1:
        raise ValueError(f"the penalty exponent must be >= 1 for a finite gradient, got {exponent}")
    diff = np.asarray(q, dtype=float) - center
    return exponent * np.asarray(gain) * np.abs(diff) ** (exponent - 1) * np.sign(diff)


def limit_penalty_gradient(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, gain: float) -> np.ndarray:
    """Gradient of Liegeois' limit penalty sum gain ((q - mid) / range)^2; 0 on unlimited joints.

    Parameters
    ----------
    q : (B, n) ndarray
    lower, upper : (n,) ndarray
        Limits [rad or m], infinite when unlimited.
    gain : float
        [1].

    Returns
    -------
    (B, n) ndarray
    """
    limited = np.isfinite(lower) & np.isfinite(upper) & (upper > lower)
    lower, upper = np.where(limited, lower, -1.0), np.where(limited, upper, 1.0)
    mid, span = 0.5 * (lower + upper), upper - lower
    return np.where(limited, 2.0 * gain * (np.asarray(q) - mid) / span**2, 0.0)


def nullspace_term(jacobian: np.ndarray, z: np.ndarray, rcond: float = 1e-10) -> np.ndarray:
    """The lecture's (J+ J - I) z with the SVD pseudo-inverse.

    Parameters
    ----------
    jacobian : (B, m, n) ndarray
    z : (B, n) ndarray
        Usually grad H.
    rcond : float
        Singular values below ``rcond`` times the largest count as zero (J+ J then
        projects onto the row space of the remaining ones).

    Returns
    -------
    (B, n) ndarray
        Joint velocity with J @ result = 0 up to rounding.
    """
    _, sigma, vt = np.linalg.svd(jacobian, full_matrices=False)
    kept = sigma > rcond * np.max(sigma, axis=-1, keepdims=True)
    row_space = np.einsum("bkn,bk,bk->bn", vt, kept, np.einsum("bkn,bn->bk", vt, z))
    return row_space - z
