"""What the dynamics metrics read of a run, reduced over its samples: per-body maxima and minima, the first and last
samples. Each extent is taken of one piece of a run (:meth:`of`) and merged with the next piece's (:meth:`merged`),
so a run is measured as its engine yields it, piece by piece, in memory flat in its number of steps; a whole
trajectory is one piece. Maxima, minima and the first and last samples do not depend on where the pieces are cut:
the extents of a run in pieces are those of the whole, bit for bit.

Energies and momenta are :mod:`comparisons.measure.invariants`' (their own, not the in-house code's).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from simparity.comparisons.measure.invariants import angular_momentum_world, kinetic_energy, potential_energy
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.references.common.conventions import quat_wxyz_angle, quat_wxyz_to_matrix
from simparity.core.model.metric_catalogue import (
    ANGULAR_VELOCITY_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_FINAL, POSITION_ERROR_MAX, VELOCITY_ERROR_MAX,
)


def _masses(scene: DynamicsScene) -> tuple[np.ndarray, np.ndarray]:
    """(mass (B,) [kg], inertia_body (B, 3, 3) [kg m^2])."""
    return np.array([b.mass for b in scene.bodies]), np.stack([b.inertia_body for b in scene.bodies])


def energies(scene: DynamicsScene, traj: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(total E, kinetic, potential) [J] per sample and body, each (T, B); potential -m g.x, zero at
    the world origin (0 without gravity)."""
    mass, inertia = _masses(scene)
    rotation = quat_wxyz_to_matrix(traj.quat_wxyz)
    kinetic = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
    potential = (np.zeros_like(kinetic) if scene.forces.gravity_world is None
                 else potential_energy(mass, scene.forces.gravity_world, traj.position_world))
    return kinetic + potential, kinetic, potential


def angular_momenta(scene: DynamicsScene, traj: Trajectory) -> np.ndarray:
    """(T, B, 3) [kg m^2/s] each body's angular momentum about its COM, world axes."""
    _, inertia = _masses(scene)
    return angular_momentum_world(inertia, traj.angular_velocity_world, quat_wxyz_to_matrix(traj.quat_wxyz))


def _norm_max(values: np.ndarray) -> np.ndarray:
    """(B,) max over samples of |values| ((T, B, k))."""
    return np.linalg.norm(values, axis=-1).max(axis=0)


@dataclass(frozen=True)
class EnergyExtents:
    """A body's energy over a run, each (B,) [J]: its energy, kinetic and potential energy at the first sample, the
    largest |E(t) - E(0)| and E(t) - E(0), the least potential energy."""

    energy0: np.ndarray
    kinetic0: np.ndarray
    potential0: np.ndarray
    change_abs_max: np.ndarray
    change_max: np.ndarray
    potential_min: np.ndarray

    @classmethod
    def of(cls, scene: DynamicsScene, piece: Trajectory, first: EnergyExtents | None) -> EnergyExtents:
        """The extents of ``piece``; ``first``: the run's first piece's (None: this is the first piece)."""
        energy, kinetic, potential = energies(scene, piece)
        energy0, kinetic0, potential0 = ((energy[0], kinetic[0], potential[0]) if first is None
                                         else (first.energy0, first.kinetic0, first.potential0))
        change = energy - energy0
        return cls(energy0, kinetic0, potential0, np.abs(change).max(axis=0), change.max(axis=0),
                   potential.min(axis=0))

    def merged(self, later: EnergyExtents) -> EnergyExtents:
        return replace(self, change_abs_max=np.maximum(self.change_abs_max, later.change_abs_max),
                       change_max=np.maximum(self.change_max, later.change_max),
                       potential_min=np.minimum(self.potential_min, later.potential_min))


@dataclass(frozen=True)
class MomentumExtents:
    """A body's angular momentum L about its COM over a run: L at the first sample (B, 3) [kg m^2/s], the largest
    |L(t) - L(0)| and |L(t)|, each (B,)."""

    momentum0: np.ndarray
    change_max: np.ndarray
    size_max: np.ndarray

    @property
    def size0(self) -> np.ndarray:
        """(B,) |L(0)|."""
        return np.linalg.norm(self.momentum0, axis=-1)

    @classmethod
    def of(cls, scene: DynamicsScene, piece: Trajectory, first: MomentumExtents | None) -> MomentumExtents:
        momentum = angular_momenta(scene, piece)
        momentum0 = momentum[0] if first is None else first.momentum0
        return cls(momentum0, _norm_max(momentum - momentum0), _norm_max(momentum))

    def merged(self, later: MomentumExtents) -> MomentumExtents:
        return replace(self, change_max=np.maximum(self.change_max, later.change_max),
                       size_max=np.maximum(self.size_max, later.size_max))


