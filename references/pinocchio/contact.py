"""A chain's spheres meeting the scene's plane in Pinocchio (issue #46): its point contacts, solved by its own ADMM
on the Delassus operator, one velocity-level (impulse) solve per step of the harness's semi-implicit Euler.

Pinocchio 4.1 steps nothing and detects no contact against a plane here; what the harness writes and what is
Pinocchio's:

- Detection (the harness's): a sphere is active when its centre, placed by Pinocchio's ``forwardKinematics`` (the
  frame that carries it: :func:`sphere_anchors`), is at most its radius from the plane (gap <= 0) at the step's
  start. No margin, no look-ahead: a sphere still above the plane gets no force.
- Each active sphere is a ``PointContactConstraintModel`` between the world (joint 0, at the sphere's centre, the
  contact frame's z axis the plane's normal) and the joint that carries it (the same point and frame in that joint's
  local frame): its ``jacobian`` (``computeJointJacobians`` first) is the sphere centre's velocity in the contact
  frame, (t1, t2, n) rows. Its Coulomb cone's friction is the scene's (default 0.5): 0 on a frictionless plane, where
  the cone is the normal's half-line; with friction the constraint sits at the sphere's contact point
  ``centre - radius N`` instead, whose slip friction resists. No Baumgarte correction, no compliance (the defaults:
  0).
- The step (Moreau-Jean time stepping, first order): v_free = v + dt aba(q, v, tau - D v); the impulses lambda
  (N s, one (t1, t2, n) per active sphere) solve the cone complementarity problem G lambda + g in K*, lambda in K,
  with g = J v_free and the Delassus operator G = J M^-1 J^T (``DelassusOperatorDense`` of ``crba``'s M, armature
  included, and the constraints' J; on a frictionless plane its tangential rows decoupled, exact there:
  :func:`frictionless`), by ``ADMMConstraintSolver`` at :data:`SOLVER_TOLERANCE`, on a frictionless plane its answer
  polished on the contacts it pushes (:func:`polished`: exact where ADMM stops at its tolerance); then
  v' = v_free + M^-1 J^T lambda and q' from v' (the semi-implicit Euler position update). An active sphere's normal
  velocity after the step is >= 0 and 0 where it is pushed (no restitution); a penetration is not corrected (no
  position stabilisation): it stays what the last step before contact left, at most the approach speed times dt.
- Not its ``PGSConstraintSolver``: on a frictionless cone (friction 0) Pinocchio 4.1's PGS stops after one sweep,
  reports convergence with 0 iterations and returns impulses that leave a pushed sphere sinking, on the coupled and on
  the decoupled problem alike (``docs/examples/pinocchio_frictionless_solvers.py`` reproduces it with its numbers).
  Whatever the solver says of its convergence, its answer is checked here (:data:`NCP_RESIDUAL`): an answer that does
  not solve the problem fails the run, one that does is taken.
- The force a sampled state shows is lambda / dt of the step from that state (:meth:`PlaneContact.solve`), the
  force the step applied over its dt.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from simparity.core.model.errors import DivergedError
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, frame_index
from simparity.references.pinocchio.mass import mass_matrix

SOLVER_TOLERANCE = 1e-12
"""Pinocchio's ADMM stops when its complementarity and feasibility residuals (absolute and relative) are below this
(defaults 1e-6): the impulses then balance the step to ~1e-12 of their size, far below every contact bound (1e-9 on
the Signorini and friction checks, 1e-3 at rest)."""
SOLVER_MAX_ITERATIONS = 5_000
"""Where ADMM stops when it has not met :data:`SOLVER_TOLERANCE` (it converges in ~100-300 iterations on the built-in
scenes). Its flag is not the verdict: converged or not, its answer is polished and then judged by the harness's own
check (:data:`NCP_RESIDUAL`). A held-out go2 landing on three feet stalled with one of ADMM's residuals at 9.7e-10
(condition number 36) while its impulses were the exact answer (8.7e-18 after the polish)."""
NCP_RESIDUAL = 1e-8
"""[1] The harness's own check of the solver's answer, relative to the largest free contact velocity |g|: no pushed
sphere may still approach the plane, none may be pulled and none pushed while it leaves (max of (-sigma_n)^+,
(-lambda_n)^+ |G|, |lambda_n sigma_n| / |lambda| and the tangential impulse |lambda_t| |G|, sigma = G lambda + g). A
converged ADMM solve leaves ~1e-10 of |g| (measured on Solo-12); the PGS miss above leaves O(1)."""
NCP_RESIDUAL_COULOMB = 1e-2
"""[1] :data:`NCP_RESIDUAL` on a plane with friction, where the coupled problem is solved and not polished (its
tangential term the natural-map residual, :func:`_cone_terms`), by Pinocchio's solvers in turn
(:meth:`PlaneContact._coulomb`). Measured on Solo-12: <= 2.2e-6 of |g| standing on and sliding down a slope; on flat
ground, four feet landing at once (a singular Delassus operator), <= 9.5e-5 at mu 0.3, 2.1e-4 at 0.1, 4.8e-4 at 0.01
and 9.4e-3 at 0.001, where no solver of Pinocchio's does better. A solve that fails leaves O(1) (the PGS miss of
:data:`NCP_RESIDUAL`: a pushed foot sinking); the answers are projected on the cone, so no pull and no force outside
it is let through, and every contact metric judges the forces a step applies."""
REGULARISATION = 1e-10
"""[1 of max |G|] The diagonal added to a singular Delassus operator for :meth:`PlaneContact._coulomb`'s second try:
it moves the answer by ~1e-10 of itself, and its answer is judged on the true operator."""
ACTIVE_GAP = 0.0
"""[m] A sphere is in contact when its gap (centre distance to the plane less its radius) is at most this."""


def sphere_anchors(model: pin.Model, chain: Chain, contact: ChainContact) -> tuple[list[int], list[np.ndarray]]:
    """(Pinocchio joint id, the sphere's centre (3,) [m] in that joint's frame) of each of ``contact``'s spheres: a
    chain joint's frame is its joint's; the end effector is the URDF link's BODY frame; the base link is the free
    flyer's (joint 1), or the universe (joint 0) on a fixed base."""
    names = tuple(j.name for j in chain.joints)
    joints, points = [], []
    for sphere in contact.spheres:
        i = frame_index(sphere.frame, names, chain.end_effector_name, chain.base_link)
        if i == len(names):
            frame = model.frames[model.getFrameId(chain.end_effector_name, pin.BODY)]
            joint, placement = int(frame.parentJoint), frame.placement
        else:
            joint = model.getJointId(names[i]) if i >= 0 else (1 if chain.floating_base else 0)
            placement = pin.SE3.Identity()
        joints.append(joint)
        points.append(placement.act(np.asarray(sphere.centre_xyz, dtype=float)))
    return joints, points


