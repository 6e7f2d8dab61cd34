"""The in-house engine: the lecture's methods in ``core`` behind the shared interface."""

from __future__ import annotations

import platform
from collections.abc import Iterator
from dataclasses import asdict, replace

import numpy as np

from simparity.core.dynamics import point_mass
from simparity.core.runtime.allocator import keep_freed_memory
from simparity.core.contact.bodies import (
    FLIGHT_SCHEME,
    PENALTY_SCHEMES,
    Bodies,
    ContactModel,
    EventLog,
    penalty_stability_limit,
    penalty_wrench,
)
from simparity.core.contact.act_after import GAUSS_SEIDEL_PASSES, ActAfterStepper
from simparity.core.contact.backup import FREE, MAX_EVENTS_PER_STEP, BackupStepper
from simparity.core.model.engine import (BatchedRun, Engine, IKModel, JointDynamicsModel, JointSimulation,
                                         KinematicsModel, PieceSimulation, Simulation, Support)
from simparity.core.articulated import model as joint_dynamics
from simparity.core.articulated import stepping as joint_stepping
from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.dynamics.forces import make_wrench
from simparity.core.ik.jacobian_solvers import METHODS, IKOptions, solve_ik, task_basis
from simparity.core.model.ik_problem import IKTolerances
from simparity.core.ik.restarts import Restarts, solve_ik_with_restarts
from simparity.core.model.ik_result import IKResult
from simparity.core.dynamics.integrators import ORDER, ORIENTATION_UPDATES, SCHEMES, STAGES, Step, make_step
from simparity.core.dynamics.quaternion_integrators import PackedBodies, make_packed_step, pack
from simparity.core.kinematics import forward_kinematics, jacobian_world
from simparity.core.dynamics.rigid_body import MassProperties, State, initial_state, velocities
from simparity.core.rotations import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.contact import PENALTY_PREFIX
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import FramePoses, Trajectory, piece_bounds

_DEFAULT_ORIENTATION = "quaternion"
_SINGLE_ORIENTATION_SCHEMES = ("engine_euler",)
"""Schemes with one orientation update of their own (the engines' scheme: always the exponential map)."""


def integrator_names() -> tuple[str, ...]:
    """``scheme`` (quaternion orientation), ``scheme+matrix``, ``scheme+expmap``, particle rules."""
    names = []
    for scheme in SCHEMES:
        names.append(scheme)
        if scheme not in _SINGLE_ORIENTATION_SCHEMES:
            names.extend(f"{scheme}+{o}" for o in ORIENTATION_UPDATES if o != _DEFAULT_ORIENTATION)
    return tuple(names) + tuple(point_mass.RULES)


CONTACT_INTEGRATORS = ("backup", "act_after") + tuple(PENALTY_PREFIX + scheme for scheme in PENALTY_SCHEMES)
"""Core's contact methods (:data:`core.scene.CONTACT_METHODS`) as integrator names: ``penalty`` once per
scheme that integrates it."""


def contact_integrators(methods: tuple[str, ...]) -> tuple[str, ...]:
    """The integrator names of contact methods, in :data:`CONTACT_INTEGRATORS`' order (``backup``, the exact
    one, first: a scene whose reference is core is measured against it): ``penalty`` -> every
    ``penalty_<scheme>``."""
    return tuple(name for name in CONTACT_INTEGRATORS
                 if name in methods or ("penalty" in methods and name.startswith(PENALTY_PREFIX)))


def parse_integrator(name: str) -> tuple[str, str]:
    """``"rk4+expmap"`` -> ``("rk4", "expmap")``; no suffix means quaternion."""
    scheme, _, orientation = name.partition("+")
    return scheme, orientation or _DEFAULT_ORIENTATION


PARTICLE_STAGES = 1
"""Wrench evaluations per step of a particle rule: the particle loop evaluates the scene's force once per step,
whatever the rule (``constant_velocity`` discards it)."""


