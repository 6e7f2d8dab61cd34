"""The free-body scene: :class:`DynamicsScene`, rigid bodies under forces and contact stepped through time."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.contact import Contact
from simparity.core.model.scenes.suites import SweepPoint


@dataclass(frozen=True)
class DynamicsScene:
    """Free rigid bodies under external forces, simulated from t = 0 to ``duration``.

    Attributes
    ----------
    name, description : str
    reference : str
        Engine whose trajectory the others are measured against (e.g. ``"analytic"``).
    bodies : tuple of RigidBody
        Independent bodies (no body-body interaction).
    forces : Forces
    duration : float
        [s].
    dts : tuple of float
        Time steps [s] to run; each divides ``duration`` into a whole number of steps.
    integrators : tuple of str
        Integrator names to run (every engine runs those it has); empty means all.
    length_unit : str
        The unit the scene file was written in (values here are already in metres).
    source : str
        File the scene came from, or ``"<code>"``: where, not what; not part of the scene's equality or
        content hash.
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    contact : Contact or None
        Planes the bodies collide with; None: no contact (no engine is given any).
    sweep : SweepPoint or None
        For a variant of a file with a ``[sweep]``: its base scene and swept values; None otherwise.
    """

    name: str
    description: str
    reference: str
    bodies: tuple[RigidBody, ...]
    forces: Forces
    duration: float
    dts: tuple[float, ...]
    integrators: tuple[str, ...] = ()
    length_unit: str = "m"
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    contact: Contact | None = None
    sweep: SweepPoint | None = None
    kind: str = field(default="dynamics", init=False)

    def n_steps(self, dt: float) -> int:
        """Number of steps of size ``dt`` that cover ``duration``."""
        return int(round(self.duration / dt))

    def replicated(self, copies: int) -> DynamicsScene:
        """The scene ``copies`` times over, as one scene of ``copies * N`` bodies: copy c's body k is body
        ``c * N + k``, with its forces (per-body arrays tiled, applied forces and timed loads re-indexed) and its contact shape and
        materials. Bodies never interact, so every copy moves as the scene does: an engine batched over bodies
        steps all copies together."""
        n, forces = len(self.bodies), self.forces

        def tiled(values: np.ndarray | None) -> np.ndarray | None:
            return None if values is None else np.tile(values, copies)

        applied = tuple(replace(a, body=a.body + c * n) for c in range(copies) for a in forces.applied)
        timed = tuple(replace(load, body=load.body + c * n) for c in range(copies) for load in forces.timed)
        forces = replace(forces, timed=timed, linear_drag=tiled(forces.linear_drag), quadratic_drag=tiled(forces.quadratic_drag),
                         angular_linear_drag=tiled(forces.angular_linear_drag),
                         angular_quadratic_drag=tiled(forces.angular_quadratic_drag), applied=applied)
        contact = None if self.contact is None else replace(self.contact, shapes=self.contact.shapes * copies,
                                                            materials=self.contact.materials * copies)
        return replace(self, bodies=self.bodies * copies, forces=forces, contact=contact)
