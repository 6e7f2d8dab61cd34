"""Joint-space dynamics judged: an engine's M, h, tau and qddot against the reference's at the same states, and the
identities every correct implementation satisfies, from the engine's own outputs alone.

A judge: it imports core's data model only (never core's dynamics), so a bug in core cannot make core agree.

Every value is relative and judged against its own scale, so that it means the same for a 1 kg arm and a 100 kg
one, in any unit:

- errors against the reference: max over states and entries of |A - A_ref| over the largest |A_ref| of the sample
  (a state where the reference is near zero is not divided by it, nor a sample where it is zero everywhere: below);
  forward dynamics as the joint force its error takes, joint by joint: [M_ref (qddot - qddot_ref)]_i over the
  largest sum_j |M_ref,ij| |qddot_ref,j| (what a backward-stable solve rounds joint i's force by). Solving with M
  amplifies rounding by M's condition number (~1e4 on a 7-joint arm: xarm7; ~1e9 with a 1 g dummy link at the tip),
  the force does not; a 1 % error in any joint's qddot is still ~1 % of that joint's force;
- torque identities: over the largest |tau| the engine itself computes at the sample's states; the round trip
  ABA(RNEA(qddot)) = qddot in the same backward form, RNEA(ABA(tau)) - tau, joint by joint over the larger of
  |tau_i| and sum_j |M_ij| |qddot_j|, so that it too does not grow with M's condition number;
- the kinetic-energy identity: over the largest kinetic energy of the sample;
- the energy identity qdot^T (Mdot - 2C) qdot = 0, i.e. qdot^T Mdot qdot = 2 qdot^T (h(q, qdot) - h(q, 0)), with
  Mdot by Richardson-extrapolated central differences along qdot (:data:`DIFFERENCE_STEP`): over max |M| |qdot|^3 / (1 rad) of the sample.
Every joint-force scale above (h, tau, the forward-dynamics force, the gravity identity's and the round trip's) is
floored at a tenth of the chain's physical force scale (:mod:`comparisons.measure.joint_force_scale`: what its
inertia, weight, speeds and damping produce at the sampled states), so that a force that vanishes at every state
(prismatic joints across gravity, no velocity-dependent term) is judged against the chain's forces, not against its
own rounding; a row whose scale is the floor says so. M (positive definite: its largest entry is a diagonal one, a sum
of non-negative link terms) and the kinetic energy (a sum of non-negative terms) round relative to themselves and
need no floor; the energy identity's scale, |M| |qdot|^3, is homogeneous in qdot like the identity itself. A scale of
zero (a massless chain at rest) has nothing to be relative to: the value is n/a with that reason.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.configuration_flow import moved
from simparity.comparisons.measure.joint_force_scale import ForceScale
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.metric_catalogue import (
    ABA_DERIVATIVE_ERROR_MAX,
    BASE_MOMENTUM_RESIDUAL,
    BIAS_FORCE_ERROR_MAX,
    CORIOLIS_SKEW_RESIDUAL,
    CENTRAL_DIFFERENCE_BEST_STEP,
    CENTRAL_DIFFERENCE_FLOOR,
    DERIVATIVE_IDENTITY_RESIDUAL,
    DERIVATIVE_STEP_EXCESS,
    FORWARD_DIFFERENCE_BEST_STEP,
    FORWARD_DIFFERENCE_FLOOR,
    FORWARD_DYNAMICS_ERROR_MAX,
    GRAVITY_EQUIVALENCE_RESIDUAL,
    GRAVITY_IDENTITY_RESIDUAL,
    INVERSE_DYNAMICS_ERROR_MAX,
    KINETIC_ENERGY_RESIDUAL,
    MASS_COLUMN_RESIDUAL,
    MASS_MATRIX_ASYMMETRY,
    MASS_MATRIX_DEFINITENESS_MIN,
    MASS_MATRIX_ERROR_MAX,
    RNEA_DERIVATIVE_ERROR_MAX,
    ROUND_TRIP_RESIDUAL,
    TIME_PER_FORWARD_DYNAMICS,
    TIME_PER_INVERSE_DYNAMICS,
    TIME_PER_MASS_MATRIX,
    units,
)
from simparity.comparisons.measure.model_parity import MODEL_METRICS
from simparity.core.model.scenes.chain import Chain

JOINT_DYNAMICS_METRICS = units(
    MASS_MATRIX_ERROR_MAX,
    BIAS_FORCE_ERROR_MAX,
    INVERSE_DYNAMICS_ERROR_MAX,
    FORWARD_DYNAMICS_ERROR_MAX,
    GRAVITY_IDENTITY_RESIDUAL,
    MASS_COLUMN_RESIDUAL,
    ROUND_TRIP_RESIDUAL,
    MASS_MATRIX_ASYMMETRY,
    MASS_MATRIX_DEFINITENESS_MIN,
    KINETIC_ENERGY_RESIDUAL,
    CORIOLIS_SKEW_RESIDUAL,
    GRAVITY_EQUIVALENCE_RESIDUAL,
    BASE_MOMENTUM_RESIDUAL,
    RNEA_DERIVATIVE_ERROR_MAX,
    ABA_DERIVATIVE_ERROR_MAX,
    DERIVATIVE_IDENTITY_RESIDUAL,
    DERIVATIVE_STEP_EXCESS,
    FORWARD_DIFFERENCE_BEST_STEP,
    FORWARD_DIFFERENCE_FLOOR,
    CENTRAL_DIFFERENCE_BEST_STEP,
    CENTRAL_DIFFERENCE_FLOOR,
    TIME_PER_MASS_MATRIX,
    TIME_PER_INVERSE_DYNAMICS,
    TIME_PER_FORWARD_DYNAMICS,
) | MODEL_METRICS
"""Every metric of a joint-dynamics case, in row order: the model-parity ones (:mod:`comparisons.measure.model_parity`)
last."""

REFERENCE_ERRORS = (MASS_MATRIX_ERROR_MAX, BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX,
                    FORWARD_DYNAMICS_ERROR_MAX) + tuple(MODEL_METRICS)
"""The metrics that need the reference; the others need only the engine."""

DIFFERENCE_STEP = 1e-4
"""[rad or m] The central-difference step along qdot (scaled to |qdot|_inf = 1) for Mdot, extrapolated with half
the step (Richardson): truncation ~ step^4 x the fifth derivative of M ~ 1e-16 (the plain central difference's
step^2 / 6 x the third derivative reached 1.4e-8 on the Panda); rounding ~ 3 x (the rounding of M) / step: ~1e-11
near the origin, ~1e-8 for a chain placed 2 km away (M rounds at ~3e-13 there); the identity's bound in the
tolerances says so."""


def _relative(values: np.ndarray, reference: np.ndarray, floor: float, what: str, scale: ForceScale | None = None
              ) -> Measured:
    """max |values - reference| over the largest |reference| of the sample, floored at ``floor`` (0: none; the
    floor of ``scale``, which the row then describes); n/a when both are zero."""
    own = float(np.max(np.abs(reference))) if reference.size else 0.0
    return _over(values - reference, own, floor, what, scale)


def _over(residual: np.ndarray, own: float, floor: float, what: str, scale: ForceScale | None = None) -> Measured:
    """max |residual| over the larger of ``own`` (the quantity's own largest magnitude) and ``floor``."""
    if not max(own, floor) > 0:
        return Measured(np.nan, "1", unmeasurable=f"{what} is zero at every state: nothing to be relative to")
    value = float(np.max(np.abs(residual))) / max(own, floor)
    if floor > own and scale is not None:
        return Measured(value, "1", note=f"relative to {scale.describe()}: {what} is at most {own:.3g}")
    return Measured(value, "1")


def reference_values(model: JointDynamicsModel, states: tuple[np.ndarray, ...]) -> dict[str, np.ndarray]:
    """The reference's M (B, n, n), h (B, n), tau (B, n) and qddot (B, n) at the scene's states."""
    q, qd, qdd, tau = states
    return {"M": model.mass_matrix(q), "h": model.bias_forces(q, qd), "tau": model.inverse_dynamics(q, qd, qdd),
            "qdd": model.forward_dynamics(q, qd, tau)}


def reference_errors(own: dict[str, np.ndarray], ref: dict[str, np.ndarray], scale: ForceScale) -> dict[str, Measured]:
    """Relative errors of an engine's M, h, tau and qddot against the reference's (:func:`reference_values`), the
    joint forces' floored at the reference's force ``scale``."""
    return {MASS_MATRIX_ERROR_MAX: _relative(own["M"], ref["M"], 0.0, "the reference's mass matrix"),
            BIAS_FORCE_ERROR_MAX: _relative(own["h"], ref["h"], scale.floor, "the reference's bias force", scale),
            INVERSE_DYNAMICS_ERROR_MAX: _relative(own["tau"], ref["tau"], scale.floor, "the reference's joint force",
                                                  scale),
            FORWARD_DYNAMICS_ERROR_MAX: _per_joint(np.einsum("bij,bj->bi", ref["M"], own["qdd"] - ref["qdd"]),
                                                   _rounded_force(ref["M"], ref["qdd"]), scale,
                                                   "the force of the reference's joint acceleration")}


def _per_joint(residual: np.ndarray, own: np.ndarray, scale: ForceScale, what: str) -> Measured:
    """max over joints i of (max over states of |residual_i|) / (max over states of own_i, floored at joint i's
    floor of ``scale``): each joint's force against its own scale ((B, n) both); n/a when every scale is zero."""
    largest = np.max(np.abs(own), axis=0)
    floors = scale.floors
    used = np.maximum(largest, floors)
    if not np.any(used > 0):
        return Measured(np.nan, "1", unmeasurable=f"{what} is zero at every state: nothing to be relative to")
    measured = used > 0
    value = float(np.max(np.max(np.abs(residual), axis=0)[measured] / used[measured]))
    floored = np.flatnonzero(floors > largest)
    if floored.size:
        joints = ", ".join(str(i + 1) for i in floored)
        return Measured(value, "1", note=f"joints {joints} relative to {scale.describe()}: {what} there is at most "
                                         f"{float(np.max(largest[floored])):.3g}")
    return Measured(value, "1")


def _rounded_force(mass: np.ndarray, qddot: np.ndarray) -> np.ndarray:
    """(B, n): sum_j |M_ij| |qddot_j|, what a backward-stable solve of M qddot = f rounds joint i's force by (times
    eps), whatever M's condition number: |f_i| itself can be 1e10 x smaller (a light link's large qddot)."""
    return np.einsum("bij,bj->bi", np.abs(mass), np.abs(qddot))


def identities(model: JointDynamicsModel, chain: Chain, states: tuple[np.ndarray, ...],
               own: dict[str, np.ndarray], scale: ForceScale, gravity_world: np.ndarray | None) -> dict[str, Measured]:
    """The identities of the engine's own outputs ``own`` (:func:`reference_values` of the engine, at ``states``) of
    ``chain``: RNEA(q, 0, 0) = g(q) = h(q, 0); RNEA(q, 0, e_i) - g = M e_i; RNEA(ABA(RNEA(qddot))) = RNEA(qddot) (the
    round trip in torque space); M symmetric and
    positive definite; 1/2 qdot^T M qdot (armature aside) = the links' kinetic energy from the engine's own
    kinematics; qdot^T (Mdot - 2 C) qdot = 0; for a floating base, g(q) = -M(q)[:, :3] ``gravity_world`` (the
    equivalence principle: weight is what a uniform acceleration -g of the base takes) and M's base rows times qdot
    = the robot's momentum from its links (the centroidal momentum A_G qdot moved to the base origin). The
    joint-force identities are
    floored at the chain's force ``scale``."""
    q, qd, qdd, _ = states
    n = chain.nv
    mass, tau = own["M"], own["tau"]
    torque_scale = float(np.max(np.abs(tau)))
    zeros = np.zeros_like(qd)
    gravity = model.bias_forces(q, zeros)
    values = {GRAVITY_IDENTITY_RESIDUAL: _over(model.inverse_dynamics(q, zeros, zeros) - gravity, torque_scale,
                                               scale.floor, "the joint force", scale),
              GRAVITY_EQUIVALENCE_RESIDUAL: _equivalence(chain, mass, gravity, gravity_world, scale)}
    columns = np.stack([model.inverse_dynamics(q, zeros, np.broadcast_to(np.eye(n)[i], qd.shape).copy()) - gravity
                        for i in range(n)], axis=-1)
    values[MASS_COLUMN_RESIDUAL] = _over(columns - mass, float(np.max(np.abs(mass))), 0.0, "the mass matrix")
    there = model.forward_dynamics(q, qd, tau)  # ~ qdd
    values[ROUND_TRIP_RESIDUAL] = _per_joint(model.inverse_dynamics(q, qd, there) - tau,
                                             np.maximum(np.abs(tau), _rounded_force(mass, there)), scale,
                                             "the joint force")
    values[MASS_MATRIX_ASYMMETRY] = _over(mass - np.swapaxes(mass, -1, -2), float(np.max(np.abs(mass))), 0.0,
                                          "the mass matrix")
    values[MASS_MATRIX_DEFINITENESS_MIN] = _definiteness(mass)
    armature = np.array([0.0] * chain.base_dofs + [joint.armature for joint in chain.joints])
    rotors = 0.5 * np.sum(armature * qd**2, axis=-1)
    quadratic = 0.5 * np.einsum("bi,bij,bj->b", qd, mass, qd) - rotors
    kinetic = model.link_kinetic_energy(q, qd)
    # the rotors' energy is taken off 1/2 qdot^T M qdot: its rounding floors the residual (pybullet_data's reacher:
    # armature 1 on links of 3.5 g, the residual 3.7e-13 of the links' energy in every engine alike, 2.1e-13 in ms)
    values[KINETIC_ENERGY_RESIDUAL] = _over(quadratic - kinetic, float(np.max(np.abs(kinetic))), float(np.max(rotors)),
                                            "the links' kinetic energy")
    values[CORIOLIS_SKEW_RESIDUAL] = _skew_residual(model, chain, q, qd, own["h"] - gravity, mass)
    values[BASE_MOMENTUM_RESIDUAL] = _momentum(model, chain, q, qd, mass)
    return values


def _momentum(model: JointDynamicsModel, chain: Chain, q: np.ndarray, qd: np.ndarray, mass: np.ndarray) -> Measured:
    """|M[:6] qdot - (P, L_o)| over the largest |(P, L_o)|: the robot's momentum from the engine's own link velocities
    (:meth:`JointDynamicsModel.momentum`, about the world origin) moved to the base origin, L_o = L - p x P."""
    if not chain.floating_base:
        return Measured(np.nan, "1", unmeasurable="the base is fixed: M's rows are the joints', not the robot's momentum")
    try:
        reported = np.asarray(model.momentum(q, qd), dtype=float)
    except NotImplementedError as err:
        return Measured(np.nan, "1", unmeasurable=str(err))
    if reported.shape != (len(q), 6) or not np.all(np.isfinite(reported)):
        raise ValueError(f"momentum has shape {reported.shape} or non-finite values, expected finite (B, 6)")
    about_base = np.concatenate([reported[:, :3], reported[:, 3:] - np.cross(q[:, :3], reported[:, :3])], axis=1)
    expected = np.einsum("bij,bj->bi", mass[:, :6, :], qd)
    return _over(expected - about_base, float(np.max(np.abs(about_base))), 0.0, "the robot's momentum")


def _equivalence(chain: Chain, mass: np.ndarray, gravity: np.ndarray, gravity_world: np.ndarray | None,
                 scale: ForceScale) -> Measured:
    """|g(q) + M(q)[:, :3] g_world| over the largest |g(q)|, floored at the force ``scale``: n/a for a fixed base or
    without gravity."""
    if not chain.floating_base:
        return Measured(np.nan, "1", unmeasurable="the base is fixed: no base acceleration stands for gravity")
    if gravity_world is None or not np.any(gravity_world):
        return Measured(np.nan, "1", unmeasurable="no gravity: nothing to be equivalent to")
    residual = gravity + np.einsum("bij,j->bi", mass[:, :, :3], np.asarray(gravity_world, dtype=float))
    return _over(residual, float(np.max(np.abs(gravity))), scale.floor, "the weight's generalized force", scale)


def _definiteness(mass: np.ndarray) -> Measured:
    """min over states of the smallest eigenvalue of D^-1/2 M D^-1/2, D = diag(M): > 0 exactly when M is positive
    definite, and unitless joint by joint (a prismatic joint's kg beside a revolute joint's kg m^2: lambda_min /
    lambda_max of M itself would change with the unit of length). A diagonal entry <= 0 is not definite: 0."""
    symmetric = 0.5 * (mass + np.swapaxes(mass, -1, -2))
    diagonal = np.diagonal(symmetric, axis1=-2, axis2=-1)
    if not np.all(diagonal > 0):
        return Measured(0.0, "1")
    inverse_root = 1.0 / np.sqrt(diagonal)
    scaled = symmetric * inverse_root[:, :, None] * inverse_root[:, None, :]
    return Measured(float(np.min(np.linalg.eigvalsh(scaled)[:, 0])), "1")


def _skew_residual(model: JointDynamicsModel, chain: Chain, q: np.ndarray, qd: np.ndarray, coriolis: np.ndarray,
                   mass: np.ndarray) -> Measured:
    """|qdot^T Mdot qdot - 2 qdot^T C qdot| over max |M| |qdot|^3, Mdot by central differences along the motion at
    qdot (:func:`comparisons.measure.configuration_flow.moved`) at :data:`DIFFERENCE_STEP` and half of it,
    extrapolated (Richardson)."""
    speed = np.max(np.abs(qd), axis=-1, keepdims=True)
    direction = np.divide(qd, speed, out=np.zeros_like(qd), where=speed > 0)

    def central(step: float) -> np.ndarray:
        return (model.mass_matrix(moved(chain, q, direction, step))
                - model.mass_matrix(moved(chain, q, direction, -step))) / (2 * step)

    mass_dot = (4 * central(DIFFERENCE_STEP / 2) - central(DIFFERENCE_STEP)) / 3 * speed[..., None]
    power = np.einsum("bi,bij,bj->b", qd, mass_dot, qd) - 2 * np.einsum("bi,bi->b", qd, coriolis)
    scale = float(np.max(np.abs(mass))) * float(np.max(speed)) ** 3
    return _over(power, scale, 0.0, "qdot")


def timed_values(model: JointDynamicsModel, states: tuple[np.ndarray, ...], timer) -> tuple[dict, dict[str, Measured]]:
    """(the engine's :func:`reference_values`, its times per state): ``timer(fn)`` -> (seconds, result) times one
    call over every state (the runner's best of its repeats)."""
    q, qd, qdd, tau = states
    count = len(q)
    mass_seconds, mass = timer(lambda: model.mass_matrix(q))
    inverse_seconds, inverse = timer(lambda: model.inverse_dynamics(q, qd, qdd))
    forward_seconds, forward = timer(lambda: model.forward_dynamics(q, qd, tau))
    own = {"M": np.asarray(mass, dtype=float), "h": np.asarray(model.bias_forces(q, qd), dtype=float),
           "tau": np.asarray(inverse, dtype=float), "qdd": np.asarray(forward, dtype=float)}
    times = {TIME_PER_MASS_MATRIX: Measured(mass_seconds / count, "s"),
             TIME_PER_INVERSE_DYNAMICS: Measured(inverse_seconds / count, "s"),
             TIME_PER_FORWARD_DYNAMICS: Measured(forward_seconds / count, "s")}
    return own, times


def shape_problem(own: dict[str, np.ndarray], count: int, n: int) -> str:
    """Why an engine's outputs are not usable ("" when they are): a wrong shape (``n``: the velocity's length,
    :attr:`Chain.nv`) or a non-finite value."""
    expected = {"M": (count, n, n), "h": (count, n), "tau": (count, n), "qdd": (count, n)}
    for key, shape in expected.items():
        if own[key].shape != shape:
            return f"{key} has shape {own[key].shape}, expected {shape}"
    bad = [key for key in expected if not np.all(np.isfinite(own[key]))]
    return f"non-finite {', '.join(bad)}" if bad else ""