class _InHouseSimulation(PieceSimulation):
    """Core's simulations, vectorised over bodies: copies of a scene step together as one scene of their bodies."""

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        self._scene, self._integrator, self._dt = scene, integrator, dt

    def batched(self, copies: int) -> BatchedRun:
        """The run of this simulation built again for ``copies`` copies of its scene
        (:meth:`DynamicsScene.replicated`): one call of every step for all of them."""
        return type(self)(self._scene.replicated(copies), self._integrator, self._dt).run


class _RigidBodySimulation(_InHouseSimulation):
    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        super().__init__(scene, integrator, dt)
        scheme, orientation = parse_integrator(integrator)
        self._props = MassProperties.of(scene.bodies)
        wrench = make_wrench(scene.forces, self._props)
        # Quaternion updates and the engines' scheme step the packed layout (the speed path).
        self._packed = orientation == "quaternion" or scheme in _SINGLE_ORIENTATION_SCHEMES
        self._state0 = initial_state(scene.bodies, self._props, quaternion=self._packed)
        if self._packed:
            self._bodies = PackedBodies(self._props)
            self._packed_step = make_packed_step(scheme, self._props, wrench)
        else:
            self._step = make_step(scheme, orientation, self._props, wrench)
        self.detail = f"in-house {scheme}, orientation update: {orientation}"

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        pieces = self._packed_pieces if self._packed else self._matrix_pieces
        for (start, stop), samples in zip(piece_bounds(n_steps, samples_per_piece),
                                          pieces(n_steps, samples_per_piece)):
            yield Trajectory(np.arange(start, stop) * self._dt, *samples)

    def _packed_pieces(self, n_steps: int, samples_per_piece: int) -> Iterator[tuple[np.ndarray, ...]]:
        """(x, q, v, omega) of each piece's samples, each (T, B, k), from the packed state."""
        state, dt = pack(self._state0), self._dt
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            record = np.empty((stop - start,) + state.shape)
            for j, i in enumerate(range(start, stop)):
                if i:
                    state = self._packed_step((i - 1) * dt, state, dt)
                record[j] = state
            yield self._bodies.samples(record.transpose(1, 0, 2))

    def _matrix_pieces(self, n_steps: int, samples_per_piece: int) -> Iterator[tuple[np.ndarray, ...]]:
        """(x, q, v, omega) of each piece's samples, each (T, B, k), from rotation-matrix states."""
        state, dt = self._state0, self._dt
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            pos, mom, ang = (np.empty((stop - start,) + state.position_world.shape) for _ in range(3))
            ori = np.empty((stop - start,) + state.orientation.shape)
            for j, i in enumerate(range(start, stop)):
                if i:
                    state = self._step((i - 1) * dt, state, dt)
                pos[j], ori[j], mom[j], ang[j] = (state.position_world, state.orientation, state.momentum_world,
                                                  state.angular_momentum_world)
            # Velocities and quaternions of the piece's samples at once, broadcast over (T, B).
            vel, omg = velocities(State(pos, ori, mom, ang), self._props)
            yield pos, matrix_to_quat_wxyz(ori), vel, omg


class _ParticleSimulation(_InHouseSimulation):
    """The lecture's point-mass rules; orientation and angular velocity stay at their initial values."""

    integrates_rotation = False

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        super().__init__(scene, integrator, dt)
        self._rule = point_mass.RULES[integrator]
        props = MassProperties.of(scene.bodies)
        self._wrench = make_wrench(scene.forces, props)
        self._mass = props.mass[:, None]
        self._x0 = np.stack([b.position_world for b in scene.bodies])
        self._v0 = np.stack([b.velocity_world for b in scene.bodies])
        self._q0 = np.stack([b.quat_wxyz for b in scene.bodies])
        self._r0 = quat_wxyz_to_matrix(np.stack([b.quat_wxyz for b in scene.bodies]))
        self.detail = f"in-house particle rule {integrator} (lecture, Bodies in Free Fall)"

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        x, v, dt = self._x0, self._v0, self._dt
        zero = np.zeros_like(x)
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            pos, vel = np.empty((stop - start,) + x.shape), np.empty((stop - start,) + x.shape)
            for j, i in enumerate(range(start, stop)):
                if i:
                    force, _ = self._wrench((i - 1) * dt, x, self._r0, v, zero)
                    x, v = self._rule(x, v, force / self._mass, dt)
                pos[j], vel[j] = x, v
            quat = np.broadcast_to(self._q0, (stop - start,) + self._q0.shape)
            omg = np.zeros((stop - start,) + x.shape)
            yield Trajectory(np.arange(start, stop) * dt, pos, quat, vel, omg)


