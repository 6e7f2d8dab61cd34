"""MJCF (MuJoCo's model format) for simparity scenes and chains.

What MuJoCo is given, and why
-----------------------------
- ``<compiler angle="radian">``: MJCF angles default to degrees.
- Every free body gets an explicit ``<inertial>`` with ``fullinertia`` from the scene (no
  inertia from geoms); it has no geom, so nothing can collide, and contact is disabled.
- Gravity is set only when the scene has gravity; otherwise it is zero AND disabled.
- With drag (given as ``dof_damping`` by the adapter) ``eulerdamp`` is disabled, so the
  Euler integrator applies damping explicitly like every other engine.
- Defaults already zero in MuJoCo (dof damping, armature, frictionloss, wind, density,
  viscosity) are left at zero; tests pin each one.
- Quaternions in MJCF are (w, x, y, z), the project's order: no conversion.
- Chains: nested bodies, one hinge or slide joint at each body origin (the URDF joint
  frame), a site at the end effector. Bodies get a placeholder inertial (mass 1,
  inertia 1e-3) because MuJoCo rejects massless moving bodies; it does not affect
  kinematics.
"""

from __future__ import annotations

from simparity.core.rotations import matrix_to_quat_wxyz
from simparity.core.scene import Chain, DynamicsScene
from simparity.references.conventions import PLACEHOLDER_INERTIA, PLACEHOLDER_MASS, fmt

INTEGRATORS = {"euler": "Euler", "rk4": "RK4", "implicit": "implicit", "implicitfast": "implicitfast"}
"""simparity integrator name -> MJCF ``option/@integrator``."""



def dynamics_mjcf(scene: DynamicsScene, integrator: str, dt: float) -> str:
    """MJCF text of a dynamics scene for one integrator and time step."""
    gravity = scene.forces.gravity_world
    flags = ['contact="disable"']
    if gravity is None:
        flags.append('gravity="disable"')
    if scene.forces.linear_drag is not None or scene.forces.angular_linear_drag is not None:
        flags.append('eulerdamp="disable"')  # the drag is dof_damping: keep Euler explicit
    gravity_attr = fmt(gravity) if gravity is not None else "0 0 0"
    bodies = []
    for body in scene.bodies:
        i = body.inertia_body
        bodies.append(
            f'    <body name="{body.name}" pos="{fmt(body.position_world)}" quat="{fmt(body.quat_wxyz)}">\n'
            f'      <freejoint name="{body.name}_free"/>\n'
            f'      <inertial pos="0 0 0" mass="{fmt([body.mass])}" '
            f'fullinertia="{fmt([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])}"/>\n'
            f"    </body>"
        )
    return (
        f'<mujoco model="{scene.name}">\n'
        f'  <compiler angle="radian"/>\n'
        f'  <option timestep="{fmt([dt])}" integrator="{INTEGRATORS[integrator]}" gravity="{gravity_attr}">\n'
        f"    <flag {' '.join(flags)}/>\n"
        f"  </option>\n"
        f"  <worldbody>\n" + "\n".join(bodies) + "\n  </worldbody>\n</mujoco>\n"
    )


def chain_mjcf(chain: Chain) -> str:
    """MJCF text of a fixed-base chain (kinematics only)."""
    lines = [f'<mujoco model="{chain.name}">', '  <compiler angle="radian"/>', "  <option>",
             '    <flag contact="disable" gravity="disable"/>', "  </option>", "  <worldbody>"]
    indent = "    "
    for joint in chain.joints:
        kind = "hinge" if joint.type == "revolute" else "slide"
        limit = f' range="{fmt([joint.lower, joint.upper])}"' if joint.limited else ' limited="false"'
        lines += [
            f'{indent}<body name="{joint.name}" pos="{fmt(joint.origin_xyz)}" '
            f'quat="{fmt(matrix_to_quat_wxyz(joint.origin_rotation))}">',
            f'{indent}  <joint name="{joint.name}" type="{kind}" axis="{fmt(joint.axis)}"{limit}/>',
            f'{indent}  <inertial pos="0 0 0" mass="{PLACEHOLDER_MASS}" '
            f'diaginertia="{fmt([PLACEHOLDER_INERTIA] * 3)}"/>',
        ]
        indent += "  "
    lines.append(
        f'{indent}<site name="{chain.end_effector_name}" pos="{fmt(chain.end_effector_xyz)}" '
        f'quat="{fmt(matrix_to_quat_wxyz(chain.end_effector_rotation))}"/>'
    )
    for _ in chain.joints:
        indent = indent[:-2]
        lines.append(f"{indent}</body>")
    lines += ["  </worldbody>", "</mujoco>", ""]
    return "\n".join(lines)
