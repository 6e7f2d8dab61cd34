"""The scene's reference: refused at load when its engine cannot serve the scene."""

from __future__ import annotations

from simparity.comparisons.engines.placeholders import UnavailableEngine
from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.common.integrators import NO_INTEGRATOR, motion_reference_integrator
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.core.model.engine import Support
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene


def check_reference(top: TableReader, scene, engines: EngineSet) -> None:
    """A reference that cannot do the scene (as its engine's ``supports_*`` says) is an error now, not a run of n/a
    rows (core too, on a chain in motion: a floating base's rigid contact it does not step); so is core as the
    reference of a contact scene that does not run its exact method, backup."""
    contact = getattr(scene, "contact", None)
    if scene.reference == "core":
        if isinstance(scene, DynamicsScene) and contact is not None and "backup" not in contact.methods:
            raise top.fail("scene.reference", "core is the reference, but the scene's contact methods leave out "
                           "backup, its exact one", 'contact.methods with "backup", or another reference')
        if not isinstance(scene, JointMotionScene):
            return
    engine = engines.reference(scene.reference)
    if isinstance(engine, UnavailableEngine):  # its library is missing here: the run's rows say so
        return
    if isinstance(scene, DynamicsScene):
        integrators = engine.integrators()
        support = engine.supports_dynamics(scene, integrators[0]) if integrators else Support.no("it offers no integrator")
    elif isinstance(scene, JointMotionScene):
        integrator = motion_reference_integrator(scene, engine)
        support = (engine.supports_joint_motion(scene, integrator) if integrator != NO_INTEGRATOR
                   else Support.no("it steps no chain through time"))
    elif isinstance(scene, JointDynamicsScene):
        methods = engine.joint_dynamics_methods()
        support = (engine.supports_joint_dynamics(scene.chain, methods[0]) if methods
                   else Support.no("it computes no joint-space dynamics"))
    else:
        support = engine.supports_kinematics(scene.chain)
    if not support.ok:
        allowed = ("analytic for a pendulum striking the plane with one sphere, core on a fixed base, or an engine that "
                   "steps it (pinocchio, pybullet: restitution 0)" if isinstance(
                       scene, JointMotionScene) and contact is not None and contact.rigid
                   else "core or mujoco: a scene with a chain's soft contact runs against no reference, but names an "
                   "engine that can do it" if isinstance(scene, JointMotionScene) and contact is not None
                   else "a reference that can: core (its backup method), mujoco or pybullet for contact" if contact is not None
                   else "a reference that computes joint-space dynamics: pinocchio, mujoco, core, or analytic for a "
                        "planar chain of 1 or 2 joints" if isinstance(scene, JointDynamicsScene)
                   else "a reference that steps chains: pinocchio (its DOP853 solve), or analytic for a pendulum or a "
                        "single damped joint" if isinstance(scene, JointMotionScene)
                   else "a reference that can: core, mujoco, pybullet, pinocchio, or tight for dynamics without a "
                        "closed form")
        raise top.fail("scene.reference", f"{scene.reference} cannot serve this scene: {support.reason}", allowed)