class _ContactSimulation(_InHouseSimulation):
    """Bodies against the scene's planes by one of core's contact methods.

    After :meth:`run`, ``events`` holds the backup method's contact events (:class:`core.contact.bodies.EventLog`;
    empty for the other methods).
    """

    def __init__(self, scene: DynamicsScene, integrator: str, dt: float) -> None:
        super().__init__(scene, integrator, dt)
        contact = scene.contact
        assert contact is not None  # built only when supported: contact integrators need the scene's contact
        self._props = MassProperties.of(scene.bodies)
        self._state0 = initial_state(scene.bodies, self._props, quaternion=True)
        self._model = ContactModel.of(contact, self._props.mass)
        self._method = integrator
        self.events = EventLog()
        if integrator == "backup":
            self._backup = BackupStepper(Bodies(self._props, self._model, scene.forces))
            self.detail = (f"in-house backup: time backed up to each contact (exact root for bodies that do not "
                           f"turn, bracketed root finder otherwise), impulse with restitution and Coulomb friction, "
                           f"resting contact below rest_speed {contact.rest_speed:g} m/s; free flight {FLIGHT_SCHEME} "
                           f"(quaternion); at most {MAX_EVENTS_PER_STEP} events per body and step (more: put at "
                           f"rest); a body at rest slides or stays, it never rolls (a sphere sliding with friction "
                           f"stops instead of rolling)")
        elif integrator == "act_after":
            self._step: Step = ActAfterStepper(Bodies(self._props, self._model, scene.forces)).step
            self.detail = (f"in-house act_after: free flight {FLIGHT_SCHEME} (quaternion), then push-out and impulse "
                           f"with restitution and Coulomb friction ({GAUSS_SEIDEL_PASSES} Gauss-Seidel passes), plastic "
                           f"below rest_speed {contact.rest_speed:g} m/s and for a body touching since the step's "
                           f"start; pushed out before each sample, so no penetration shows")
        else:
            scheme = integrator.removeprefix(PENALTY_PREFIX)
            wrench = penalty_wrench(self._model, self._props, make_wrench(scene.forces, self._props))
            self._step = make_step(scheme, "quaternion", self._props, wrench)
            undamped = float(penalty_stability_limit(scheme, contact.penalty_stiffness, self._props.mass).min())
            damping = (f"k_d {contact.penalty_damping:g} N s/m" if contact.penalty_damping is not None else
                       "k_d " + ", ".join(f"{c:.4g}" for c in np.unique(self._model.damping)) + " N s/m (from each "
                       "pair's restitution, linear spring-damper)")
            self.detail = (f"in-house penalty: k_s {contact.penalty_stiffness:g} N/m, {damping}, regularised "
                           f"Coulomb friction (mu_k), integrated by {scheme} (quaternion); "
                           f"restitution and rest_speed not used; in theory an undamped linear spring is "
                           + (f"stable below {undamped:.3g} s" if undamped > 0 else "unstable at every step"))

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        state, dt = self._state0, self._dt
        self.events = EventLog()
        resting = np.full(len(self._props.mass), FREE)
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            pos, mom, ang = (np.empty((stop - start,) + state.position_world.shape) for _ in range(3))
            ori = np.empty((stop - start,) + state.orientation.shape)
            for j, i in enumerate(range(start, stop)):
                if i and self._method == "backup":
                    state, resting = self._backup.step((i - 1) * dt, state, resting, dt, self.events)
                elif i:
                    state = self._step((i - 1) * dt, state, dt)
                pos[j], ori[j], mom[j], ang[j] = (state.position_world, state.orientation, state.momentum_world,
                                                  state.angular_momentum_world)
            vel, omg = velocities(State(pos, ori, mom, ang), self._props)
            if stop == n_steps + 1:
                self._report_caps()
            yield Trajectory(np.arange(start, stop) * dt, pos, ori, vel, omg)

    def _report_caps(self) -> None:
        """Say in the detail how often a body hit the per-step event cap and was put at rest (never silently)."""
        self._base_detail = getattr(self, "_base_detail", self.detail)
        capped = self.events.kind.count("cap")
        self.detail = self._base_detail + (f"; {capped} times a body reached the cap of {MAX_EVENTS_PER_STEP} "
                                           "events in a step and was put at rest" if capped else "")


