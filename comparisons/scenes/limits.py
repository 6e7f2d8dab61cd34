"""What a scene may ask for: the resource limits a run is refused beyond, checked on loading
(before anything runs) with the cost in the message. The physical range of every number is in
:mod:`core.model.ranges`, the names a scene may give in :mod:`core.model.names`; all are listed in
``docs/scenes.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

from simparity.core.model.files import MAX_FILE_BYTES
from simparity.core.urdf import MAX_MOVABLE_JOINTS

POSITION_TOLERANCE_OF_REACH = 0.1
"""An IK position tolerance may be at most this fraction of the chain's reach: beyond it, wild
misses would count as solved."""


@dataclass(frozen=True)
class Limits:
    """Resource limits a scene is checked against before anything runs.

    The defaults admit every built-in scene many times over and refuse what would run for hours
    or exhaust memory; the ones a big honest run may need are raised with a ``simparity run``
    option (named in the refusal's message).

    Attributes
    ----------
    max_steps : int
        Work of one case: body-steps at one time step of a dynamics scene (steps x bodies), or
        solver iterations of an IK scene (random targets x max_iterations, the worst case);
        ``--max-steps``.
    max_samples : int
        Configurations of a kinematics scene, or random targets of an IK scene; ``--max-samples``.
    max_joints : int
        Movable joints on a chain, and movable joints in a URDF file (every engine loads the
        whole file: Pinocchio's data for 256 joints takes 1.2 GB, for 1,000 joints 24 GB);
        ``--max-joints``.
    max_dts : int
        Time steps in a ladder.
    max_bodies : int
        Bodies of a dynamics scene, and applied forces of one body.
    max_iterations : int
        IK iterations per target (``max_iterations``).
    max_file_bytes : int
        Size of a scene or URDF file [bytes].
    """

    max_steps: int = 2_000_000
    max_samples: int = 100_000
    max_joints: int = MAX_MOVABLE_JOINTS
    max_dts: int = 20
    max_bodies: int = 1_000
    max_iterations: int = 100_000
    max_file_bytes: int = MAX_FILE_BYTES


DEFAULT_LIMITS = Limits()

RAISED_BY = {"max_steps": "--max-steps", "max_samples": "--max-samples", "max_joints": "--max-joints"}
"""The ``simparity run`` option that raises each limit that has one."""


def allowed_at_most(limits: Limits, name: str, what: str = "") -> str:
    """The "(allowed: ...)" text of a refusal by limit ``name``: the limit and how to raise it."""
    most = f"at most {getattr(limits, name):,}{' ' + what if what else ''}"
    option = RAISED_BY.get(name)
    return f"{most}; simparity run {option} N raises it" if option else f"{most} (a fixed limit)"
