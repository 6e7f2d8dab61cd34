"""Inverse kinematics: the lecture's analytic two-link solution and Jacobian methods.

``solve_ik`` iterates a batch of position or pose targets with the Jacobian inverse,
pseudo-inverse, transpose or damped least squares, under hard joint limits, optionally
with the lecture's null-space term; it reports each failure with a reason instead of
raising. ``two_link_ik`` is the closed form for the planar two-link arm.
"""

from core.ik.analytic_2link import TwoLinkIK, two_link_fk, two_link_ik
from core.ik.jacobian_solvers import METHODS, IKOptions, solve_ik
from core.ik.nullspace import limit_penalty_gradient, nullspace_term, penalty, penalty_gradient
from core.ik.reach import reach_upper_bound
from core.ik.result import REASONS, IKResult

__all__ = [
    "IKOptions",
    "IKResult",
    "METHODS",
    "REASONS",
    "TwoLinkIK",
    "limit_penalty_gradient",
    "nullspace_term",
    "penalty",
    "penalty_gradient",
    "reach_upper_bound",
    "solve_ik",
    "two_link_fk",
    "two_link_ik",
]
