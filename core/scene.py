"""``simparity.core.scene``: the path plugins import (docs/plugins.md), an alias of the scene types in
:mod:`simparity.core.model.scenes` (one module per kind of scene and per part)."""

from simparity.core.model.scenes.bodies import AppliedForce, Forces, PointMasses, RigidBody  # noqa: F401
from simparity.core.model.scenes.chain import Chain, DHTable, Joint, LinkInertia, sample_configurations  # noqa: F401
from simparity.core.model.scenes.contact import (  # noqa: F401
    CONTACT_METHODS, PENALTY_PREFIX, SHAPES, ZERO_NORMAL, Contact, Material, Plane, Shape)
from simparity.core.model.scenes.dynamics import DynamicsScene  # noqa: F401
from simparity.core.model.scenes.ik import HARD_TARGETS, IKScene  # noqa: F401
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene  # noqa: F401
from simparity.core.model.scenes.joint_motion import JointMotionScene  # noqa: F401
from simparity.core.model.scenes.kinematics import KinematicsScene  # noqa: F401
from simparity.core.model.scenes.kinds import Scene  # noqa: F401
from simparity.core.model.scenes.suites import SUITES, SweepPoint  # noqa: F401
