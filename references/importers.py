"""Each engine's own importer on a robot file, as it is (``simparity import``, issue #45): whether MuJoCo, Pinocchio and
PyBullet read a URDF or MJCF file, in one line each, what they compiled or why not.

Nothing is changed in the file (no base chosen, no joint held): the verdict is the importer's on the file a user has.
PyBullet is asked in a forked child: its parsers abort the process on some files (a joint without ``limited`` in an
MJCF file, ``references.pybullet.adapter.FIXED_BASE_JOINT``), which must not end simparity.
"""

from __future__ import annotations

from dataclasses import dataclass

from simparity.references.common.forked import asked_in_child
from simparity.references.common.quiet import captured_output

URDF, MJCF = "urdf", "mjcf"
"""The robot file formats."""


@dataclass(frozen=True)
class ReaderVerdict:
    """One reader on one robot file.

    Attributes
    ----------
    reader : str
        The engine (or ``core``).
    loads : bool
        Whether it reads the file.
    said : str
        One line: what it compiled (joints, mass), or why it does not read the file, in its own words.
    """

    reader: str
    loads: bool
    said: str


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split())[:400] or type(error).__name__


def mujoco_verdict(path: str) -> ReaderVerdict:
    import mujoco

    try:
        with captured_output():
            model = mujoco.MjModel.from_xml_path(path)
    except Exception as error:  # noqa: BLE001 - the importer's refusal, said
        return ReaderVerdict("mujoco", False, f"refuses it: {_one_line(error)}")
    return ReaderVerdict("mujoco", True, f"reads it: {model.njnt} joints, nq {model.nq}, nv {model.nv}, "
                                         f"{float(model.body_mass.sum()):.6g} kg")


def pinocchio_verdict(path: str, kind: str) -> ReaderVerdict:
    import pinocchio as pin

    try:
        with captured_output():
            model = pin.buildModelFromMJCF(path) if kind == MJCF else pin.buildModelFromUrdf(path)
    except Exception as error:  # noqa: BLE001 - the parser's refusal, said
        return ReaderVerdict("pinocchio", False, f"refuses it: {_one_line(error)}")
    mass = sum(model.inertias[i].mass for i in range(model.njoints))
    return ReaderVerdict("pinocchio", True, f"reads it: {model.njoints - 1} joints, nq {model.nq}, nv {model.nv}, "
                                            f"{mass:.6g} kg")


def _pybullet_in_child(path: str, kind: str) -> str:
    """What PyBullet's loader says of ``path`` ("+" and what it made, or why not), run in the forked child."""
    from simparity.references.pybullet.quiet import pybullet

    client = pybullet.connect(pybullet.DIRECT)
    try:
        with captured_output():
            bodies = (pybullet.loadMJCF(path, physicsClientId=client) if kind == MJCF
                      else [pybullet.loadURDF(path, useFixedBase=True, physicsClientId=client)])
        joints = sum(pybullet.getNumJoints(b, physicsClientId=client) for b in bodies)
        mass = sum(pybullet.getDynamicsInfo(b, link, physicsClientId=client)[0] for b in bodies
                   for link in range(-1, pybullet.getNumJoints(b, physicsClientId=client)))
        return f"+reads it: {len(bodies)} bodies, {joints} joints, {mass:.6g} kg"
    except Exception as error:  # noqa: BLE001 - the loader's refusal, said
        return f"-refuses it: {_one_line(error)}"


def pybullet_verdict(path: str, kind: str) -> ReaderVerdict:
    said, signal = asked_in_child(lambda: _pybullet_in_child(path, kind))
    if signal is not None:
        return ReaderVerdict("pybullet", False, f"crashes on it (signal {signal})")
    return ReaderVerdict("pybullet", said.startswith("+"), said[1:] if said[:1] in "+-" else f"refuses it: {said}")


def engine_verdicts(path: str, kind: str) -> tuple[ReaderVerdict, ...]:
    """MuJoCo's, Pinocchio's and PyBullet's verdicts on the robot file ``path`` of format ``kind``."""
    return mujoco_verdict(path), pinocchio_verdict(path, kind), pybullet_verdict(path, kind)
