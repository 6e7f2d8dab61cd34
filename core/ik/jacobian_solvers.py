"""Iterative Jacobian IK over a batch of targets, with hard joint limits.

All targets of the batch are iterated at once; a target leaves the active set when it is
solved or when it has stalled for a reason the solver can name. Each iteration:

1. Task error e: position p_target - p [m], and for pose targets the rotation vector
   so3_log(R_target R^T) [rad], in world axes like the Jacobian's angular rows. The two
   are stacked unweighted (1 m of position counts as much as 1 rad of rotation).
2. Joint update dq from the method's rule (:mod:`core.ik.steps`), plus, when asked, the
   lecture's null-space term (J+ J - I) grad H (:mod:`core.ik.nullspace`).
3. Joint limits are hard bounds (:mod:`core.ik.limits`). A joint at a limit whose update
   points outward is locked (its Jacobian column zeroed) and the update recomputed, so the
   free joints take over its share; the inverse method, whose Jacobian would turn
   singular, is never locked. The update is scaled so no joint moves more than
   ``max_step``; a revolute value that leaves its limits is wrapped by 2 pi into them
   when it can be, and clipped otherwise. The start pose is clipped too, so every
   iterate is inside the limits.

A target has stalled when its error |e| has not fallen by a factor (1 - ``stall_ratio``)
for ``stall_window`` iterations. A stalled target with a revolute joint locked at a limit
whose range leaves a gap narrower than ``max_step`` (e.g. the iiwa's 350 deg joints) gets
up to ``gap_crossings`` escapes: the joint is moved to its other limit, the same angle as
a turn through the gap in the direction it was pushing, and the iteration goes on.

Failure reasons, for a target that stalls unsolved (first match; a target beyond the
reach bound is ``"unreachable"`` also when the iteration cap stops it):

- ``"unreachable"``: the target position is farther from the first joint than the
  triangle-inequality bound of :func:`core.ik.reach.reach_upper_bound` (the sum of the
  link offsets and prismatic travels; the true reach may be smaller);
- ``"limit_blocked"``: a joint was locked at a limit in the last update;
- ``"unreachable"``: the arm is stretched toward the target: sigma_min of the position
  rows is below ``singular_threshold`` and the target is farther from the first joint
  than the end effector;
- ``"singular"``: sigma_min of the task Jacobian is below ``singular_threshold`` (any
  other singularity, e.g. folded onto the base);
- ``"iteration_cap"``: the cap came while the target was still making progress, or it
  had stalled without any of these causes (such a target keeps going until the cap), or it
  stalled with ``IKOptions.abandon_stalled`` (restarts' attempts: stopped at once, not classified).

A stalled target is judged at its current iterate, and where that names no cause, at its
best configuration (an iterate can oscillate about a singular best one).

A failed target returns the best configuration met (smallest |e|).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.ik import steps
from simparity.core.ik.batch_progress import BatchProgress
from simparity.core.ik.limits import cross_gap, crossable_gap, inside, wrap_into_limits
from simparity.core.model.ik_problem import IKTolerances, check_inputs
from simparity.core.ik.nullspace import limit_penalty_gradient, nullspace_term, penalty_gradient
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.model.ik_result import IKReason, IKResult
from simparity.core.kinematics import jacobian_of_frames, jacobian_world, packed_frames
from simparity.core.rotations import so3_log
from simparity.core.model.scenes.chain import Chain, sample_configurations

METHODS = ("jacobian_inverse", "pseudo_inverse", "transpose", "damped_least_squares")


@dataclass(frozen=True)
class IKOptions(IKTolerances):
    """Settings of the in-house iterative solvers: the problem's tolerances and iteration
    cap (:class:`~simparity.core.model.ik_problem.IKTolerances`) plus their own.

    Attributes
    ----------
    max_step : float
        Largest change of any joint in one update [rad or m]; a longer update is scaled
        down as a whole, its direction kept.
    rank_rcond : float
        J counts as rank-deficient when sigma_min <= rank_rcond * sigma_max [1] (inverse
        and pseudo-inverse rules, null-space projector).
    singular_threshold : float
        sigma_min below which damped least squares damps and a stalled target counts as
        singular [the Jacobian's units: m/rad for position rows, 1 for rotation rows].
    damping_max : float
        Damping lambda reached at sigma_min = 0 [same units]; with ``error_damping``, the damping at e = 0.
    error_damping : float
        0: damped least squares damps by sigma_min (the lecture's rule); c > 0: by the error instead,
        lambda^2 = c |e|^2 + damping_max^2 (Levenberg-Marquardt, :func:`core.ik.steps.error_damped_least_squares_step`)
        [1].
    stall_window : int
        Iterations without progress that make a stall.
    stall_ratio : float
        Progress: the best |e| fell by more than this fraction [1].
    abandon_stalled : bool
        False: the stall rules of the module docstring. True: a stalled target stops at once (after its gap
        escapes), unclassified, as ``"iteration_cap"``: for restarts (:mod:`core.ik.restarts`), which start it
        again elsewhere and judge only the best attempt; the classification's singular values are not computed.
    gap_crossings : int
        Escapes through a narrow limit gap allowed per target (see the module docstring).
    rest_pose : (n,) array_like or None
        theta_c of the null-space penalty H = sum rest_gain_i |q_i - theta_c_i|^rest_exponent
        [rad or m]; None: no rest-pose term.
    rest_gain : float or (n,) array_like
        alpha_i of H [1/rad^Psi or 1/m^Psi]. Each iteration adds a null-space step of
        size ~alpha Psi |q - theta_c|^(Psi - 1); keep alpha Psi well below 1, or its
        second-order end-effector drift keeps the residual above the tolerance.
    rest_exponent : float
        Psi of H, >= 1.
    limit_gain : float
        Gain of Liegeois' joint-limit term of H, 0 for none [1].
    """

    # Defaults tuned on the seeded KUKA iiwa pose targets of tests/core/ik/test_jacobian_solvers.py.
    # Damping is light: max_step already bounds the steps near singularities, and
    # damping_max = 1e-2 lowered the solve rate from 99.7 % to 99.1 % because damping
    # slows the approach to near-singular solutions (linear rate lambda^2 / (sigma^2 +
    # lambda^2)). max_step = 0.75 rad lets a step cross the iiwa's 0.17-0.35 rad limit gaps.
    max_step: float = 0.75
    rank_rcond: float = 1e-6
    singular_threshold: float = 1e-2
    damping_max: float = 1e-3
    error_damping: float = 0.0
    stall_window: int = 30
    stall_ratio: float = 1e-3
    abandon_stalled: bool = False
    gap_crossings: int = 2
    rest_pose: np.ndarray | None = None
    rest_gain: float | np.ndarray = 0.1
    rest_exponent: float = 2.0
    limit_gain: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("max_step", "rank_rcond", "singular_threshold", "damping_max", "stall_ratio"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"IKOptions.{name} must be finite and > 0, got {value}")
        if self.stall_window < 1:
            raise ValueError(f"IKOptions.stall_window must be >= 1, got {self.stall_window}")
        if self.gap_crossings < 0:
            raise ValueError(f"IKOptions.gap_crossings must be >= 0, got {self.gap_crossings}")
        if self.rest_exponent < 1:
            raise ValueError(f"IKOptions.rest_exponent must be >= 1, got {self.rest_exponent}")
        if not (self.limit_gain >= 0 and np.all(np.asarray(self.rest_gain) >= 0)):
            raise ValueError("IKOptions.limit_gain and rest_gain must be >= 0")
        if not (np.isfinite(self.error_damping) and self.error_damping >= 0):
            raise ValueError(f"IKOptions.error_damping must be finite and >= 0, got {self.error_damping}")


def solve_ik(
    chain: Chain,
    target_position: np.ndarray,
    target_rotation: np.ndarray | None = None,
    q_start: np.ndarray | None = None,
    method: str = "damped_least_squares",
    options: IKOptions = IKOptions(),
    starts_per_target: int = 1,
) -> IKResult:
    """Solve a batch of position or pose targets with one of the Jacobian methods.

    Parameters
    ----------
    chain : Chain
    target_position : (B, 3) ndarray
        End-effector origin targets, world frame [m].
    target_rotation : (B, 3, 3) ndarray or None
        End-effector orientation targets (frame to world); None for position-only IK.
    q_start : (n,) or (B, n) ndarray, optional
        Start configuration(s) [rad or m], clipped into the limits; default zeros.
    method : str
        One of :data:`METHODS`. ``"jacobian_inverse"`` needs a square task Jacobian: n = 3 joints for
        position, 6 for pose targets, or n = the number of task directions the chain moves in at all (a planar
        arm of 3 joints with pose targets moves in x, y and the turn about the plane's normal: its inverse is
        taken on those, :func:`task_basis`).
    options : IKOptions
    starts_per_target : int
        Rows that are one target from several starts, in runs of this many consecutive rows (B a multiple of it):
        once one row of a run is solved, the others stop where they are (with ``"iteration_cap"``), since the
        target needs no second solution (:mod:`core.ik.restarts`). 1: every row its own target.

    Returns
    -------
    IKResult
        Unreachable or singular targets come back as failures with finite residuals
        and a reason, never as an exception.

    Raises
    ------
    ValueError
        On malformed inputs, an unknown method, or a non-square Jacobian for
        ``"jacobian_inverse"``.
    """
    target_position, target_rotation, q = check_inputs(chain, target_position, target_rotation, q_start)
    if method not in METHODS:
        raise ValueError(f"unknown IK method {method!r}, expected one of {METHODS}")
    if not (starts_per_target >= 1 and len(target_position) % starts_per_target == 0):
        raise ValueError(f"starts_per_target is {starts_per_target!r}: a whole number >= 1 that divides the "
                         f"{len(target_position)} targets")
    rows = 3 if target_rotation is None else 6
    basis = None
    if method == "jacobian_inverse" and rows != chain.n_joints:
        basis = task_basis(chain, rows)
        if basis.shape[1] != chain.n_joints:
            raise ValueError(f"jacobian_inverse needs a square Jacobian: the task has {rows} rows, of which "
                             f"{basis.shape[1]} the chain can move in, and chain '{chain.name}' has "
                             f"{chain.n_joints} joints")
    lower, upper = chain.lower, chain.upper
    revolute = np.array([j.type == "revolute" for j in chain.joints])
    crossable = crossable_gap(revolute, lower, upper, options.max_step)
    center, radius = reach_upper_bound(chain)
    beyond_reach = np.linalg.norm(target_position - center, axis=1) > radius + options.position_tolerance

    progress = BatchProgress.start(np.clip(q, lower, upper), options.gap_crossings)
    for it in range(options.max_iterations + 1):
        idx = progress.unsolved()
        if idx.size == 0:
            break
        qa = progress.q[idx]
        frames = packed_frames(chain, qa)  # one FK pass gives the error and the Jacobian
        end_world = frames.positions[-1].T
        err, pos_res, rot_res = _error(end_world, frames.end_rotation.transpose(2, 0, 1), target_position[idx],
                                       None if target_rotation is None else target_rotation[idx])
        solved = (pos_res <= options.position_tolerance) & (rot_res <= options.orientation_tolerance)
        progress.observe(idx, qa, np.linalg.norm(err, axis=1), solved, options.stall_ratio)
        if starts_per_target > 1 and solved.any():
            progress.retire_runs(idx[solved], starts_per_target)
        go = progress.active[idx]  # only the unsolved targets still iterated are updated
        idx, qa, err, end_world = idx[go], qa[go], err[go], end_world[go]
        if idx.size == 0:
            break

        jac = jacobian_of_frames(chain, frames)[go, :rows]
        if basis is None:
            dq, locked = _update(method, jac, err, qa, lower, upper, revolute, options)
        else:  # the task's directions the chain moves in: a planar arm's x, y and turn about the plane's normal
            dq, locked = _update(method, basis.T @ jac, err @ basis, qa, lower, upper, revolute, options)
        # Only a target that has not progressed for stall_window iterations can stop unsolved: only those are
        # classified (the singular values cost more than the rest of the iteration), and none when abandoned.
        due = progress.stalled(idx, options.stall_window)
        cause = np.full(due.size, IKReason.ITERATION_CAP, dtype=object)
        if due.size and not options.abandon_stalled:
            cause[:] = _classify(jac[due], locked[due], end_world[due], target_position[idx[due]], center,
                                 beyond_reach[idx[due]], options)
            # A stalled iterate that oscillates about a singular best configuration (the
            # pseudo-inverse at a stretched arm) is judged at that configuration, which it returns.
            waiting = np.flatnonzero(cause == IKReason.ITERATION_CAP)
            if waiting.size:
                w = idx[due[waiting]]
                best = packed_frames(chain, progress.best_q[w])
                cause[waiting] = _classify(jacobian_of_frames(chain, best)[:, :rows],
                                           locked[due[waiting]], best.positions[-1].T, target_position[w], center,
                                           beyond_reach[w], options)
        crossable_due = np.any(locked[due] & crossable, axis=1) & progress.may_cross(idx[due])
        escapes = crossable_due & ((cause == IKReason.LIMIT_BLOCKED) | options.abandon_stalled)
        stops = ~escapes & ((cause != IKReason.ITERATION_CAP) | options.abandon_stalled)
        stalled, escape = np.zeros(idx.size, bool), np.zeros(idx.size, bool)
        stalled[due[stops]], escape[due[escapes]] = True, True
        last = it == options.max_iterations
        if last:
            capped = ~stalled
            progress.stop(idx[capped], np.where(beyond_reach[idx[capped]], IKReason.UNREACHABLE,
                                                IKReason.ITERATION_CAP))
        progress.stop(idx[due[stops]], cause[stops])

        step = ~(stalled | escape) & (not last)
        escape &= not last
        stepped = np.clip(wrap_into_limits(qa[step] + dq[step], revolute, lower, upper), lower, upper)
        progress.advance(idx, step, stepped, escape, cross_gap(qa[escape], locked[escape] & crossable, lower, upper))

    best_q = progress.best_q
    frames = packed_frames(chain, best_q)
    _, pos_res, rot_res = _error(frames.positions[-1].T, frames.end_rotation.transpose(2, 0, 1), target_position,
                                 target_rotation)
    violation = np.max(np.maximum(np.maximum(lower - best_q, best_q - upper), 0.0), axis=1, initial=0.0)
    return IKResult(q=best_q, success=progress.reason == IKReason.SOLVED, iterations=progress.iterations,
                    position_residual=pos_res, orientation_residual=rot_res, limit_violation=violation,
                    reason=progress.reason.astype(str))


TASK_SAMPLES = 32
"""Configurations at which :func:`task_basis` samples the Jacobian: a direction a chain cannot move in at 32
seeded random configurations it cannot move in anywhere (the configurations where it could are not a set of
measure zero)."""

TASK_RTOL = 1e-9
"""A singular value below this fraction of the largest is zero (rounding leaves ~1e-16)."""


def task_basis(chain: Chain, rows: int) -> np.ndarray:
    """(rows, k) an orthonormal basis of the task directions (of the first ``rows`` of the world Jacobian: 3
    for position, 6 for pose) the chain moves in at some configuration, k their number: the span of the
    Jacobian's columns over :data:`TASK_SAMPLES` seeded random configurations within the limits."""
    q = sample_configurations(chain, TASK_SAMPLES, 0)
    columns = np.concatenate(list(jacobian_world(chain, q)[:, :rows]), axis=1)  # (rows, samples x n)
    u, sigma, _ = np.linalg.svd(columns, full_matrices=False)
    return u[:, sigma > TASK_RTOL * sigma[0]]


def _error(end_world, end_rotation, target_position, target_rotation):
    """Task error (B, m) and the position and orientation residuals (B,) of the end effector's pose."""
    pos_err = target_position - end_world
    pos_res = np.linalg.norm(pos_err, axis=1)
    if target_rotation is None:
        return pos_err, pos_res, np.zeros(len(end_world))
    rot_err = so3_log(target_rotation @ np.swapaxes(end_rotation, 1, 2))
    return np.concatenate([pos_err, rot_err], axis=1), pos_res, np.linalg.norm(rot_err, axis=1)


def _update(method, jac, err, q, lower, upper, revolute, options):
    """Joint update (B, n), scaled to ``max_step``, and the joints locked at a limit (B, n).

    A joint at a limit whose update points outward is locked and the update of its target recomputed
    (only those targets), until no free joint pushes outward.
    """
    locked = np.zeros(q.shape, bool)
    z = _secondary_gradient(q, lower, upper, options)
    dq = _direction(method, jac, err, z, locked, options)
    redo = np.arange(len(q))
    for _ in range(q.shape[1] if method != "jacobian_inverse" else 0):
        qr, dr = q[redo], dq[redo]
        pushing = ~locked[redo] & (((qr <= lower) & (dr < 0)) | ((qr >= upper) & (dr > 0)))
        some = np.flatnonzero(np.any(pushing, axis=1))  # only these can push outward: wrapped only where needed
        if not some.size:
            break
        pushing = pushing[some] & ~inside(wrap_into_limits(qr[some] + dr[some], revolute, lower, upper), lower,
                                          upper)
        again = np.any(pushing, axis=1)
        if not np.any(again):
            break
        pushing, redo = pushing[again], redo[some[again]]
        locked[redo] |= pushing
        dq[redo] = _direction(method, jac[redo], err[redo], None if z is None else z[redo], locked[redo], options)
    largest = np.max(np.abs(dq), axis=1, initial=0.0)
    scale = np.minimum(1.0, options.max_step / np.where(largest > 0, largest, 1.0))
    return dq * scale[:, None], locked


def _direction(method, jac, err, z, locked, options):
    """The method's update with the ``locked`` joints' columns zeroed, plus the null-space term of ``z``."""
    reduced = jac * ~locked[:, None, :] if locked.any() else jac
    dq = _rule(method, reduced, err, options)
    if z is not None:
        dq = dq + nullspace_term(reduced, np.where(locked, 0.0, z), options.rank_rcond)
    return dq


def _rule(method, jac, err, options):
    if method == "jacobian_inverse":
        return steps.jacobian_inverse_step(jac, err, options.rank_rcond)
    if method == "pseudo_inverse":
        return steps.pseudo_inverse_step(jac, err, options.rank_rcond)
    if method == "transpose":
        return steps.transpose_step(jac, err)
    if options.error_damping > 0:
        return steps.error_damped_least_squares_step(jac, err, options.error_damping, options.damping_max)
    return steps.damped_least_squares_step(jac, err, options.singular_threshold, options.damping_max)


def _secondary_gradient(q, lower, upper, options):
    """grad H of the rest-pose and joint-limit terms, or None when neither is asked for."""
    z = None
    if options.rest_pose is not None:
        z = penalty_gradient(q, np.asarray(options.rest_pose, dtype=float), options.rest_gain,
                             options.rest_exponent)
    if options.limit_gain > 0:
        limit = limit_penalty_gradient(q, lower, upper, options.limit_gain)
        z = limit if z is None else z + limit
    return z


def failure_causes(chain: Chain, q: np.ndarray, target_position: np.ndarray, rows: int,
                   options: IKTolerances) -> np.ndarray:
    """The reason (B,) each target would get if its iteration stopped, unsolved, at ``q`` (B, n): the stall
    rules of the module docstring, with a joint sitting at a limit counted as locked ("iteration_cap" where
    none applies). ``rows``: 3 for position targets, 6 for poses."""
    center, radius = reach_upper_bound(chain)
    beyond = np.linalg.norm(target_position - center, axis=1) > radius + options.position_tolerance
    frames = packed_frames(chain, q)
    at_limit = (q <= chain.lower) | (q >= chain.upper)
    return _classify(jacobian_of_frames(chain, frames)[:, :rows], at_limit, frames.positions[-1].T, target_position,
                     center, beyond, options).astype(str)


def _classify(jac, locked, end_world, target_position, center, beyond_reach, options):
    """Failure reason (B,) each target would get if it stopped now (see the module docstring)."""
    sigma_task = np.linalg.svd(jac, compute_uv=False)[:, -1]
    sigma_position = np.linalg.svd(jac[:, :3], compute_uv=False)[:, -1]
    farther = np.linalg.norm(target_position - center, axis=1) > np.linalg.norm(end_world - center, axis=1)
    cause = np.full(len(jac), IKReason.ITERATION_CAP, dtype=object)
    cause[sigma_task < options.singular_threshold] = IKReason.SINGULAR
    cause[(sigma_position < options.singular_threshold) & farther] = IKReason.UNREACHABLE
    cause[np.any(locked, axis=1)] = IKReason.LIMIT_BLOCKED
    cause[beyond_reach] = IKReason.UNREACHABLE
    return cause