@dataclass(frozen=True)
class RunExtents:
    """What the drift, validity, divergence and rounding-floor metrics read of an engine's run.

    Attributes
    ----------
    start, end : float
        [s] The first and last sample times.
    finite : bool
        Every value of every sample finite.
    speed_max, spin_max, position_norm_max : (B,) ndarray
        Largest |v| [m/s], |omega| [rad/s] and |x| [m] per body.
    quaternion_deviation_max : float
        Largest | |q| - 1 | over samples and bodies.
    energy : EnergyExtents or None
        Where the scene's forces conserve energy (None once a value is not finite: the run diverged).
    momentum : MomentumExtents or None
        Where they conserve angular momentum (likewise).
    """

    start: float
    end: float
    finite: bool
    speed_max: np.ndarray
    spin_max: np.ndarray
    position_norm_max: np.ndarray
    quaternion_deviation_max: float
    energy: EnergyExtents | None
    momentum: MomentumExtents | None

    @classmethod
    def of(cls, scene: DynamicsScene, piece: Trajectory, first: RunExtents | None = None) -> RunExtents:
        """The extents of ``piece`` of a run of ``scene``; ``first``: the run's extents so far (None: this is the
        first piece), for what is measured from the first sample."""
        forces, finite = scene.forces, piece.is_finite()
        energy = (EnergyExtents.of(scene, piece, None if first is None else first.energy)
                  if forces.conserves_energy and finite else None)
        momentum = (MomentumExtents.of(scene, piece, None if first is None else first.momentum)
                    if forces.conserves_angular_momentum and finite else None)
        norm = np.linalg.norm(np.asarray(piece.quat_wxyz, dtype=float), axis=-1)
        return cls(float(piece.times[0]), float(piece.times[-1]), finite, _norm_max(piece.velocity_world),
                   _norm_max(piece.angular_velocity_world), _norm_max(piece.position_world),
                   float(np.abs(norm - 1.0).max()), energy, momentum)

    def merged(self, later: RunExtents) -> RunExtents:
        """The extents of this run's samples followed by ``later``'s (taken with this as ``first``)."""
        return RunExtents(
            self.start, later.end, self.finite and later.finite, np.maximum(self.speed_max, later.speed_max),
            np.maximum(self.spin_max, later.spin_max), np.maximum(self.position_norm_max, later.position_norm_max),
            max(self.quaternion_deviation_max, later.quaternion_deviation_max),
            None if self.energy is None or later.energy is None else self.energy.merged(later.energy),
            None if self.momentum is None or later.momentum is None else self.momentum.merged(later.momentum))

    @property
    def duration(self) -> float:
        """[s] From the first sample to the last."""
        return self.end - self.start


@dataclass(frozen=True)
class ReferenceExtents:
    """What the saturation scales read of a reference run, each (B,): its largest kinetic energy [J], range of
    motion max_t |x(t) - x(0)| [m], speed [m/s] and angular speed [rad/s]; ``start``, ``end`` [s] its first and
    last sample times, ``position0`` (B, 3) [m] its first position."""

    start: float
    end: float
    position0: np.ndarray
    kinetic_max: np.ndarray
    travel_max: np.ndarray
    speed_max: np.ndarray
    spin_max: np.ndarray

    @classmethod
    def of(cls, scene: DynamicsScene, piece: Trajectory, first: ReferenceExtents | None = None) -> ReferenceExtents:
        mass, inertia = _masses(scene)
        rotation = quat_wxyz_to_matrix(piece.quat_wxyz)
        kinetic = kinetic_energy(mass, inertia, piece.velocity_world, piece.angular_velocity_world, rotation)
        position0 = piece.position_world[0] if first is None else first.position0
        return cls(float(piece.times[0]), float(piece.times[-1]), position0, kinetic.max(axis=0),
                   _norm_max(piece.position_world - position0), _norm_max(piece.velocity_world),
                   _norm_max(piece.angular_velocity_world))

    def merged(self, later: ReferenceExtents) -> ReferenceExtents:
        return ReferenceExtents(self.start, later.end, self.position0,
                                *(np.maximum(getattr(self, name), getattr(later, name))
                                  for name in ("kinetic_max", "travel_max", "speed_max", "spin_max")))


ERROR_MAXIMA = (POSITION_ERROR_MAX, ORIENTATION_ERROR_MAX, VELOCITY_ERROR_MAX, ANGULAR_VELOCITY_ERROR_MAX)
"""The errors that are maxima over the run's samples."""


@dataclass(frozen=True)
class ErrorExtents:
    """A run's errors against its reference per body, each (B,): the maxima over samples of :data:`ERROR_MAXIMA`
    (distances [m], [m/s], [rad/s]; the orientation's geodesic angle [rad]) and the final position error [m]."""

    per_body: dict[str, np.ndarray]

    @classmethod
    def of(cls, piece: Trajectory, ref: Trajectory) -> ErrorExtents:
        """The errors of ``piece`` against the reference's samples at the same times, ``ref``."""
        if piece.position_world.shape != ref.position_world.shape:
            raise ValueError(f"trajectory shape {piece.position_world.shape} != reference {ref.position_world.shape}")
        position = np.linalg.norm(piece.position_world - ref.position_world, axis=-1)
        return cls({
            POSITION_ERROR_MAX: position.max(axis=0),
            POSITION_ERROR_FINAL: position[-1],
            ORIENTATION_ERROR_MAX: quat_wxyz_angle(piece.quat_wxyz, ref.quat_wxyz).max(axis=0),
            VELOCITY_ERROR_MAX: np.linalg.norm(piece.velocity_world - ref.velocity_world, axis=-1).max(axis=0),
            ANGULAR_VELOCITY_ERROR_MAX: np.linalg.norm(
                piece.angular_velocity_world - ref.angular_velocity_world, axis=-1).max(axis=0),
        })

    def merged(self, later: ErrorExtents) -> ErrorExtents:
        out = {metric: np.maximum(self.per_body[metric], later.per_body[metric]) for metric in ERROR_MAXIMA}
        return ErrorExtents(out | {POSITION_ERROR_FINAL: later.per_body[POSITION_ERROR_FINAL]})