class _Kinematics(KinematicsModel):
    def __init__(self, chain: Chain) -> None:
        self._chain = chain
        self.detail = "in-house FK; Jacobian columns a_i x (E - P_i) (lecture)"

    def forward_kinematics(self, q: np.ndarray) -> FramePoses:
        return forward_kinematics(self._chain, q)

    def jacobian_world(self, q: np.ndarray) -> np.ndarray:
        return jacobian_world(self._chain, q)


NULLSPACE = "damped_least_squares+nullspace"
"""Damped least squares plus the lecture's control expression pulling toward the start pose."""

RESTARTS = "damped_least_squares+restarts"
"""Damped least squares with TRAC-IK's restarts from seeded random configurations (:mod:`core.ik.restarts`)."""


class _InHouseIK(IKModel):
    def __init__(self, chain: Chain, solver: str, options: IKOptions) -> None:
        self._chain, self._options = chain, options
        self._method = solver.partition("+")[0]
        self._nullspace = solver == NULLSPACE
        self._restarts = Restarts() if solver == RESTARTS else None
        restarts = self._restarts
        self.detail = (f"in-house {self._method} (batched), max step {options.max_step:g} rad, hard joint limits"
                       + ("; null-space term H = sum a (q - q_start)^2 toward the start pose" if self._nullspace else "")
                       + (f"; failed targets restarted from up to {restarts.attempts} seeded random configurations "
                          f"({restarts.starts_per_round} per round, more when fewer than {restarts.min_round_rows} "
                          f"would make the round, seed {restarts.seed}"
                          f"{'; the first round the pool poses nearest each target' if restarts.nearest_first else ''}"
                          f"; a target's other starts stopped at its first solution), each attempt at most "
                          f"{restarts.max_iterations} iterations with Levenberg-Marquardt damping lambda^2 = "
                          f"{restarts.error_damping:g} |e|^2 + {restarts.damping_floor:g}^2, abandoned after "
                          f"{restarts.stall_window} iterations without a {restarts.stall_ratio:.0%} fall of |e|"
                          if restarts else ""))

    def solve(self, target_position_world, target_rotation_world, q_start) -> IKResult:
        options = replace(self._options, rest_pose=np.asarray(q_start, dtype=float)) if self._nullspace else self._options
        if self._restarts is not None:
            return solve_ik_with_restarts(self._chain, target_position_world, target_rotation_world, q_start,
                                          self._method, options, self._restarts)
        return solve_ik(self._chain, target_position_world, target_rotation_world, q_start, self._method, options)


