"""A robust driver around the lecture's Jacobian solvers: restarts from seeded random configurations.

The recipe of TRAC-IK (Beeson and Ames, 2015): a local Jacobian iteration that stalls (a joint
limit, a singularity, a local minimum of the error) is tried again from a random configuration
within the limits. The lecture's solvers (:func:`core.ik.jacobian_solvers.solve_ik`) are used as
they are, with the settings of a short attempt (:meth:`Restarts.attempt_options`: for damped least
squares, Levenberg-Marquardt damping; an attempt abandoned as soon as it stalls); this module chooses
where they start:

1. every target is solved from the given start, for at most ``max_iterations``;
2. the targets that failed are solved again, all at once, each from ``starts_per_round`` fresh
   draws within the limits ([-pi, pi] rad or [-1, 1] m where unlimited), or from more when
   fewer than ``min_round_rows`` attempts would make the round, round after round until
   ``attempts`` draws per target are used. The first of these rounds starts each target from the
   configurations of a seeded pool whose end-effector poses are nearest to it
   (:func:`core.ik.pose_seeds.nearest_pose_starts`; ``nearest_first``), the later rounds from uniform
   draws (starts spread over the whole range, where the nearest poses led to no solution). A target's
   starts are one run of the batch (``solve_ik``'s ``starts_per_target``): once one of them solves it,
   the others stop;
3. each target keeps a success, or else its best attempt (smallest
   sqrt(position_residual^2 + orientation_residual^2)) with that attempt's reason; where that
   reason is only "iteration_cap" (an attempt is abandoned unclassified, or ends at its cap), the
   target is judged at its best configuration by the solver's stall rules
   (:func:`core.ik.jacobian_solvers.failure_causes`: e.g. "unreachable" for an arm stretched
   toward a target beyond it).

A target beyond the chain's reach bound (:func:`core.ik.reach.reach_upper_bound`) is provably
unreachable and is not restarted. The draws come from their own stream of ``seed`` (a
``SeedSequence`` spawn key no target sampler uses), so a restart never starts at the
configuration a random target was made from, and results are deterministic: TRAC-IK's time
budget is replaced by an attempt budget. Iterations are summed over the attempts.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import cast

import numpy as np

from simparity.core.ik.jacobian_solvers import IKOptions, failure_causes, solve_ik
from simparity.core.model.ik_problem import check_inputs
from simparity.core.ik.pose_seeds import nearest_pose_starts
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.model.ik_result import IKReason, IKResult
from simparity.core.model.scenes.chain import Chain, sample_configurations

RESTART_STREAM = 0x5E57A27
"""Spawn key of the restart draws' stream of the seed."""


@dataclass(frozen=True)
class Restarts:
    """How often and from where failed targets are solved again.

    Attributes
    ----------
    attempts : int
        Restarts per target at most (0: the plain solver).
    starts_per_round : int
        Random starts given at once to each target still failing: the restarts of a round are one
        batch, so a few hard targets cost a few batched iterations, not a few sequential solves.
    max_iterations : int or None
        Iteration cap of every attempt, the first included, when below the problem's (None: the
        problem's); a start that has not converged by then is better replaced by a fresh one.
    seed : int
        Seed of the random starts.
    min_round_rows : int
        Attempts a round holds at least, while the targets have attempts left: a round's iteration costs
        about the same below this many rows (NumPy's per-call overhead), so the last hard targets get more
        starts each at no extra cost, in fewer rounds.
    error_damping, damping_floor : float
        Each attempt's damping lambda^2 = error_damping |e|^2 + damping_floor^2
        (:func:`core.ik.steps.error_damped_least_squares_step`) [1; the Jacobian's units].
    stall_window, stall_ratio : int, float
        An attempt whose best |e| has not fallen by the fraction ``stall_ratio`` in ``stall_window``
        iterations is abandoned (``IKOptions.abandon_stalled``) [iterations; 1].
    nearest_first : bool
        The first restart round starts from the pool configurations nearest each target in pose
        (:mod:`core.ik.pose_seeds`); False: from uniform draws, as every later round.
    """

    # Measured on the bench suite (10,000 TRAC-IK targets per arm: iiwa, Panda, UR5) and on the 5-DOF SO-100
    # (comparisons/bench/ik.py five_dof_scene), each setting against its neighbours in one run:
    # - error damping c = 0.01 (Sugihara's LM): an attempt solves 97-99 % of what it solves in 60 iterations by its
    #   25th (90 % on the UR5 under the lecture's sigma_min damping), in 1.3-2x fewer iterations; c = 0.003 and
    #   0.03 needed within 8 % of its iterations per target, c = 1 needed 1.3-1.7x as many;
    # - a damping floor of 1e-5: at 1e-3 (the lecture's damping_max) a target whose solution is near a
    #   singularity converges linearly at lambda^2 / (sigma^2 + lambda^2) and runs out of iterations (the UR5
    #   lost 12 of 10,000 targets); 1e-5 and 1e-7 solved all;
    # - abandoning after 5 iterations without a 10 % fall of the best |e| saves 28-45 % of the iterations of
    #   random starts on the Panda and the SO-100, and abandons 0.8-2.6 % of the attempts that would have
    #   succeeded (they are restarted); 3 iterations abandoned up to 9 %;
    # - 32 attempts of at most 25 iterations: 99.99-100 % of the targets of all four arms, in 0.4-0.9x the time
    #   of 16 of at most 60 (which solved 99.5 % of the SO-100's);
    # - nearest-pose starts in the first restart round and a target's other starts stopped at its first solution
    #   (#41): 1.6x fewer iterations per target on the SO-100 (19.2 -> 12.0), 1.26x on the Panda (15.5 -> 12.4),
    #   1.24x on the UR5 (17.9 -> 14.4), 1.02x on the iiwa (8.70 -> 8.51), 99.99-100 % solved as before; nearest
    #   starts in every round solved 99.92 % of the SO-100's (the same basins again).
    attempts: int = 32
    starts_per_round: int = 4
    max_iterations: int | None = 25
    seed: int = 0
    min_round_rows: int = 256
    error_damping: float = 0.01
    damping_floor: float = 1e-5
    stall_window: int = 5
    stall_ratio: float = 0.1
    nearest_first: bool = True

    def __post_init__(self) -> None:
        def whole(value) -> bool:
            return isinstance(value, (int, np.integer)) and not isinstance(value, bool)

        checks = (("attempts", whole(self.attempts) and self.attempts >= 0, "a whole number >= 0"),
                  ("starts_per_round", whole(self.starts_per_round) and self.starts_per_round >= 1,
                   "a whole number >= 1"),
                  ("max_iterations", self.max_iterations is None or (whole(self.max_iterations)
                                                                     and self.max_iterations >= 1),
                   "None or a whole number >= 1"),
                  ("seed", whole(self.seed) and self.seed >= 0, "a whole number >= 0 (results are deterministic)"),
                  ("min_round_rows", whole(self.min_round_rows) and self.min_round_rows >= 1, "a whole number >= 1"))
        for name, ok, allowed in checks:
            if not ok:
                raise ValueError(f"Restarts.{name} is {getattr(self, name)!r} (allowed: {allowed})")

    def attempt_options(self, options: IKOptions) -> IKOptions:
        """The problem's ``options`` with this attempt's iteration cap, damping and stall rule."""
        cap = options.max_iterations if self.max_iterations is None else min(options.max_iterations,
                                                                             self.max_iterations)
        return replace(options, max_iterations=cap, error_damping=self.error_damping, damping_max=self.damping_floor,
                       stall_window=self.stall_window, stall_ratio=self.stall_ratio, abandon_stalled=True)