def _contact_frame(normal: np.ndarray) -> np.ndarray:
    """(3, 3) a right-handed orthonormal frame whose columns are (t1, t2, n), n the unit ``normal``."""
    n = normal / np.linalg.norm(normal)
    seed = np.eye(3)[int(np.argmin(np.abs(n)))]
    t1 = np.cross(seed, n)
    t1 /= np.linalg.norm(t1)
    return np.column_stack([t1, np.cross(n, t1), n])


class PlaneContact:
    """The scene's plane and its spheres on Pinocchio's ``model`` (the module docstring: detection, constraints, solve).

    Attributes
    ----------
    detail : str
        What the rows' detail says of the contact.
    """

    def __init__(self, model: pin.Model, chain: Chain, contact: ChainContact) -> None:
        self._model, self._data = model, model.createData()
        self._joints, self._points = sphere_anchors(model, chain, contact)
        self._normal = np.asarray(contact.plane.normal_world, dtype=float)
        self._offset = float(contact.plane.offset)
        self._radii = np.array([s.radius for s in contact.spheres])
        self._friction = float(contact.friction)
        self._frame = _contact_frame(self._normal)
        self._solver, self._result = pin.ADMMConstraintSolver(), pin.ADMMSolverResult()
        self._settings = _limited(pin.ADMMSolverSettings())
        self._pgs_settings = _limited(pin.PGSSolverSettings())
        self.detail = (f"contact: PointContactConstraintModel per sphere at gap <= 0 (harness detection, no margin), "
                       f"friction {self._friction:g}{' (Coulomb cone)' if self._friction > 0 else ''}, no Baumgarte, "
                       f"no compliance; impulses by "
                       f"ADMMConstraintSolver on DelassusOperatorDense(J M^-1 J^T) at {SOLVER_TOLERANCE:g} "
                       + ("(polished on its active set, answer checked)" if self._friction == 0 else
                          "(the coupled problem, answer checked)")
                       + ", v' = v_free + M^-1 J^T lambda (Moreau-Jean, no restitution, penetration not corrected); "
                         "force = lambda / dt")

    def centres(self, configuration: np.ndarray) -> np.ndarray:
        """(S, 3) [m]: the spheres' centres in the world at Pinocchio's ``configuration`` (nq,)."""
        pin.forwardKinematics(self._model, self._data, configuration)
        return np.array([self._data.oMi[j].act(p) for j, p in zip(self._joints, self._points)])

    def solve(self, configuration: np.ndarray, v_free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(impulses (S, 3) [N s] in world axes on the spheres, the velocity change M^-1 J^T lambda (nv,)) of the step
        from ``configuration`` (nq,) whose unconstrained velocity would be ``v_free`` (nv,), in Pinocchio's
        coordinates. Zero where no sphere touches."""
        m, d = self._model, self._data
        centres = self.centres(configuration)
        active = np.flatnonzero(centres @ self._normal + self._offset - self._radii <= ACTIVE_GAP)
        impulses = np.zeros((len(self._radii), 3))
        if len(active) == 0:
            return impulses, np.zeros(m.nv)
        pin.computeJointJacobians(m, d, configuration)
        models, datas = pin.StdVec_ConstraintModel(), pin.StdVec_ConstraintData()
        rows = []
        for s in active:
            joint = self._joints[s]
            turn = d.oMi[joint].rotation.T
            world, point = centres[s], self._points[s]
            if self._friction > 0:  # at the contact point, whose slip friction resists
                world, point = world - self._radii[s] * self._normal, point - self._radii[s] * turn @ self._normal
            constraint = pin.PointContactConstraintModel(m, 0, pin.SE3(self._frame, world), joint,
                                                         pin.SE3(turn @ self._frame, point))
            constraint.setFriction(self._friction)
            data = constraint.createData()
            constraint.calc(m, d, data)
            rows.append(np.asarray(constraint.jacobian(m, d, data), dtype=float).reshape(3, m.nv))
            models.append(pin.ConstraintModel(constraint))
            datas.append(pin.ConstraintData(data))
        jacobian = np.concatenate(rows)
        mass = mass_matrix(m, d, configuration)
        mobility = np.linalg.solve(mass, jacobian.T)
        delassus, free = jacobian @ mobility, jacobian @ v_free
        if self._friction == 0:
            posed, posed_free = frictionless(delassus, free)
            local_impulses = polished(delassus, free, self._admm(posed, posed_free, models, datas))
        else:
            local_impulses = self._coulomb(delassus, free, models, datas)
        _check_answer(delassus, free, local_impulses, self._friction)
        impulses[active] = local_impulses.reshape(-1, 3) @ self._frame.T
        return impulses, mobility @ local_impulses

    def _admm(self, delassus: np.ndarray, free: np.ndarray, models, datas) -> np.ndarray:
        """(3k,) the impulses of Pinocchio's ADMM on Delassus matrix ``delassus`` (3k, 3k) and free velocity ``free``
        (3k,) at :data:`SOLVER_TOLERANCE`."""
        self._solver.solve(pin.DelassusOperatorDense(delassus), free, models, datas, self._settings, self._result)
        return np.asarray(self._result.retrieveConstraintImpulses(), dtype=float)

    def _coulomb(self, delassus: np.ndarray, free: np.ndarray, models, datas) -> np.ndarray:
        """(3k,) the impulses of the coupled problem with Coulomb's cone: Pinocchio's solvers in turn, ADMM on the
        problem, ADMM on the operator regularised by :data:`REGULARISATION` of its largest entry on its diagonal,
        then PGS, the first answer that solves it (:data:`NCP_RESIDUAL_COULOMB`), else the best (which the check
        refuses). Four feet of a rigid body make the operator singular (12 rows of rank 6): one solver stalls where
        another converges (Solo-12 on flat ground at mu 0.1-0.3: ADMM 1e-4 to 3e-3 of |g|, its regularised run 5e-9;
        at mu 0.001: ADMM 0.14, PGS 1e-9)."""
        regularised = delassus + REGULARISATION * float(np.max(np.abs(delassus))) * np.eye(len(free))
        best, best_residual = np.zeros_like(free), math.inf
        for solve in (lambda: self._admm(delassus, free, models, datas),
                      lambda: self._admm(regularised, free, models, datas),
                      lambda: self._pgs(delassus, free, models, datas)):
            candidate = solve()
            residual = ncp_residual(delassus, free, candidate, self._friction)
            if residual < best_residual:
                best, best_residual = candidate, residual
            if best_residual <= NCP_RESIDUAL_COULOMB:
                break
        return best

    def _pgs(self, delassus: np.ndarray, free: np.ndarray, models, datas) -> np.ndarray:
        """(3k,) the impulses of Pinocchio's PGS (:meth:`_admm`'s arguments), at its iteration limit and tolerance."""
        result = pin.PGSSolverResult()  # a fresh solver and result per solve: nothing carried from the last
        pin.PGSConstraintSolver().solve(pin.DelassusOperatorDense(delassus), free, models, datas, self._pgs_settings,
                                        result)
        return np.asarray(result.retrieveConstraintImpulses(), dtype=float)


def _limited(settings):
    """Pinocchio's solver ``settings`` (ADMM's or PGS's) at :data:`SOLVER_MAX_ITERATIONS` and every tolerance at
    :data:`SOLVER_TOLERANCE`: the same stopping rule for each solver the contact tries."""
    settings.max_iterations = SOLVER_MAX_ITERATIONS
    settings.absolute_complementarity_tol = settings.absolute_feasibility_tol = SOLVER_TOLERANCE
    settings.relative_complementarity_tol = settings.relative_feasibility_tol = SOLVER_TOLERANCE
    return settings


def frictionless(delassus: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The problem the solver is given, (Delassus (3k, 3k), free velocity (3k,)): ``delassus`` and ``free`` with every
    tangential row and column decoupled, a diagonal entry the largest |G| and a free velocity 0. On a frictionless
    plane the cone forces lambda_t = 0, so the normal rows sigma_n = G_nn lambda_n + g_n are those of the coupled
    problem and the answer is the same; Pinocchio 4.1's ADMM does not converge on the coupled form with friction 0 (on
    Solo-12's four feet touching at once in ``solo12-drop-stand``: primal feasibility 0.019 after 20,000 iterations
    at any tolerance from 1e-6 to 1e-12), and on this one converges in ~130 iterations to the answer the normal
    problem's active sets give."""
    normal = np.arange(2, len(free), 3)
    posed = np.eye(len(free)) * float(np.max(np.abs(delassus)))
    posed[np.ix_(normal, normal)] = delassus[np.ix_(normal, normal)]
    posed_free = np.zeros_like(free)
    posed_free[normal] = free[normal]
    return posed, posed_free


