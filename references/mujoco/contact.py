"""A chain's contact spheres and plane in MuJoCo (issue #46): geoms added to the model, forces read back.

What MuJoCo is given (pinned by ``tests/references/test_chain_contact_engines.py``)
---------------------------------------------------------------------------------
- One plane geom on the world body (its normal the plane's, through the point -d N) and a sphere geom per contact
  sphere on the body of its frame: a chain joint's child body (the body the joint moves: its frame is the URDF link's),
  the end effector's body, or the base link's body. Spheres touch the plane only (sphere contype 0, conaffinity 1;
  plane contype 1, conaffinity 0), ``condim`` 1 on a frictionless plane (it pushes along its normal only), ``condim``
  3 with the scene's friction (sliding friction mu on both geoms, so that MuJoCo's mix, the larger, is mu; torsional
  and rolling 0, unused by condim 3) where it has one,
  ``margin`` = ``gap`` = 0 (no force before the sphere touches), MuJoCo's default soft-contact parameters
  (:data:`SOLREF`, :data:`SOLIMP`: reported in each row), elliptic cones (moot with condim 1). Geoms add no mass: the
  URDF importer's ``inertiafromgeom`` is false.
- Constraints on, but only contact: joint limits, equality constraints and frictionloss disabled
  (``mjDSBL_LIMIT``, ``mjDSBL_EQUALITY``, ``mjDSBL_FRICTIONLOSS``), as without contact.
- Forces: at a state, with ``qfrc_applied`` as the run had it at that time (the soft contact's force balances the
  applied forces too: read without them, a pressing arm's force missed its torque's whole share), ``mj_forward`` then
  ``mj_contactForce`` per contact (the contact frame's first row is the normal,
  from geom 1 to geom 2; the force acts on geom 2 along it), turned to world axes and summed per sphere.
- Centres: the sphere geoms' ``geom_xpos`` after ``mj_kinematics``.
"""

from __future__ import annotations

import mujoco
import numpy as np

from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, frame_index

SOLREF = (0.02, 1.0)
"""MuJoCo's default solref (time constant [s], damping ratio) of a contact, kept."""
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
"""MuJoCo's default solimp (d0, d_width, width [m], midpoint, power), kept."""
SPHERE_PREFIX = "simparity_contact_sphere_"


def detail(contact: ChainContact) -> str:
    """What a row says of MuJoCo's contact with ``contact``'s plane."""
    friction = (f"condim 3, friction {contact.friction:g}, impratio 1" if contact.friction > 0
                else "condim 1, frictionless")
    return (f"contact: a plane geom and a sphere geom per contact sphere ({friction}; margin 0; solref {SOLREF}, "
            f"solimp {SOLIMP}: MuJoCo's defaults; elliptic cone), joint limits, equality and frictionloss disabled; "
            "forces by mj_contactForce after mj_forward at each sampled state")


def _plane_quat_wxyz(normal: np.ndarray) -> np.ndarray:
    """The rotation taking z to the unit ``normal`` (w, x, y, z): about z x N by the angle between them."""
    axis = np.cross([0.0, 0.0, 1.0], normal)
    sine, cosine = float(np.linalg.norm(axis)), float(normal[2])
    if sine == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0]) if cosine > 0 else np.array([0.0, 1.0, 0.0, 0.0])
    half = 0.5 * np.arctan2(sine, cosine)
    return np.concatenate([[np.cos(half)], np.sin(half) * axis / sine])


