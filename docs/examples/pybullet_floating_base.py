"""PyBullet's floating-base inverse dynamics against Pinocchio's, standalone (docs/floating-bases.md).

Solo-12's front-left leg with a floating base (the other legs fixed at 0, no geometry), one state with the base turned:
Pinocchio's free flyer (its LOCAL velocity: zero here) and PyBullet's calculateInverseDynamics (flags=0, 7 + n
positions with quat_xyzw, 6 + n velocities) under the same gravity. Run: python docs/examples/pybullet_floating_base.py
(needs pin, pybullet and example-robot-data; prints both bias forces, about 5 seconds). Do not pass flags=1: it
corrupted the heap of the process that measured it (malloc(): invalid size)."""

import os
import tempfile

import numpy as np
import pinocchio as pin
import pybullet
from scipy.spatial.transform import Rotation

from simparity.core.urdf import chain_from_urdf
from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
from simparity.references.common.dynamics_urdf import dynamics_urdf
from importlib import metadata

robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
chain = chain_from_urdf(str(robots / "solo_description/robots/solo12.urdf"), "base_link", "FL_FOOT", dynamics=True,
                        floating_base=True)
text = dynamics_urdf(chain)
rng = np.random.default_rng(1)
quat_wxyz = Rotation.random(random_state=1).as_quat(scalar_first=True)
joints = rng.uniform(-1, 1, 3)
position = rng.uniform(-1, 1, 3)
gravity = np.array([0.0, 0.0, -9.81])

model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
model.gravity = pin.Motion(gravity, np.zeros(3))
q = pin.neutral(model)
q[:3], q[3:7] = position, np.r_[quat_wxyz[1:], quat_wxyz[0]]
ids = [model.getJointId(j.name) for j in chain.joints]
q[[model.joints[i].idx_q for i in ids]] = joints
h_pinocchio = pin.rnea(model, model.createData(), q, np.zeros(model.nv), np.zeros(model.nv))
print("Pinocchio joint forces at rest:", h_pinocchio[[model.joints[i].idx_v for i in ids]])

with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as handle:
    handle.write(text)
client = pybullet.connect(pybullet.DIRECT)
body = pybullet.loadURDF(handle.name, useFixedBase=False, flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                         physicsClientId=client)
pybullet.setGravity(*gravity, physicsClientId=client)
positions = list(position) + list(quat_wxyz[1:]) + [quat_wxyz[0]] + list(joints)
h_pybullet = pybullet.calculateInverseDynamics(body, positions, [0.0] * 9, [0.0] * 9, flags=0,
                                               physicsClientId=client)
print("PyBullet  joint forces at rest:", np.array(h_pybullet[6:]))
os.unlink(handle.name)