def polished(delassus: np.ndarray, free: np.ndarray, impulses: np.ndarray) -> np.ndarray:
    """The solver's ``impulses`` (3k,) polished on the contacts it pushes: their normal impulses solved exactly from
    G_AA lambda_A = -g_A (least squares), so that each pushed sphere's normal velocity after the step is 0 to
    rounding, not to the solver's tolerance (a 1e-12 residual velocity under a standing force does work: measured on
    the pressed arm, 1e-11 J over a second, all of its energy budget's change); kept only where the polished answer is
    no worse (:func:`ncp_residual`), the solver's answer otherwise."""
    normal = np.arange(2, len(free), 3)
    pushed = normal[impulses[normal] > 0.0]
    if len(pushed) == 0:
        return impulses
    out = np.zeros_like(impulses)
    out[pushed] = np.linalg.lstsq(delassus[np.ix_(pushed, pushed)], -free[pushed], rcond=None)[0]
    return out if ncp_residual(delassus, free, out) <= ncp_residual(delassus, free, impulses) else impulses


def ncp_residual(delassus: np.ndarray, free: np.ndarray, impulses: np.ndarray, friction: float = 0.0) -> float:
    """[1] How far ``impulses`` (3k,) (t1, t2, n per contact) are from solving the contact problem of Delassus matrix
    ``delassus`` (3k, 3k) and free velocity ``free`` (3k,) (:data:`NCP_RESIDUAL`'s terms), relative to max |free|;
    where nothing moves (free = 0) the answer is no impulse: 0 for it, infinite for any other. With Coulomb
    ``friction`` mu > 0 the tangential term is the Coulomb problem's natural-map residual (:func:`_cone_terms`): a
    contact either sticks inside its cone or slides on it against its slip."""
    scale = float(np.max(np.abs(free)))
    if scale == 0.0:
        return 0.0 if not np.any(impulses) else math.inf
    sigma = (delassus @ impulses + free).reshape(-1, 3)
    lam = impulses.reshape(-1, 3)
    stiffness = float(np.max(np.abs(delassus)))
    size = max(float(np.max(np.abs(lam[:, 2]))), np.finfo(float).tiny)
    terms = (np.maximum(-sigma[:, 2], 0.0), np.maximum(-lam[:, 2], 0.0) * stiffness,
             np.abs(lam[:, 2] * sigma[:, 2]) / size,
             np.abs(lam[:, :2]).max(axis=1) * stiffness if friction == 0
             else _cone_terms(sigma, lam, friction, stiffness))
    return float(max(np.max(t) for t in terms)) / scale


