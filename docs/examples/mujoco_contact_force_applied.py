"""MuJoCo's soft-contact force depends on the applied forces: read it at a state without them and it is wrong.

A rod on a hinge presses its tip sphere onto a plane under gravity and a constant torque (qfrc_applied) and settles.
At rest the contact force has the closed form f = m g / 2 + tau / (l cos angle) (moments about the hinge). MuJoCo's
contact force at a state comes from its constraint solve, which includes every applied force: read after mj_forward
with qfrc_applied as the simulation had it, it is the closed form; read after mj_forward on data whose qfrc_applied is
0 (a fresh MjData, or a state restored with mj_setState of the physics only), it misses the torque's share. simparity's
MuJoCo adapter made exactly this mistake before issue #46's rest_equilibrium_error caught it (docs/floating-bases.md,
"On the ground"). Run: python docs/examples/mujoco_contact_force_applied.py (needs mujoco; under a second)."""

import mujoco
import numpy as np

MASS, LENGTH, TIP, TORQUE, G = 1.0, 0.4, 0.02, 0.5, 9.81
XML = f"""
<mujoco>
  <option gravity="0 0 -{G}" timestep="0.001"/>
  <worldbody>
    <geom type="plane" size="0 0 1" pos="0 0 -{TIP}" condim="1" contype="1" conaffinity="0"/>
    <body>
      <joint name="hinge" type="hinge" axis="0 1 0" damping="0.5"/>
      <inertial pos="{LENGTH / 2} 0 0" mass="{MASS}" diaginertia="1e-4 1e-2 1e-2"/>
      <geom type="sphere" size="{TIP}" pos="{LENGTH} 0 0" condim="1" contype="0" conaffinity="1" mass="0"/>
    </body>
  </worldbody>
</mujoco>"""

model = mujoco.MjModel.from_xml_string(XML)
data = mujoco.MjData(model)
data.qfrc_applied[0] = TORQUE  # presses the tip down (the hinge's axis is +y: a positive angle lowers the tip)
for _ in range(3000):  # 3 s: the rod settles on the plane
    mujoco.mj_step(model, data)


def normal_force(d: mujoco.MjData) -> float:
    """The plane's normal force on the sphere after mj_forward: the contact frame's normal runs from geom 1 (the plane)
    to geom 2 (the sphere), and mj_contactForce gives the force on geom 2 in that frame."""
    mujoco.mj_forward(model, d)
    wrench = np.zeros(6)
    mujoco.mj_contactForce(model, d, 0, wrench)
    return float(wrench[0])


angle = float(data.qpos[0])  # the rod rests nearly flat, the sphere sunk by MuJoCo's soft contact
closed_form = MASS * G / 2 + TORQUE / (LENGTH * np.cos(angle))  # moments about the hinge: f l cos = m g l/2 cos + tau
print(f"at rest: angle {angle:.3e} rad, speed {data.qvel[0]:.1e} rad/s")
print(f"closed form m g / 2 + tau / (l cos)   = {closed_form:.6f} N")
print(f"MuJoCo, qfrc_applied as simulated     = {normal_force(data):.6f} N")
fresh = mujoco.MjData(model)
fresh.qpos[:], fresh.qvel[:] = data.qpos, data.qvel
print(f"MuJoCo, the same state, qfrc_applied 0 = {normal_force(fresh):.6f} N (misses tau / l = {TORQUE / LENGTH:.3f} N)")