_FIELDS = ("q", "success", "iterations", "position_residual", "orientation_residual", "limit_violation", "reason")


def solve_ik_with_restarts(
    chain: Chain,
    target_position: np.ndarray,
    target_rotation: np.ndarray | None = None,
    q_start: np.ndarray | None = None,
    method: str = "damped_least_squares",
    options: IKOptions = IKOptions(),
    restarts: Restarts = Restarts(),
) -> IKResult:
    """:func:`core.ik.jacobian_solvers.solve_ik` with restarts of the failed targets (module docstring).

    Same parameters and result as ``solve_ik``; ``restarts`` says how many and from which seed.
    """
    target_position, target_rotation, q_start = check_inputs(chain, target_position, target_rotation, q_start)
    attempt = restarts.attempt_options(options)
    result = solve_ik(chain, target_position, target_rotation, q_start, method, attempt)
    best = {name: np.array(getattr(result, name)) for name in _FIELDS}
    best["reason"] = best["reason"].astype(object)  # a later attempt's reason may be longer than any so far
    center, radius = reach_upper_bound(chain)
    retry = np.linalg.norm(target_position - center, axis=1) <= radius + options.position_tolerance
    rng = np.random.default_rng(np.random.SeedSequence(restarts.seed, spawn_key=(RESTART_STREAM,)))
    left = restarts.attempts
    nearest = restarts.nearest_first
    while left > 0:
        todo = np.flatnonzero(retry & ~best["success"])
        if not todo.size:
            break
        starts = min(max(restarts.starts_per_round, -(-restarts.min_round_rows // todo.size)), left)
        left -= starts
        rows = np.repeat(todo, starts)  # every failed target from `starts` random configurations at once
        q_starts = (nearest_pose_starts(chain, target_position[todo],
                                        None if target_rotation is None else target_rotation[todo], starts, rng)
                    if nearest else sample_configurations(chain, rows.size, rng))
        nearest = False  # later rounds: uniform draws
        again = solve_ik(chain, target_position[rows], None if target_rotation is None else target_rotation[rows],
                         q_starts, method, attempt, starts)
        np.add.at(best["iterations"], rows, again.iterations)
        merit = np.where(again.success, -1.0, _merit(again.position_residual, again.orientation_residual))
        # rows.size >= 1 (todo is not empty, starts >= 1), so pick is always the index array
        pick = cast(np.ndarray, rows.size and np.argmin(merit.reshape(todo.size, starts), axis=1)
                    + np.arange(todo.size) * starts)
        take = again.success[pick] | (merit[pick] < _merit(best["position_residual"][todo],
                                                            best["orientation_residual"][todo]))
        for name in _FIELDS:
            if name != "iterations":
                best[name][todo[take]] = getattr(again, name)[pick[take]]
    capped = np.flatnonzero(best["reason"] == IKReason.ITERATION_CAP)
    if capped.size:
        best["reason"][capped] = failure_causes(chain, best["q"][capped], target_position[capped],
                                                3 if target_rotation is None else 6, options)
    return IKResult(**best)


def _merit(position_residual: np.ndarray, orientation_residual: np.ndarray) -> np.ndarray:
    return np.hypot(position_residual, orientation_residual)
