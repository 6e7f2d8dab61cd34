"""URDF for simparity scenes and chains (given to PyBullet and Pinocchio).

What the URDF says, and why
---------------------------
- A free body is one link whose ``<inertial>`` carries the scene's mass and inertia in
  PRINCIPAL axes (``origin rpy`` = the principal frame, off-diagonal terms zero): PyBullet
  keeps only a diagonal inertia and reports the base pose in this inertial frame, so the
  adapters convert with the same rotation (:func:`references.conventions.principal_axes`).
- No ``<collision>`` or ``<visual>``: nothing collides.
- Chains: ``base`` link, then one link per joint named after the joint, and a fixed joint
  to a link named after the end effector. Revolute joints without limits become
  ``continuous``. Links (the fixed base too) get a placeholder inertial (mass 1, inertia 1e-3; PyBullet would
  otherwise invent mass 1, inertia 1), which does not affect kinematics.
"""

from __future__ import annotations

from simparity.core.engine import Support
from simparity.core.rotations import matrix_to_rpy
from simparity.core.scene import Chain, RigidBody
from simparity.references.conventions import PLACEHOLDER_INERTIA, PLACEHOLDER_MASS, fmt, principal_axes



def _inertial(mass: float, moments, rpy) -> str:
    ixx, iyy, izz = moments
    return (
        f'    <inertial>\n      <origin xyz="0 0 0" rpy="{fmt(rpy)}"/>\n'
        f'      <mass value="{fmt([mass])}"/>\n'
        f'      <inertia ixx="{fmt([ixx])}" ixy="0" ixz="0" iyy="{fmt([iyy])}" iyz="0" izz="{fmt([izz])}"/>\n'
        f"    </inertial>\n"
    )


def body_urdf(body: RigidBody) -> str:
    """URDF text of one free rigid body (a single link, inertia in principal axes)."""
    moments, axes = principal_axes(body.inertia_body)
    return (
        f'<robot name="{body.name}">\n  <link name="{body.name}">\n'
        + _inertial(body.mass, moments, matrix_to_rpy(axes))
        + "  </link>\n</robot>\n"
    )


def urdf_support(chain: Chain) -> Support:
    """Whether the chain can be written as URDF: a prismatic joint needs limits there."""
    for joint in chain.joints:
        if joint.type == "prismatic" and not joint.limited:
            return Support.no(f"URDF cannot express the unlimited prismatic joint '{joint.name}'")
    return Support.yes()


class UrdfChains:
    """Support rules of an engine that receives chains as URDF (a mixin for Engine subclasses)."""

    def supports_kinematics(self, chain: Chain) -> Support:
        return urdf_support(chain) if chain.urdf_path is None else Support.yes()

    def supports_ik(self, chain: Chain, solver: str, position_only: bool) -> Support:
        named = super().supports_ik(chain, solver, position_only)
        return named if not named.ok else self.supports_kinematics(chain)


def chain_urdf(chain: Chain) -> str:
    """URDF text of a fixed-base chain."""
    placeholder = _inertial(PLACEHOLDER_MASS, [PLACEHOLDER_INERTIA] * 3, [0, 0, 0])
    parts = [f'<robot name="{chain.name}">', f'  <link name="base">\n{placeholder}  </link>']
    parent = "base"
    for joint in chain.joints:
        kind = joint.type if joint.limited or joint.type == "prismatic" else "continuous"
        limit = (
            f'\n    <limit lower="{fmt([joint.lower])}" upper="{fmt([joint.upper])}" effort="0" velocity="0"/>'
            if joint.limited
            else ""
        )
        parts += [
            f'  <link name="{joint.name}">\n{placeholder}  </link>',
            f'  <joint name="{joint.name}" type="{kind}">\n'
            f'    <parent link="{parent}"/>\n    <child link="{joint.name}"/>\n'
            f'    <origin xyz="{fmt(joint.origin_xyz)}" rpy="{fmt(matrix_to_rpy(joint.origin_rotation))}"/>\n'
            f'    <axis xyz="{fmt(joint.axis)}"/>{limit}\n  </joint>',
        ]
        parent = joint.name
    ee = chain.end_effector_name
    parts += [
        f'  <link name="{ee}">\n{placeholder}  </link>',
        f'  <joint name="{ee}_fixed" type="fixed">\n    <parent link="{parent}"/>\n    <child link="{ee}"/>\n'
        f'    <origin xyz="{fmt(chain.end_effector_xyz)}" rpy="{fmt(matrix_to_rpy(chain.end_effector_rotation))}"/>\n'
        f"  </joint>",
        "</robot>",
        "",
    ]
    return "\n".join(parts)


def original_urdf(chain: Chain, how: str) -> str:
    """The URDF file a chain was read from, headed by how the engine loads it (for ``simparity export``)."""
    with open(chain.urdf_path, encoding="utf-8") as f:
        text = f.read()
    return f"<!-- {chain.urdf_path}, loaded by {how} -->\n{text}"
