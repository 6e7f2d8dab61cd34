"""Every kind of scene, one module each: :data:`Scene` is any of them."""

from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinematics import KinematicsScene

Scene = DynamicsScene | KinematicsScene | IKScene | JointDynamicsScene | JointMotionScene
"""A scene of any kind: free bodies (:mod:`~core.model.scenes.dynamics`), forward kinematics, inverse
kinematics, joint-space dynamics or joint motion (a chain stepped through time)."""