class InHouseEngine(Engine):
    """The lecture's methods as implemented in ``core``."""

    name = "core"

    def __init__(self) -> None:
        keep_freed_memory()  # batched temporaries: see core/runtime/allocator.py

    def version(self) -> str:
        return f"numpy {np.__version__}, python {platform.python_version()}"

    def integrators(self) -> tuple[str, ...]:
        return integrator_names() + CONTACT_INTEGRATORS

    def scene_integrators(self, scene: DynamicsScene) -> tuple[str, ...]:
        """Of :meth:`integrators`: the contact methods the scene asks for on a scene with contact, the
        free-body integrators otherwise."""
        if scene.contact is None:
            return tuple(i for i in self.integrators() if i not in CONTACT_INTEGRATORS)
        return tuple(i for i in contact_integrators(scene.contact.methods) if i in self.integrators())

    def integrator_variant(self, integrator: str) -> tuple[str, str]:
        """(scheme, orientation update) of a rigid-body integrator; particle rules and contact methods have none."""
        scheme, orientation = parse_integrator(integrator)
        no_variants = integrator in point_mass.RULES or integrator in CONTACT_INTEGRATORS
        if no_variants or scheme in _SINGLE_ORIENTATION_SCHEMES:
            return integrator, ""
        return scheme, orientation

    def theoretical_order(self, integrator: str) -> int | None:
        """The scheme's order (:data:`core.dynamics.integrators.ORDER`); None for the particle rules (it depends on the
        scene) and the contact methods (a contact's first-order or exact treatment dominates the scheme's)."""
        if integrator in CONTACT_INTEGRATORS:
            return None
        if integrator in joint_stepping.SCHEMES:
            return joint_stepping.ORDER[integrator]
        return ORDER.get(parse_integrator(integrator)[0])

    def stages(self, integrator: str) -> int | None:
        """Wrench evaluations per step, counted in the code (:data:`core.dynamics.integrators.STAGES`): a scheme's stages
        whatever its orientation update; a particle rule 1 (:data:`PARTICLE_STAGES`); ``penalty_<scheme>`` its
        scheme's (the penalty force is part of the wrench); backup and act_after their free flight's, RK4's 4.
        That is all act_after evaluates (its push-out and impulses evaluate no force). Backup's event handling is
        not counted, so its 4 is a lower bound: every step it also evaluates the wrench for the resting support
        (1) and the contact search (1 for the exact root, a trial flight of 4 for the root finder), and backing
        up time to each contact adds root-finder flights and a second flight for the rest of the step. None for
        an integrator core does not offer."""
        if integrator in point_mass.RULES:
            return PARTICLE_STAGES
        if integrator in ("backup", "act_after"):
            return STAGES[FLIGHT_SCHEME]
        if integrator in CONTACT_INTEGRATORS:
            return STAGES[integrator.removeprefix(PENALTY_PREFIX)]
        if integrator in joint_stepping.SCHEMES:
            return joint_stepping.STAGES[integrator]
        return STAGES.get(parse_integrator(integrator)[0])

    def supports_dynamics(self, scene: DynamicsScene, integrator: str) -> Support:
        named = self.check_integrator(integrator)
        if not named.ok:
            return named
        if scene.contact is not None and len(scene.contact.shapes) != len(scene.bodies):
            return Support.no(f"the scene's contact has {len(scene.contact.shapes)} shapes for {len(scene.bodies)} "
                              f"bodies")
        if (integrator in CONTACT_INTEGRATORS) != (scene.contact is not None):
            if scene.contact is None:
                return Support.no(f"{integrator} is a contact method; the scene has no contact planes")
            return Support.no(f"{integrator} ignores contact; the scene has contact planes (core runs "
                              f"{', '.join(contact_integrators(scene.contact.methods))} on it)")
        if integrator not in point_mass.RULES:
            return named
        rotating = any(np.any(b.angular_velocity_world != 0) for b in scene.bodies)
        if rotating or scene.forces.exerts_torque:
            return Support.no(f"{integrator} is a point-mass rule; the scene's bodies rotate")
        if integrator in point_mass.FORCE_FREE_RULES and scene.forces.names():
            return Support.no(f"{integrator} is the lecture's rule for a point no force acts on; the scene has "
                              + ", ".join(scene.forces.names()))
        return Support.yes()

    def build_dynamics(self, scene: DynamicsScene, integrator: str, dt: float) -> Simulation:
        if integrator in CONTACT_INTEGRATORS:
            return _ContactSimulation(scene, integrator, dt)
        if integrator in point_mass.RULES:
            return _ParticleSimulation(scene, integrator, dt)
        return _RigidBodySimulation(scene, integrator, dt)

    def supports_kinematics(self, chain: Chain) -> Support:
        return Support.yes()

    def build_kinematics(self, chain: Chain) -> KinematicsModel:
        return _Kinematics(chain)

    def ik_solvers(self) -> tuple[str, ...]:
        return METHODS + (NULLSPACE, RESTARTS)

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        """Featherstone's recursive algorithms and the lecture's sum over link Jacobians
        (:mod:`core.articulated`)."""
        return joint_dynamics.METHODS

    def supports_joint_dynamics(self, chain: Chain, method: str) -> Support:
        named = super().supports_joint_dynamics(chain, method)
        problem = (chain.dynamics_problem() or _declined_mass(chain)
                   or joint_dynamics.floating_problem(chain, method))
        return Support.no(problem) if named.ok and problem else named

    def build_joint_dynamics(self, chain: Chain, method: str, gravity_world: np.ndarray | None) -> JointDynamicsModel:
        return joint_dynamics.build(chain, method, gravity_world)

    def joint_motion_integrators(self) -> tuple[str, ...]:
        """The free-body family on the joints, plus implicit damping (:mod:`core.articulated.stepping`)."""
        return joint_stepping.SCHEMES

    def supports_joint_motion(self, scene: JointMotionScene, integrator: str) -> Support:
        named = super().supports_joint_motion(scene, integrator)
        problem = _declined_mass(scene.chain)
        return Support.no(problem) if named.ok and problem else named

    def build_joint_motion(self, scene: JointMotionScene, integrator: str, dt: float) -> JointSimulation:
        return CoreJointMotion(scene, integrator, dt)

    def chain_contact(self, scene: JointMotionScene) -> Support:
        """Soft: the lecture's penalty method at each sphere, through ABA (:mod:`core.articulated.chain_contact`).
        Rigid: the lecture's impulses with time backed up, on a fixed base (:mod:`core.articulated.chain_impulse`)."""
        if scene.contact is not None and scene.contact.rigid and scene.chain.floating_base:
            return Support.no("core's impulses are carried on a fixed base only (a floating base's contact-space "
                              "inertia has the base's six rows); its soft contact (penalty_stiffness) runs there")
        return Support.yes()

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        task = 3 if position_only else 6
        if named.ok and solver == "jacobian_inverse":
            moves = task_basis(chain, task).shape[1]
            if moves != chain.n_joints:
                return Support.no(f"the Jacobian inverse needs a square, invertible Jacobian; the chain moves in "
                                  f"{moves} of the target's {task} directions with {chain.n_joints} joints")
        return named

    def scheme(self, integrator: str, scene) -> str:
        """What the engine's default says (core names its methods after what they are); every in-house IK solver
        keeps the joints within their limits every iteration: ``+limits``; a chain's rigid contact is stepped with
        time backed up to each impact: ``backup+``."""
        kind = super().scheme(integrator, scene)
        if kind and isinstance(scene, JointMotionScene) and scene.contact is not None and scene.contact.rigid:
            return f"backup+{kind}"  # impulses at the backed-up instant: not the plain scheme's discretisation
        return f"{kind}+limits" if kind and isinstance(scene, IKScene) else kind

    def build_ik(self, chain: Chain, solver: str, options: IKTolerances) -> IKModel:
        # The scene's tolerances and cap; the in-house settings keep their defaults unless given.
        return _InHouseIK(chain, solver, options if isinstance(options, IKOptions) else IKOptions(**asdict(options)))


def _declined_mass(chain: Chain) -> str:
    """Why core declines a robot file's mass properties ("" when it takes them): a non-physical inertia tensor on a
    moving link, which engines that accept the file compute with as written (:attr:`Chain.mass_problem`)."""
    return f"core refuses the file's mass properties: {chain.mass_problem}" if chain.mass_problem else ""