def add_contact(spec: mujoco.MjSpec, chain: Chain, contact: ChainContact) -> None:
    """Add the plane and the spheres to ``spec`` (see the module docstring)."""
    names = tuple(j.name for j in chain.joints)
    plane = spec.worldbody.add_geom()
    plane.type, plane.size = mujoco.mjtGeom.mjGEOM_PLANE, [0.0, 0.0, 1.0]
    plane.pos = -contact.plane.offset * np.asarray(contact.plane.normal_world)
    plane.quat = _plane_quat_wxyz(np.asarray(contact.plane.normal_world))
    condim = 3 if contact.friction > 0 else 1
    friction = [contact.friction, 0.0, 0.0]
    plane.contype, plane.conaffinity, plane.condim = 1, 0, condim
    for k, sphere in enumerate(contact.spheres):
        i = frame_index(sphere.frame, names, chain.end_effector_name, chain.base_link)
        body = (spec.worldbody.first_body() if i < 0 else spec.body(chain.end_effector_name) if i == len(names)
                else spec.joint(names[i]).parent)
        geom = body.add_geom()
        geom.name, geom.type = f"{SPHERE_PREFIX}{k}", mujoco.mjtGeom.mjGEOM_SPHERE
        geom.size, geom.pos = [sphere.radius, 0.0, 0.0], np.asarray(sphere.centre_xyz)
        geom.contype, geom.conaffinity, geom.condim = 0, 1, condim
        if condim > 1:
            geom.friction = friction
        geom.margin = geom.gap = 0.0
        geom.solref, geom.solimp = SOLREF, SOLIMP
    plane.solref, plane.solimp, plane.margin, plane.gap = SOLREF, SOLIMP, 0.0, 0.0
    if condim > 1:
        plane.friction = friction
    spec.option.disableflags = (mujoco.mjtDisableBit.mjDSBL_LIMIT | mujoco.mjtDisableBit.mjDSBL_EQUALITY
                                | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC


class ContactReader:
    """Sphere centres and contact forces of a compiled model with :func:`add_contact`'s geoms."""

    def __init__(self, model: mujoco.MjModel, contact: ChainContact) -> None:
        self._model, self._data = model, mujoco.MjData(model)
        self._geoms = np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{SPHERE_PREFIX}{k}")
                                for k in range(len(contact.spheres))])
        self._sphere_of = {int(g): k for k, g in enumerate(self._geoms)}

    def _set(self, qpos_at: np.ndarray, dof: np.ndarray, q_row: np.ndarray, qvel_row: np.ndarray | None) -> None:
        d = self._data
        d.qpos[:], d.qvel[:] = self._model.qpos0, 0.0
        d.qpos[qpos_at] = q_row
        if qvel_row is not None:
            d.qvel[dof] = qvel_row

    def centres(self, qpos_at: np.ndarray, dof: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(B, S, 3) the sphere geoms' centres at the configurations q (B, nq) (qpos at ``qpos_at``)."""
        out = np.empty((len(q), len(self._geoms), 3))
        for b, row in enumerate(q):
            self._set(qpos_at, dof, row, None)
            mujoco.mj_kinematics(self._model, self._data)
            out[b] = self._data.geom_xpos[self._geoms]
        return out

    def forces(self, qpos_at: np.ndarray, dof: np.ndarray, q: np.ndarray, qvel: np.ndarray,
               applied: np.ndarray) -> np.ndarray:
        """(B, S, 3) the plane's force on each sphere in world axes at the states (q (B, nq), MuJoCo's qvel (B, nv))
        under ``qfrc_applied`` (B, model nv): MuJoCo's soft contact solves for the force with the applied forces in."""
        m, d = self._model, self._data
        out = np.zeros((len(q), len(self._geoms), 3))
        wrench = np.empty(6)
        for b, (row, rates) in enumerate(zip(q, qvel)):
            self._set(qpos_at, dof, row, rates)
            d.qfrc_applied[:] = applied[b]
            mujoco.mj_forward(m, d)
            for i in range(d.ncon):
                con = d.contact[i]
                mujoco.mj_contactForce(m, d, i, wrench)
                force = con.frame.reshape(3, 3).T @ wrench[:3]  # on geom 2, world axes
                if int(con.geom2) in self._sphere_of:
                    out[b, self._sphere_of[int(con.geom2)]] += force
                elif int(con.geom1) in self._sphere_of:
                    out[b, self._sphere_of[int(con.geom1)]] -= force
        return out