def _cone_terms(sigma: np.ndarray, lam: np.ndarray, friction: float, stiffness: float) -> np.ndarray:
    """(k,) [m/s] the Coulomb problem's natural-map residual per contact (De Saxce's form, Acary & Brogliato 2008):
    |G| |lambda - P_K(lambda - (sigma + mu |sigma_t| e_n) / |G|)| of velocities and impulses (k, 3) (t1, t2, n), P_K
    the projection on the cone |lambda_t| <= mu lambda_n; 0 exactly where each contact either is off, sticks inside
    its cone, or slides on it against its slip, and for a sliding contact about its slip times its impulse's error of
    direction (slow slips are ill-conditioned in direction; the product is what the step's energy sees)."""
    modified = sigma + friction * np.linalg.norm(sigma[:, :2], axis=1)[:, None] * np.array([0.0, 0.0, 1.0])
    return np.linalg.norm(lam - _cone_projection(lam - modified / stiffness, friction), axis=1) * stiffness


def _cone_projection(x: np.ndarray, friction: float) -> np.ndarray:
    """(k, 3) each row (t1, t2, n) of ``x`` projected on the cone |t| <= mu n."""
    t = np.linalg.norm(x[:, :2], axis=1)
    n = x[:, 2]
    inside, polar = t <= friction * n, friction * t <= -n
    on = (friction * t + n) / (1 + friction**2)
    scale = np.where(inside | polar | (t == 0), 0.0, friction * on / np.where(t > 0, t, 1.0))
    edge = np.column_stack([x[:, :2] * scale[:, None], on])
    return np.where(inside[:, None], x, np.where(polar[:, None], 0.0, edge))


def _check_answer(delassus: np.ndarray, free: np.ndarray, impulses: np.ndarray, friction: float) -> None:
    """Raise :class:`DivergedError` when the solver's ``impulses`` do not solve the problem (:func:`ncp_residual`)."""
    residual = ncp_residual(delassus, free, impulses, friction)
    allowed = NCP_RESIDUAL if friction == 0 else NCP_RESIDUAL_COULOMB
    if not residual <= allowed:
        raise DivergedError(f"Pinocchio's contact solve leaves a residual of {residual:.3g} of "
                            f"the free contact velocity (allowed {allowed:g}): its impulses do not solve the step")
