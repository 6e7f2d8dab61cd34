"""The one engine interface shared by the in-house core and every reference.

An engine answers three questions about a scene: can you do it (:class:`Support`, with
the reason when not), build it (untimed), and run it (timed by the runner). Building and
running are split so the runner can time the stepping alone.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from simparity.core.model.errors import NotBatchedError, SimparityError
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.derivatives import DynamicsDerivatives, StepJacobian
from simparity.core.model.rigid_groups import CompiledJoints, RigidGroups
from simparity.core.model.ik_result import IKResult
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinds import Scene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.core.model.trajectory import FramePoses, JointTrajectory, Trajectory, joined, trajectory_pieces


SCHEME_KINDS = {
    # How a dynamics integrator steps a free body.
    "explicit_euler": "explicit (forward) Euler: first order, gains energy on any oscillation or spin",
    "semi_implicit_euler": "semi-implicit (symplectic) Euler: first order",
    "engine_euler": "semi-implicit Euler with the orientation advanced by the exponential map, as engines step: "
                    "first order",
    "implicit_damping": "semi-implicit Euler with velocity-dependent forces taken implicitly (MuJoCo's "
                              "implicit, implicitfast): first order, damps stiff drag and fast spins",
    "implicit_velocity": "semi-implicit Euler with every velocity-dependent joint force (damping and the Coriolis "
                         "and centrifugal forces) linearised implicitly (MuJoCo's implicit on a chain): first order",
    "midpoint": "the explicit midpoint rule (RK2): second order",
    "average_velocity": "the lecture's average-velocity rule (Heun's method, RK2): second order",
    "rk4": "classical fourth-order Runge-Kutta",
    "engine_rk4": "classical fourth-order Runge-Kutta whose stages move a floating base's orientation by the "
                  "exponential map of their velocity combination, as MuJoCo steps a free joint: fourth order, "
                  "another discretisation than RK4 on the quaternion in R^4",
    "taylor2": "the lecture's Taylor rule for a point: exact under constant acceleration",
    "constant_velocity": "the lecture's rule for a point no force acts on",
    "closed_form": "a closed-form solution (a truth, not a scheme)",
    "adaptive": "an adaptive high-order solve at a tight tolerance (a truth, not a scheme)",
    # How contact with a plane is treated (a contact scene's scheme is "<treatment>+<time integrator>").
    "backup": "time backed up to each contact, the response there (exact for ballistic flight)",
    "act_after": "the kinematic response after the step in which the contact happened, with push-out",
    "penalty": "a spring-damper force on penetration, integrated by a time integrator",
    "soft": "a soft constraint (MuJoCo's solref/solimp), with no restitution coefficient",
    "impulse": "velocity-level impulses with restitution and position correction (Bullet)",
    # How a time integrator meets a load that changes with time (a prefix, as the contact treatments).
    "held": "a held load whose jumps fall inside steps: each such step is first order, whatever the scheme "
            "(comparisons.measure.held_forcing)",
    # How joint-space dynamics (mass matrix, bias forces, inverse and forward dynamics) are computed.
    "recursive": "Featherstone's recursive algorithms: Newton-Euler (RNEA), composite rigid body (CRBA), "
                 "articulated body (ABA) or a factorisation of M",
    "jacobian_sum": "the lecture's route: M and h summed over every link's centre-of-mass Jacobians, O(n^3)",
    # How the derivatives of joint-space dynamics are found (after a '+': "recursive+forward_differences").
    "analytic_derivatives": "derivatives in closed form (differentiated algorithms): exact up to rounding",
    "forward_differences": "forward differences (f(x + h) - f(x)) / h: truncation ~ h |d2f| / 2",
    "central_differences": "centred differences (f(x + h) - f(x - h)) / 2h: truncation ~ h^2 |d3f| / 6",
    # How an IK solver steps.
    "jacobian_inverse": "Newton steps with J^-1 (square, invertible Jacobians only)",
    "pseudo_inverse": "Newton steps with the Moore-Penrose pseudo-inverse of J",
    "transpose": "gradient steps along J^T e",
    "damped_least_squares": "damped least squares (Levenberg-Marquardt) steps",
    "nullspace": "a secondary objective projected into J's null space (after a '+')",
    "restarts": "restarts from random configurations when a solve stalls (after a '+')",
    "limits": "keeps the joints within their limits at every iteration (after a '+')",
}
"""The kinds of scheme the CI gate keys its bounds by (``scheme`` in a tolerances file), whatever the engine
calls its integrators: an engine's :meth:`Engine.scheme` answers with these names, joined by ``+`` where a
kind is modified (``damped_least_squares+nullspace``) or a contact treatment drives a time integrator
(``penalty+rk4``, ``soft+rk4``). "" is an engine that does not say, which only the bounds for every scheme
hold."""

TRUTH_SCHEMES = ("closed_form", "adaptive")
"""The kinds of scheme a truth is: a reference runs one where it has one, and no report ranks one beside the schemes
it judges."""

SCHEME_FAMILIES = {"engine_rk4": "rk4", "engine_euler": "semi_implicit_euler"}
"""Kinds that are another discretisation of the same order as a kind with more built-in engines: a user's scheme of
such a kind is cross-checked against its family's built-ins where no built-in of its own kind ran (a looser factor:
their error constants differ), so that a run without MuJoCo or PyBullet still holds it."""


def is_scheme_label(label: str) -> bool:
    """Whether ``label`` is "" or kinds of :data:`SCHEME_KINDS` joined by ``+``."""
    return label == "" or all(part in SCHEME_KINDS for part in label.split("+"))


def _offered(offered: tuple[str, ...], name: str, none: str, not_this: str) -> Support:
    """Support for ``name`` among what an engine ``offered``: yes, ``none`` when it offers nothing, else
    ``not_this 'name' (offers: ...)``."""
    if name in offered:
        return Support.yes()
    if not offered:
        return Support.no(none)
    return Support.no(f"{not_this} '{name}' (offers: {', '.join(offered)})")


@dataclass(frozen=True)
class Support:
    """Whether an engine can do what a scene asks, and why not when it cannot."""

    ok: bool
    reason: str = ""

    @classmethod
    def yes(cls) -> "Support":
        return cls(True)

    @classmethod
    def no(cls, reason: str) -> "Support":
        return cls(False, reason)


BatchedRun = Callable[[int], object]
"""``run(n_steps)`` of :meth:`Simulation.batched`: every copy stepped ``n_steps`` steps from the initial state; what it
returns is not measured (only its wall time is)."""


class Simulation(abc.ABC):
    """A dynamics scene built for one engine, integrator and time step.

    Attributes
    ----------
    detail : str
        What the engine was configured with beyond the scene (defaults switched off,
        harness-side stepping, ...); shown in the results' ``detail`` column.
    integrates_rotation : bool
        False when the scheme moves only the centre of mass (the lecture's point-mass
        rules): orientation and angular velocity stay at their initial values, so their
        errors and orders of convergence measure nothing.
    """

    detail: str = ""
    integrates_rotation: bool = True

    @abc.abstractmethod
    def run(self, n_steps: int) -> Trajectory:
        """Simulate ``n_steps`` steps from the scene's initial state.

        Every call starts again from the initial state. Returns a :class:`Trajectory` with
        ``n_steps + 1`` samples.
        """

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """The ``n_steps + 1`` samples of :meth:`run` in consecutive pieces of at most ``samples_per_piece``
        samples, the first starting at the initial state, each yielded as soon as it is stepped: the runner
        measures a piece and drops it, so an engine that steps in pieces holds memory flat in the number of steps.

        Every call starts again from the initial state. The default runs the whole trajectory and cuts it: an
        engine that only implements :meth:`run` still runs, its memory growing with the steps (the run says so;
        :func:`streams_in_pieces`). Override it (and :meth:`run` as the one-piece stream: :class:`PieceSimulation`)
        to stream.
        """
        yield from trajectory_pieces(self.run(n_steps), samples_per_piece)

    def batched(self, copies: int) -> BatchedRun:
        """``run(n_steps)`` stepping ``copies`` copies of the scene's initial state together, the same model and
        options as :meth:`run` (built here, untimed; the runner times its calls, each from the initial state, and
        stores the time per copy and step).

        Raises :class:`NotBatchedError` with the reason when the engine cannot step copies in one call: the
        default, so an engine that does not say has an ``n/a`` batched timing.
        """
        raise NotBatchedError("the engine's simulation declares no batched stepping (Simulation.batched)")


class PieceSimulation(Simulation):
    """A simulation that steps in pieces: subclasses implement :meth:`stream`; :meth:`run` is its one-piece
    stream."""

    def run(self, n_steps: int) -> Trajectory:
        return joined(self.stream(n_steps, n_steps + 1))

    @abc.abstractmethod
    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        """See :meth:`Simulation.stream`."""


def streams_in_pieces(sim: Simulation) -> bool:
    """Whether ``sim`` steps in pieces (overrides :meth:`Simulation.stream`): False for an engine that returns only
    whole trajectories, whose memory grows with the steps."""
    return type(sim).stream is not Simulation.stream


class JointSimulation(abc.ABC):
    """A joint-motion scene built for one engine, integrator and time step.

    Attributes
    ----------
    detail : str
        What the engine was configured with beyond the scene (defaults switched off, how damping and the applied
        forces reach its steps); shown in the results' ``detail`` column.
    """

    detail: str = ""

    @abc.abstractmethod
    def run(self, n_steps: int) -> JointTrajectory:
        """Step the scene's B copies ``n_steps`` steps from their initial states (every call starts again).
        Returns a :class:`JointTrajectory` with ``n_steps + 1`` samples at times k * dt."""

    @abc.abstractmethod
    def energy(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(kinetic, potential), each (B,) [J], at states q, qdot ((B, nq), (B, nv)), from the engine's own model:
        kinetic 1/2 qdot^T M qdot (armature included), potential -sum_i m_i g . c_i(q) (c_i the centre of mass
        of link i in the base frame, 0 without gravity). Not timed."""

    @abc.abstractmethod
    def end_effector_world(self, q: np.ndarray) -> np.ndarray:
        """(B, 3) [m]: the chain's end-effector origin in the base frame (a floating base's: in the world) at q
        ((B, nq)), by the engine's own forward kinematics. Not timed."""

    def batched(self, copies: int) -> BatchedRun:
        """``run(n_steps)`` stepping ``copies`` copies of the scene's first initial state together (as
        :meth:`Simulation.batched`); raises :class:`NotBatchedError` with the reason when the engine cannot."""
        raise NotBatchedError("the engine's joint simulation declares no batched stepping (JointSimulation.batched)")

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, 6): a floating-base chain's linear momentum [kg m/s] and its angular momentum about its own centre of
        mass [kg m^2/s], both in world axes, at states q (B, 7 + n) and qdot (B, 6 + n), from the engine's own model.
        Not timed. Optional: the momentum metrics are n/a where an engine does not say."""
        raise NotImplementedError(f"{type(self).__name__} does not report a floating base's momentum (momentum)")

    def contact_centres(self, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) [m]: the centres of the scene's contact spheres (``scene.contact.spheres``) in the world at
        configurations q (B, nq), by the engine's own forward kinematics. Not timed. A scene with contact needs it:
        without it every contact metric is n/a."""
        raise NotImplementedError(f"{type(self).__name__} does not report its contact spheres (contact_centres)")

    def contact_forces(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray) -> np.ndarray:
        """(B, S, 3) [N]: the force the plane exerts on each contact sphere, in world axes, at states q (B, nq) and
        qdot (B, nv) reached at ``times`` (B,) [s] (zero where a sphere does not touch), as the engine's contact model
        gives it at that state under the scene's applied forces at that time (a soft contact's force depends on them).
        The states come copy by copy, each copy's in the order of its run (where friction acts on a floating base, every
        step of it), so a reading that carries contact history (PyBullet's manifolds) carries its own run's.
        Not timed. Optional: the contact-force metrics are n/a where an engine does not say."""
        raise NotImplementedError(f"{type(self).__name__} does not report its contact forces (contact_forces)")

    def step_jacobian(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> StepJacobian:
        """The Jacobian of one step of this simulation's scheme and time step at B states q, qdot ((B, n) each) under
        joint forces ``tau`` (B, n) held over the step (the scene's timed torque left out): ∂(q', q̇')/∂(q, q̇) and
        ∂(q', q̇')/∂τ (:class:`core.model.derivatives.StepJacobian`). Optional: checked against the complex-step truth
        carried through the scheme's formula (``step_jacobian_error_max``), n/a where an engine does not say."""
        raise NotImplementedError(f"{type(self).__name__} does not report the Jacobian of its step (step_jacobian)")


class KinematicsModel(abc.ABC):
    """A chain built for one engine.

    Attributes
    ----------
    detail : str
    resolution : tuple of float
        (position [m], orientation [rad]) below which this engine's FK cannot tell two
        poses apart (0 for double precision); a judge of IK solutions grants that much.
    """

    detail: str = ""
    resolution: tuple[float, float] = (0.0, 0.0)

    @abc.abstractmethod
    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        """Poses of every joint's child-link frame and of the end effector.

        Parameters
        ----------
        q : (B, n) ndarray
            Joint values [rad or m].

        Returns
        -------
        FramePoses
            F = n + 1 frames in the order of :meth:`Chain.frame_names`.
        """

    @abc.abstractmethod
    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        """Geometric Jacobian of the end-effector frame.

        Rows 0-2 map joint velocities to the linear velocity of the end-effector origin,
        rows 3-5 to the angular velocity, both in world axes (Pinocchio's
        LOCAL_WORLD_ALIGNED). (B, n) -> (B, 6, n).
        """


class JointDynamicsModel(abc.ABC):
    """A chain's joint-space dynamics built for one engine and method: the base fixed, its frame the world's, or
    floating free (:attr:`Chain.floating_base`).

    Every function is batched over states: q, qdot, qddot, tau are (B, n) [rad or m, per second, per second
    squared; N m or N]; with a floating base q is (B, 7 + n) and the others (B, 6 + n), the base's pose and velocity
    first in the project's convention (:class:`core.model.scenes.chain.Chain`: world axes, the base origin's linear
    velocity, quat_wxyz). The equation of motion is M(q) qddot + h(q, qdot) + D qdot = tau, with D the joints'
    viscous damping (diagonal) and M including each joint's armature.

    Attributes
    ----------
    detail : str
        How the engine was given the chain and what it was switched to (shown in the rows).
    """

    detail: str = ""

    @abc.abstractmethod
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q), (B, n, n) [kg m^2, kg m, kg]: the joint-space inertia, armature included."""

    @abc.abstractmethod
    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """h(q, qdot) = C(q, qdot) qdot + g(q), (B, n): the joint forces that give zero acceleration with no
        damping (Coriolis, centrifugal and gravity; MuJoCo's ``qfrc_bias``, Pinocchio's ``nle``)."""

    @abc.abstractmethod
    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        """tau = M qddot + h + D qdot, (B, n): the joint forces that give ``qddot``."""

    @abc.abstractmethod
    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """qddot = M^-1 (tau - h - D qdot), (B, n)."""

    @abc.abstractmethod
    def link_kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B,) [J]: sum over the chain's links of 1/2 m |v_c|^2 + 1/2 omega^T I_c omega, from the engine's own
        forward kinematics of each link (its centre-of-mass velocity and angular velocity) and its own link masses
        and inertias, never from its mass matrix: an independent check of M (1/2 qdot^T M qdot, armature
        aside)."""

    def rigid_groups(self, q: np.ndarray) -> RigidGroups:
        """What the engine compiled, joint by joint, at joint values q (B, n) (a floating base at the world's origin,
        unturned): each chain joint's rigid group (its
        child link and the links welded to it) as mass, centre of mass and inertia about it, with the joint's axis
        and origin, all in the base frame (:class:`core.model.rigid_groups.RigidGroups`). Optional: an engine that
        does not report its compiled model raises NotImplementedError, and its model-parity rows are n/a."""
        raise NotImplementedError(f"{type(self).__name__} does not report its compiled model (rigid_groups)")

    def momentum(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, 6): the whole robot's momentum from the engine's own link velocities and masses (never from M):
        linear momentum [kg m/s] and angular momentum about the WORLD origin [kg m^2/s], world axes, the base's and
        every link's. Optional: checked against M's base rows on a floating base (``base_momentum_residual``), n/a
        where an engine raises NotImplementedError."""
        raise NotImplementedError(f"{type(self).__name__} does not report the robot's momentum (momentum)")

    def derivatives(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> DynamicsDerivatives:
        """The partial derivatives of inverse dynamics at (q, q̇, q̈ = its forward dynamics of tau) and of forward
        dynamics at (q, q̇, tau), B states (:class:`core.model.derivatives.DynamicsDerivatives`; the damping's D in
        ∂τ/∂q̇). Optional: checked against the complex-step truth (``*_derivative_error_max``), n/a where an engine
        raises NotImplementedError."""
        raise NotImplementedError(f"{type(self).__name__} does not report derivatives of its dynamics (derivatives)")

    def compiled_joints(self) -> CompiledJoints:
        """What the engine compiled of each chain joint, configuration aside: its type and limits
        (:class:`core.model.rigid_groups.CompiledJoints`). Optional, as :meth:`rigid_groups`."""
        raise NotImplementedError(f"{type(self).__name__} does not report its compiled joints (compiled_joints)")


@dataclass(frozen=True)
class StoppingRule:
    """The rule an IK solver stops by, in the residuals the harness measures: a solve meets it when its
    position residual is within ``position_tolerance`` [m] and its orientation residual within
    ``orientation_tolerance`` [rad] (``math.inf``: the solver never tests the orientation).

    ``description`` says the rule in the solver's own terms (``residualThreshold 1e-4 m``); ``note`` a known
    limitation of the solver that keeps it from its rule, with its upstream cause and link ("" when none).
    Both go into the detail of the ``solve_rate_own_stop`` row.
    """

    position_tolerance: float
    orientation_tolerance: float = math.inf
    description: str = ""
    note: str = ""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.position_tolerance) and self.position_tolerance > 0):
            raise ValueError(f"StoppingRule.position_tolerance must be finite and > 0, got {self.position_tolerance}")
        if not self.orientation_tolerance > 0:
            raise ValueError(f"StoppingRule.orientation_tolerance must be > 0 (inf: not tested), "
                             f"got {self.orientation_tolerance}")

    @property
    def criterion(self) -> str:
        """The rule as the report states it: ``position <= 0.0001 m, orientation not tested``."""
        angle = ("orientation not tested" if math.isinf(self.orientation_tolerance)
                 else f"orientation <= {self.orientation_tolerance:g} rad")
        return f"position <= {self.position_tolerance:g} m, {angle}"


class IKModel(abc.ABC):
    """An inverse-kinematics solver built for one chain.

    Attributes
    ----------
    detail : str
        What the solver is and how it was configured (library call, iterations, damping).
    stopping_rule : StoppingRule or None
        The rule the solver stops by when it is not the harness's (a library's default threshold); None: it
        stops at the scene's tolerances, which is what the harness judges success by. The harness reports the
        solve rate at both (``solve_rate``, ``solve_rate_own_stop``).
    """

    detail: str = ""
    stopping_rule: StoppingRule | None = None

    @abc.abstractmethod
    def solve(self, target_position_world: np.ndarray, target_rotation_world: np.ndarray | None,
              q_start: np.ndarray) -> IKResult:
        """Solve a batch of end-effector targets, every one from the same start.

        Parameters
        ----------
        target_position_world : (B, 3) ndarray
            [m].
        target_rotation_world : (B, 3, 3) ndarray or None
            End-effector to world rotation; ``None`` for position-only targets.
        q_start : (n,) ndarray
            Start configuration [rad or m].

        Returns
        -------
        IKResult
            Never raises for an unreachable or singular target; residuals are measured with
            the engine's own forward kinematics. ``iterations`` is -1 where the engine does
            not report it.
        """


class Engine(abc.ABC):
    """One engine: the in-house core, an analytic truth, or an adapter to a library."""

    name: str = ""

    @abc.abstractmethod
    def version(self) -> str:
        """Version string of the library behind the engine."""

    @abc.abstractmethod
    def integrators(self) -> tuple[str, ...]:
        """Names of the dynamics integrators the engine offers (empty if none)."""

    def scene_integrators(self, scene: DynamicsScene) -> tuple[str, ...]:
        """The integrators this engine runs on ``scene``: all of :meth:`integrators` unless the engine's
        methods differ by kind of scene (core runs its contact methods on a scene with contact, and its
        free-body integrators on the others). Each is a case of the scene; unsupported ones are n/a rows."""
        return self.integrators()

    @abc.abstractmethod
    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        """Whether :meth:`build_dynamics` can simulate ``scene`` with ``integrator``."""

    @abc.abstractmethod
    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        """Build the model for ``scene`` (not timed). Call only when supported."""

    @abc.abstractmethod
    def supports_kinematics(self, chain: Chain) -> Support:
        """Whether :meth:`build_kinematics` can evaluate ``chain``."""

    @abc.abstractmethod
    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        """Build the model for ``chain`` (not timed). Call only when supported."""

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        """Names of the ways the engine computes joint-space dynamics (each a case of a joint-dynamics scene,
        in its ``integrator`` column); empty (the default) when it has none, and its rows are n/a."""
        return ()

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        """Whether :meth:`build_joint_dynamics` can build ``chain`` with ``method``."""
        return _offered(self.joint_dynamics_methods(), method, f"{self.name} computes no joint-space dynamics",
                        f"{self.name} has no joint-dynamics method")

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        """Build ``chain``'s joint-space dynamics under ``gravity_world`` ((3,) [m/s^2] in the base frame, None for
        none) with ``method`` (not timed). Call only when supported."""
        raise SimparityError(f"engine '{self.name}' computes no joint-space dynamics "
                             "(allowed: an engine whose joint_dynamics_methods() is not empty)")

    def joint_motion_integrators(self) -> tuple[str, ...]:
        """Names of the integrators the engine steps a chain's joints with (each a case of a joint-motion scene);
        empty (the default) when it steps no chain, and its rows are n/a. :meth:`theoretical_order`,
        :meth:`stages` and :meth:`scheme` answer for them as for the free-body integrators."""
        return ()

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        """Whether :meth:`build_joint_motion` can step ``scene`` with ``integrator``; a scene with contact only where
        the engine says :meth:`chain_contact` (its contact reason otherwise)."""
        offered = _offered(self.joint_motion_integrators(), integrator, f"{self.name} steps no chain through time",
                           f"{self.name} has no joint-motion integrator")
        if offered.ok and scene.contact is not None:
            return self.chain_contact(scene)
        return offered

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """Whether the engine puts ``scene.contact``'s spheres and plane into its steps (and reports
        :meth:`JointSimulation.contact_centres` and, optionally, :meth:`JointSimulation.contact_forces`); no by
        default: an engine that does overrides this."""
        return Support.no(f"{self.name} declares no contact of a chain's spheres with a plane (Engine.chain_contact)")

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        """Build ``scene`` for stepping with ``integrator`` at ``dt`` [s] (not timed). Call only when supported."""
        raise SimparityError(f"engine '{self.name}' steps no chain through time "
                             "(allowed: an engine whose joint_motion_integrators() is not empty)")

    def theoretical_order(self, integrator: str) -> int | None:
        """Global order of accuracy the integrator has in theory (None: unknown, or it depends on the
        scene). Reports draw it beside the observed order."""
        return None

    def stages(self, integrator: str) -> int | None:
        """Evaluations of the scene's force model (the right-hand side of its ODE) per step of ``integrator``: a
        step's cost in the unit of Hairer's work-precision diagrams, the same on every machine (RK4 4, Euler 1).
        None: unknown (the default), or it varies from step to step (an adaptive solve, a closed form). The runner
        stores ``stages / dt``, evaluations per simulated second."""
        return None

    def scheme(self, integrator: str, scene: Scene) -> str:
        """What kind of scheme ``integrator`` (an IK solver on an IK scene) is on ``scene``, in the names of
        :data:`SCHEME_KINDS` (``rk4``, ``penalty+rk4``, ``damped_least_squares+nullspace``); "" when unknown.
        The CI gate holds every engine's scheme of a kind to that kind's bounds.

        By default an integrator named as a kind is of that kind (its variant, after the first ``+`` of
        :meth:`integrator_variant`, left out), and on a contact scene ``penalty_<kind>`` is ``penalty+<kind>``:
        an engine that names its integrators and solvers after what they are needs nothing more."""
        name = integrator
        if isinstance(scene, DynamicsScene):
            name = self.integrator_variant(integrator)[0]
            if scene.contact is not None and name.startswith("penalty_"):
                name = "penalty+" + name.removeprefix("penalty_")
        return name if is_scheme_label(name) else ""

    def integrator_variant(self, integrator: str) -> tuple[str, str]:
        """(scheme, variant) of an integrator: integrators that differ only in a variant of one scheme
        (core's orientation updates of RK4, say) share the scheme, and reports put them on one row.
        "" when the integrator has no variants."""
        return integrator, ""

    def ik_solvers(self) -> tuple[str, ...]:
        """Names of the IK solvers the engine offers (empty if none)."""
        return ()

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        """Whether :meth:`build_ik` can build ``solver`` for ``chain`` and this kind of target."""
        return _offered(self.ik_solvers(), solver, f"{self.name} offers no IK solver",
                        f"{self.name} has no IK solver")

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        """Build ``solver`` for ``chain`` with the scene's tolerances and iteration cap (not timed)."""
        raise SimparityError(f"engine '{self.name}' has no IK solvers (allowed: an engine whose ik_solvers() is not empty)")

    def check_integrator(self, integrator: str) -> Support:
        """Support for an integrator name alone."""
        if integrator in self.integrators():
            return Support.yes()
        offered = ", ".join(self.integrators()) or "none"
        return Support.no(f"{self.name} has no integrator '{integrator}' (offers: {offered})")

    def export(self, scene: DynamicsScene | KinematicsScene, integrator: str | None, dt: float | None) -> str:
        """Text of the model this engine is given for ``scene`` (MJCF, URDF, ...).

        ``integrator`` and ``dt`` apply to dynamics scenes; ``None`` picks the engine's
        first integrator and the scene's first time step.
        """
        raise SimparityError(f"engine '{self.name}' builds no model to export (allowed: mujoco, pybullet, pinocchio)")

    def _export_settings(self, scene: DynamicsScene, integrator: str | None, dt: float | None) -> tuple[str, float]:
        integrator = integrator or self.integrators()[0]
        support = self.check_integrator(integrator)
        if not support.ok:
            raise SimparityError(f"--integrator: {support.reason} (allowed: {', '.join(self.integrators())})")
        dt = scene.dts[0] if dt is None else dt
        if not (dt > 0 and dt < float("inf")):
            raise SimparityError(f"--dt {dt}: not a time step (allowed: a finite number of seconds > 0)")
        return integrator, dt
