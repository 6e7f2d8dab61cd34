"""Pinocchio 4.1's PGS on a frictionless plane claims convergence after 0 iterations with a wrong answer: corners it
pushes keep sinking. Its ADMM solves the same problem.

A free-flying box (1 kg) falls at 0.6 m/s onto a plane with three of its bottom corners touching at once: three
PointContactConstraintModels, friction 0 (the cone is the normal's half-line). One velocity-level step asks for
impulses lambda with G lambda + g in the dual cone, lambda in the cone and complementarity, G = J M^-1 J^T (Pinocchio's
crba and constraint Jacobians), g = J v. Its answer is checked here independently: every pushed corner must stop
(normal velocity after the step sigma_n = 0), none may sink (sigma_n >= 0), none may be pulled (lambda_n >= 0); the
exact answer comes from enumerating the active sets of the 3 x 3 normal problem.

With the tangential rows decoupled (exact when friction is 0: the cone forces lambda_t = 0) PGS is as wrong and ADMM
as right. simparity's Pinocchio adapter (references/pinocchio/contact.py) uses ADMM on the decoupled problem: on the
coupled one ADMM did not converge on Solo-12's four feet touching at once (primal feasibility 0.019 after 20,000
iterations at any tolerance, measured in simparity's solo12-drop-stand; this box does not show it), polishes its answer
on its active set and checks every answer it takes. Run: python docs/examples/pinocchio_frictionless_solvers.py
(needs pinocchio; under a second)."""

import itertools

import numpy as np
import pinocchio as pin

HALF = np.array([0.2, 0.15, 0.1])  # [m] the box's half sizes
CORNERS = np.array([[HALF[0], HALF[1], -HALF[2]], [-HALF[0], HALF[1], -HALF[2]], [0.0, -HALF[1], -HALF[2]]])
SPEED = 0.6  # [m/s] downwards, at the instant all three corners touch
TOLERANCE = 1e-12

model = pin.Model()
box = pin.Inertia.FromBox(1.0, *(2 * HALF))
joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
model.appendBodyToJoint(joint, box, pin.SE3.Identity())
data = model.createData()
q = pin.neutral(model)
q[2] = HALF[2]  # the bottom face on the plane z = 0
v = np.zeros(model.nv)
v[2] = -SPEED
pin.computeJointJacobians(model, data, q)
mass = pin.crba(model, data, q)
mass = np.triu(mass) + np.triu(mass, 1).T


def problem(friction: float):
    """(constraint models, datas, G, g) of the three corners with Coulomb friction ``friction``."""
    models, datas, rows = pin.StdVec_ConstraintModel(), pin.StdVec_ConstraintData(), []
    for corner in CORNERS:
        world = data.oMi[joint].act(corner)
        constraint = pin.PointContactConstraintModel(model, 0, pin.SE3(np.eye(3), world), joint,
                                                     pin.SE3(data.oMi[joint].rotation.T, corner))
        constraint.setFriction(friction)
        constraint_data = constraint.createData()
        constraint.calc(model, data, constraint_data)
        rows.append(np.asarray(constraint.jacobian(model, data, constraint_data)).reshape(3, model.nv))
        models.append(pin.ConstraintModel(constraint))
        datas.append(pin.ConstraintData(constraint_data))
    jacobian = np.concatenate(rows)
    return models, datas, jacobian @ np.linalg.solve(mass, jacobian.T), jacobian @ v


def solve(solver, settings, result, delassus, free, models, datas):
    settings.max_iterations = 20_000
    settings.absolute_complementarity_tol = settings.absolute_feasibility_tol = TOLERANCE
    settings.relative_complementarity_tol = settings.relative_feasibility_tol = TOLERANCE
    converged = solver.solve(pin.DelassusOperatorDense(delassus), free, models, datas, settings, result)
    return converged, result.iterations, np.asarray(result.retrieveConstraintImpulses(), dtype=float)


def exact(delassus, free):
    """The frictionless answer by enumerating the normal problem's active sets."""
    normal = np.arange(2, len(free), 3)
    g_n, g_nn = free[normal], delassus[np.ix_(normal, normal)]
    for size in range(len(normal) + 1):
        for active in map(list, itertools.combinations(range(len(normal)), size)):
            lam = np.zeros(len(normal))
            if active:
                lam[active] = np.linalg.solve(g_nn[np.ix_(active, active)], -g_n[active])
            if np.all(lam >= -1e-12) and np.all(g_nn @ lam + g_n >= -1e-12):
                out = np.zeros(len(free))
                out[normal] = lam
                return out
    raise RuntimeError("no solution")


def report(label, converged, iterations, impulses, delassus, free):
    sigma = (delassus @ impulses + free)[2::3]
    print(f"{label}: claims converged = {converged}, iterations = {iterations}; "
          f"slowest normal velocity after = {sigma.min():.3e} m/s (a corner sinking if < 0); "
          f"normal impulses = {np.round(impulses[2::3], 6)}")


models, datas, delassus, free = problem(0.0)
truth = exact(delassus, free)
report("exact (active sets)", True, 0, truth, delassus, free)
report("PGS, friction 0", *solve(pin.PGSConstraintSolver(), pin.PGSSolverSettings(), pin.PGSSolverResult(),
                                 delassus, free, models, datas), delassus, free)
report("ADMM, friction 0", *solve(pin.ADMMConstraintSolver(), pin.ADMMSolverSettings(), pin.ADMMSolverResult(),
                                  delassus, free, models, datas), delassus, free)
normal = np.arange(2, len(free), 3)
decoupled = np.eye(len(free)) * np.abs(delassus).max()
decoupled[np.ix_(normal, normal)] = delassus[np.ix_(normal, normal)]
decoupled_free = np.where(np.isin(np.arange(len(free)), normal), free, 0.0)
report("ADMM, friction 0, tangential rows decoupled",
       *solve(pin.ADMMConstraintSolver(), pin.ADMMSolverSettings(), pin.ADMMSolverResult(), decoupled,
              decoupled_free, models, datas), delassus, free)
report("PGS, friction 0, tangential rows decoupled",
       *solve(pin.PGSConstraintSolver(), pin.PGSSolverSettings(), pin.PGSSolverResult(), decoupled,
              decoupled_free, models, datas), delassus, free)
print(f"pinocchio {pin.__version__}")
