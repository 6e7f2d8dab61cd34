"""Contact metrics: impacts, restitution, penetration, tunnelling, energy gained, rest and sliding.

Every engine's trajectory is read the same way, from its samples and the scene's geometry, so the
truth (sampled at the same times) and each engine are measured by one protocol:

- A body's **support distance** from a plane is the signed distance of its lowest point (a vertex
  of its shape; the centre minus the radius for a sphere). Geometry here is written from the
  scene's data (rotations are SciPy's), never core's code.
- An **impact episode** is a run of steps in which the body touches the plane (support distance
  <= 0 at a sample) or its normal velocity jumps up (v_n rises by more than free flight allows:
  an impulse inside the step). The episode's impact velocity, time and rebound are extrapolated
  from the free samples on either side along the ballistic normal motion (acceleration g.N), which
  is exact for a free flight and independent of where the samples fall: v_in = -sqrt(v_n^2 + 2 |g_n| d)
  before, v_out = sqrt(v_n^2 + 2 |g_n| d) after, apex = d + v_n^2 / (2 |g_n|).
- Measured **restitution** of an impact is v_out / |v_in| (the normal velocity of the COM; for a
  body that does not turn, the contact point's).

Definitions with their reasons are in docs/metrics.md ("Contact").
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from simparity.comparisons.invariants import kinetic_energy, potential_energy
from simparity.comparisons.rows import Measured
from simparity.core.scene import DynamicsScene
from simparity.core.trajectory import Trajectory
from simparity.references.conventions import quat_wxyz_to_matrix

CONTACT_METRICS = {
    "impact_time_error": "s",
    "rebound_velocity_error": "m/s",
    "apex_height_error": "m",
    "impacts_missed": "1",
    "restitution_measured": "1",
    "restitution_error": "1",
    "energy_loss_error": "1",
    "penetration_max": "m",
    "tunnelled": "1",
    "energy_gain_max": "1",
    "rest_time_error": "s",
    "stopping_distance": "m",
    "stopping_distance_error": "m",
}
"""Per-case contact metrics (units); see the module docstring and docs/metrics.md."""

IMPACTS_COMPARED = 10
"""Impacts compared with the reference's: the issue's first ten bounces; later ones are ever
shorter (k^n) and fall below any sampling."""

TOUCH_GAP = 1e-9
"""[m] A sample whose support distance is at most this touches the plane: a body resting on it
(distance 0 up to rounding of positions of order 1-100 m, ~1e-14) or pressed into it. Free flight
samples of a falling body are farther: the closest a ballistic sample can come to an impact
without touching is the body's speed times the sub-step left, which is this small only for
impacts timed to 1e-9 s."""

JUMP_RTOL = 1e-9
"""An upward jump of the normal velocity within a step larger than this x (|v_n| + |g_n| dt) is
an impulse, not rounding: free flight changes v_n by exactly g_n dt up to rounding (~1e-16
relative), and the drags a contact scene may add change it by far less than an impact's 2 k |v|."""

ENERGY_GAIN_ROUNDING = 1e-9
"""Relative energy changes below this are rounding (energies of order 1-1e4 J summed over up to
1e6 steps), not a gain."""


@dataclass(frozen=True)
class Impacts:
    """The impact episodes of one body against one plane, in time order.

    Attributes
    ----------
    time : (N,) ndarray
        Impact instant [s], backed up from the free sample before the episode.
    velocity_in : (N,) ndarray
        Normal velocity at the impact [m/s] (negative: toward the plane).
    velocity_out : (N,) ndarray
        Normal velocity leaving the plane [m/s]; 0 when the body stays on it (rest, slide), NaN when
        the run ends inside the episode.
    apex : (N,) ndarray
        Support height of the apex after the impact [m]; 0 when the body stays, NaN without gravity
        toward the plane or when the run ends inside the episode.
    turning : (N,) ndarray of bool
        The body turns around the impact (its points move by rotation faster than the scene's
        rest speed at the sample before or after): the COM's normal velocity is then not the
        contact point's, and the impact gives no restitution.
    """

    time: np.ndarray
    velocity_in: np.ndarray
    velocity_out: np.ndarray
    apex: np.ndarray
    turning: np.ndarray

    @property
    def measured(self) -> np.ndarray:
        """(N,) bool: the impact's outcome (a rebound, or staying: 0) is known."""
        return np.isfinite(self.velocity_out)


def shape_points_body(shape) -> np.ndarray:
    """(V, 3) the points of a shape that can be lowest or highest against a plane, relative to the COM in body
    axes [m], written here from the shape's data (not core's): a box's 8 corners, the given points, the
    centre of a point or a sphere (whose radius is added apart)."""
    if shape.kind == "box":
        signs = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))
        return shape.center_body + signs * shape.half_extents_body
    if shape.kind == "points":
        return np.asarray(shape.points_body, dtype=float)
    return np.zeros((1, 3))


def extreme_distances(scene: DynamicsScene, traj: Trajectory, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest): the signed distance [m] of each body's lowest and highest point from each plane at
    every sample, each (T, B, P); highest < 0 means wholly beyond the plane. ``rotation`` (T, B, 3, 3): the
    samples' body-to-world rotations."""
    contact = scene.contact
    lowest, highest = (np.empty(traj.position_world.shape[:2] + (len(contact.planes),)) for _ in range(2))
    for b, shape in enumerate(contact.shapes):
        vertices = traj.position_world[:, b, None, :] + np.einsum("tij,vj->tvi", rotation[:, b],
                                                                  shape_points_body(shape))
        for p, plane in enumerate(contact.planes):
            distance = vertices @ plane.normal_world + plane.offset
            lowest[:, b, p] = distance.min(axis=1) - shape.radius
            highest[:, b, p] = distance.max(axis=1) + shape.radius
    return lowest, highest


def _normal_gravity(scene: DynamicsScene, p: int) -> float:
    """g . N [m/s^2] of plane p (negative: gravity pushes toward the plane)."""
    gravity = scene.forces.gravity_world
    return 0.0 if gravity is None else float(gravity @ scene.contact.planes[p].normal_world)


def _episodes(touch: np.ndarray, jump: np.ndarray) -> list[tuple[int, int]]:
    """Runs of event steps [(first step, last step)]: step i (samples i -> i + 1) is an event step when
    either sample touches or the normal velocity jumps up within it."""
    event = touch[:-1] | touch[1:] | jump
    starts = np.flatnonzero(event & ~np.concatenate([[False], event[:-1]]))
    ends = np.flatnonzero(event & ~np.concatenate([event[1:], [False]]))
    return list(zip(starts.tolist(), ends.tolist()))


def episode_samples(times: np.ndarray, distance: np.ndarray, normal_velocity: np.ndarray, normal_gravity: float,
                    nearest: np.ndarray | None = None) -> list[tuple[int, int]]:
    """(sample before, sample after) of every contact episode of one body against one plane (see
    :func:`impacts` for the arguments): the samples either side of a run of steps that touch the plane or
    in which the normal velocity jumps up."""
    dt = float(times[1] - times[0]) if len(times) > 1 else 0.0
    touch = distance <= TOUCH_GAP
    rise = np.diff(normal_velocity) - normal_gravity * dt
    jump = rise > JUMP_RTOL * (np.abs(normal_velocity[:-1]) + abs(normal_gravity) * dt)
    if nearest is not None:
        jump &= nearest
    return [(first, last + 1) for first, last in _episodes(touch, jump)]


def impacts(times: np.ndarray, distance: np.ndarray, normal_velocity: np.ndarray, normal_gravity: float,
            min_speed: float = 0.0, spin_speed: np.ndarray | None = None,
            episodes: list[tuple[int, int]] | None = None) -> Impacts:
    """The impact episodes of one body against one plane from its samples; episodes whose impact speed is
    below ``min_speed`` [m/s] are settling, not impacts, and are left out. ``spin_speed`` (T,) [m/s]: how
    fast the body's points move by its rotation (|omega| x its extent); an impact where it exceeds
    ``min_speed`` is marked turning. ``episodes``: :func:`episode_samples` of these samples when already
    found (None: found here, every step counted).

    Parameters
    ----------
    times : (T,) ndarray
        [s], evenly spaced.
    distance : (T,) ndarray
        Support distance [m].
    normal_velocity : (T,) ndarray
        COM velocity along the plane's normal [m/s].
    normal_gravity : float
        g . N [m/s^2].
    """
    g = -normal_gravity  # > 0 when gravity pulls toward the plane
    touch = distance <= TOUCH_GAP
    out: list[tuple[float, float, float, float, bool]] = []
    if episodes is None:
        episodes = episode_samples(times, distance, normal_velocity, normal_gravity)
    for before, after in episodes:
        if touch[before] or normal_velocity[before] ** 2 + 2 * g * distance[before] < 0:
            continue  # starts in contact (a body placed on the plane): not an impact
        d, v = distance[before], normal_velocity[before]
        speed_in = math.sqrt(max(v * v + 2 * g * d, 0.0))
        backed = (v + speed_in) / g if g > 0 else (d / -v if v < 0 else math.nan)
        v_out = apex = math.nan  # the run ends inside the episode: the rebound is unknown
        if not touch[after] and normal_velocity[after] > 0:
            d1, v1 = distance[after], normal_velocity[after]
            v_out = math.sqrt(max(v1 * v1 + 2 * g * d1, 0.0))
            apex = d1 + v1 * v1 / (2 * g) if g > 0 else math.nan
        elif after < len(times) - 1 or touch[after]:
            v_out = apex = 0.0  # the body stayed on the plane: a rebound of 0, measured
        if speed_in >= min_speed:
            spin = 0.0 if spin_speed is None else max(spin_speed[before], spin_speed[after])
            out.append((times[before] + backed, -speed_in, v_out, apex, spin > min_speed))
    columns = np.array(out, dtype=float).reshape(-1, 5).T
    return Impacts(*columns[:4], columns[4].astype(bool))


@dataclass(frozen=True)
class ContactReading:
    """What a trajectory shows about contact, per body and plane."""

    impacts: dict[tuple[int, int], Impacts]
    episodes: dict[tuple[int, int], list[tuple[int, int]]]  # (sample before, sample after) of every contact episode
    distance: np.ndarray  # (T, B, P) support distances [m]
    highest: np.ndarray  # (T, B, P) distances of the highest points [m]; negative: wholly beyond the plane
    rest_time: np.ndarray  # (B,) first sample time after which the body stays at rest [s]; NaN if never
    energy: np.ndarray  # (T, B) kinetic + potential [J]
    kinetic: np.ndarray  # (T, B) [J]


def _extents(scene: DynamicsScene) -> np.ndarray:
    """(B,) the largest distance of a body's shape from its COM [m]."""
    return np.array([np.linalg.norm(shape_points_body(s), axis=1).max() + s.radius for s in scene.contact.shapes])


def _rest_times(scene: DynamicsScene, traj: Trajectory) -> np.ndarray:
    """(B,) the first sample time from which every later sample's speed (COM speed plus |omega| times
    the body's extent) is within the scene's rest speed; NaN where the body is still moving at the end."""
    speed = (np.linalg.norm(traj.velocity_world, axis=-1)
             + np.linalg.norm(traj.angular_velocity_world, axis=-1) * _extents(scene))
    moving = speed > scene.contact.rest_speed
    out = np.full(len(scene.bodies), math.nan)
    for b in range(len(scene.bodies)):
        if not moving[-1, b]:
            last_moving = np.flatnonzero(moving[:, b])
            out[b] = traj.times[last_moving[-1] + 1] if last_moving.size else traj.times[0]
    return out


def _settling_speed(rest_speed: float, restitution: float) -> float:
    """[m/s] The impact speed below which the scene's rule ends an impact at rest (its rebound k v would be
    slower than the rest speed): contacts that slow are a body settling or resting (a soft contact's
    jitter), not impacts. With k = 0 every impact is plastic, and the rest speed itself is the floor."""
    return rest_speed / restitution if restitution > 0 else rest_speed


def read_contact(scene: DynamicsScene, traj: Trajectory) -> ContactReading:
    """Everything the contact metrics need from one trajectory."""
    rotation = quat_wxyz_to_matrix(traj.quat_wxyz)  # SciPy's
    distance, highest = extreme_distances(scene, traj, rotation)
    mass = np.array([b.mass for b in scene.bodies])
    inertia = np.stack([b.inertia_body for b in scene.bodies])
    kinetic = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
    potential = (np.zeros_like(kinetic) if scene.forces.gravity_world is None
                 else potential_energy(mass, scene.forces.gravity_world, traj.position_world))
    found, episodes = {}, {}
    restitution = scene.contact.restitution
    spin = np.linalg.norm(traj.angular_velocity_world, axis=-1) * _extents(scene)
    closest = np.minimum(distance[:-1], distance[1:]).argmin(axis=-1)  # (T - 1, B): each step's nearest plane
    for b in range(len(scene.bodies)):
        for p, plane in enumerate(scene.contact.planes):
            normal_velocity, g_n = traj.velocity_world[:, b] @ plane.normal_world, _normal_gravity(scene, p)
            episodes[b, p] = episode_samples(traj.times, distance[:, b, p], normal_velocity, g_n, closest[:, b] == p)
            found[b, p] = impacts(traj.times, distance[:, b, p], normal_velocity, g_n,
                                  _settling_speed(scene.contact.rest_speed, restitution[b, p]), spin[:, b],
                                  episodes[b, p])
    return ContactReading(found, episodes, distance, highest, _rest_times(scene, traj), kinetic + potential, kinetic)


def _own_metrics(scene: DynamicsScene, reading: ContactReading, traj: Trajectory) -> dict[str, Measured]:
    """Metrics that need no reference: restitution against the requested one, penetration, tunnelling,
    energy gained, stopping distance."""
    out: dict[str, Measured] = {}
    worst, measured, requested = -1.0, math.nan, math.nan
    turning = False
    for (b, p), found in reading.impacts.items():
        known = found.measured & ~found.turning
        turning |= bool(found.turning.any())
        if known.any():
            k = float(scene.contact.restitution[b, p])
            i = int(np.argmax(known))  # the body's first impact with a known outcome
            e = float(found.velocity_out[i] / -found.velocity_in[i])
            if abs(e - k) > worst:
                worst, measured, requested = abs(e - k), e, k
    if worst < 0:
        none = ("the body turns at its impacts: the COM's rebound is not the contact point's" if turning else
                "no impact: nothing to measure restitution on")
        for metric in ("restitution_measured", "restitution_error"):
            out[metric] = Measured(math.nan, "1", unmeasurable=none)
    else:
        note = f"first impact: measured {measured:.6g}, requested {requested:.6g}"
        out["restitution_measured"] = Measured(measured, "1", note=note)
        out["restitution_error"] = Measured(worst, "1", note=note)
    out["penetration_max"] = Measured(float(max(0.0, -reading.distance.min())), "m")
    out["tunnelled"] = Measured(float(_tunnelled(scene, reading, traj).sum()), "1",
                                note="bodies wholly beyond a plane at the end and still moving away from it")
    out["energy_gain_max"] = _energy_gain(reading)
    out["stopping_distance"] = _stopping_distance(reading, traj)
    return out


def _tunnelled(scene: DynamicsScene, reading: ContactReading, traj: Trajectory) -> np.ndarray:
    """(B,) bool: the body went through a plane and is still going: at the last sample its highest point is
    beyond the plane, as deep as it has ever been, and it moves farther in faster than the scene's rest
    speed. (A plane is a half-space, so a body deep inside one may still be pushed back: the depth alone is
    ``penetration_max``. A body resting in a soft or penalty contact sits slightly inside, and a soft
    contact's jitter moves it in and out, but never deeper than its impact took it.)"""
    normals = np.stack([p.normal_world for p in scene.contact.planes])  # (P, 3)
    inward = traj.velocity_world[-1] @ normals.T < -scene.contact.rest_speed  # (B, P)
    deepest = reading.highest[-1] <= reading.highest.min(axis=0)
    return ((reading.highest[-1] < 0) & deepest & inward).any(axis=1)


def contact_energy_gains(reading: ContactReading) -> np.ndarray:
    """(B,) the largest rise of kinetic + potential energy across a contact episode of each body (from the
    sample before it to the sample after it), relative to the body's largest kinetic energy of the run; 0
    where it has none. Contact and friction only take energy away; a free flight's own drift between
    episodes is the integrator's, not the contact's, and is not counted."""
    scale = reading.kinetic.max(axis=0)
    gains = np.zeros(reading.energy.shape[1])
    for (b, _), bounds in reading.episodes.items():
        if bounds and scale[b] > 0:
            rise = max(reading.energy[after, b] - reading.energy[before, b] for before, after in bounds)
            gains[b] = max(gains[b], rise / scale[b])
    return gains


def _energy_gain(reading: ContactReading) -> Measured:
    """:func:`contact_energy_gains`, the worst body's."""
    if not any(reading.episodes.values()):
        return Measured(math.nan, "1", unmeasurable="no contact: no energy to gain at one")
    if not (reading.kinetic.max(axis=0) > 0).any():
        return Measured(math.nan, "1", unmeasurable="no body moved: no energy to gain")
    gain = float(contact_energy_gains(reading).max())
    if gain <= ENERGY_GAIN_ROUNDING:
        return Measured(0.0, "1", note=f"rises below {ENERGY_GAIN_ROUNDING:g} of the largest kinetic energy are "
                        "rounding")
    return Measured(gain, "1", note="across a contact episode, relative to the run's largest kinetic energy")


UNSTABLE_ENERGY_GAIN = 0.1
"""Energy gained across one contact above 10 % of the run's largest kinetic energy is a blow-up, not an
error: a stable scheme errs by a few per cent of the impact's energy at the steps run here, while an
unstable one multiplies the energy by a growing factor each oscillation of a contact spring."""


def contact_blow_up(scene: DynamicsScene, reading: ContactReading) -> str:
    """Why a run counts as diverged at a contact (energy gained beyond :data:`UNSTABLE_ENERGY_GAIN`), or ""."""
    gains = contact_energy_gains(reading)
    if gains.max(initial=0.0) <= UNSTABLE_ENERGY_GAIN:
        return ""
    b = int(np.argmax(gains))
    return (f"energy of {scene.bodies[b].name} rose by {gains[b]:.3g} of its largest kinetic energy across a contact "
            f"(limit {UNSTABLE_ENERGY_GAIN:.0%}: contact only takes energy away)")


def _stops(reading: ContactReading, traj: Trajectory) -> np.ndarray:
    """(B,) how far each body that starts on a plane has moved when at rest at the end [m]: |x(end) - x(0)|;
    NaN for a body that does not start on a plane or is still moving at the end."""
    starts_on = (np.abs(reading.distance[0]) <= TOUCH_GAP).any(axis=1)
    moved = np.linalg.norm(traj.position_world[-1] - traj.position_world[0], axis=-1)
    return np.where(starts_on & ~np.isnan(reading.rest_time), moved, np.nan)


def _stopping_distance(reading: ContactReading, traj: Trajectory) -> Measured:
    """The largest stopping distance [m] over bodies that start on a plane and come to rest (sliding)."""
    if not (np.abs(reading.distance[0]) <= TOUCH_GAP).any():
        return Measured(math.nan, "m", unmeasurable="no body starts on a plane: stopping distance is for sliding")
    stops = _stops(reading, traj)
    if np.isnan(stops).all():
        return Measured(math.nan, "m", unmeasurable="no sliding body is at rest at the end of the run")
    return Measured(float(np.nanmax(stops)), "m")


def _stopping_distance_error(reading: ContactReading, traj: Trajectory, truth: ContactReading,
                             ref: Trajectory) -> Measured:
    """Largest per-body |stop - stop(reference)| [m]; a body at rest in one run and moving in the other is off
    by at least |x(end) - x_stop|, its distance from the other's rest position, and the note says so."""
    mine, theirs = _stops(reading, traj), _stops(truth, ref)
    either = ~np.isnan(mine) | ~np.isnan(theirs)
    if not either.any():
        return Measured(math.nan, "m", unmeasurable="no sliding body comes to rest in this run or the reference")
    moved = np.linalg.norm(traj.position_world[-1] - traj.position_world[0], axis=-1)
    moved_ref = np.linalg.norm(ref.position_world[-1] - ref.position_world[0], axis=-1)
    error = np.abs(np.where(np.isnan(mine), moved, mine) - np.where(np.isnan(theirs), moved_ref, theirs))[either]
    mismatch = (np.isnan(mine) != np.isnan(theirs))[either].any()
    return Measured(float(error.max()), "m", note=("a body rests in one run and still moves in the other: the "
                                                   "error is at least this" if mismatch else ""))


def _compare(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a - b| over entries finite in both; NaN when none are."""
    both = np.isfinite(a) & np.isfinite(b)
    return float(np.abs(a[both] - b[both]).max()) if both.any() else math.nan


def contact_metrics(scene: DynamicsScene, traj: Trajectory, ref: Trajectory | None,
                    reading: ContactReading | None = None) -> dict[str, Measured]:
    """The contact metrics of ``traj`` (those comparing with a reference only when ``ref`` is given);
    ``reading``: :func:`read_contact` of ``traj`` when already computed."""
    reading = reading or read_contact(scene, traj)
    out = _own_metrics(scene, reading, traj)
    if ref is None:
        return out
    truth = read_contact(scene, ref)
    times, rebounds, apexes, energies, missed, compared = [], [], [], [], 0, 0
    for key, expected in truth.impacts.items():
        got = reading.impacts[key]
        n = min(len(expected.time), IMPACTS_COMPARED)
        compared += n
        missed += max(0, n - len(got.time))
        m = min(n, len(got.time))
        times.append(_compare(got.time[:m], expected.time[:m]))
        rebounds.append(_compare(got.velocity_out[:m], expected.velocity_out[:m]))
        apexes.append(_compare(got.apex[:m], expected.apex[:m]))
        still = ~got.turning[:m] & ~expected.turning[:m]
        energies.append(_compare((got.velocity_out[:m] / got.velocity_in[:m])[still] ** 2,
                                 (expected.velocity_out[:m] / expected.velocity_in[:m])[still] ** 2))
    note = f"over the reference's first {IMPACTS_COMPARED} impacts per body and plane ({compared} here)"
    shared = sum(min(len(truth.impacts[key].time), IMPACTS_COMPARED, len(got.time))
                 for key, got in reading.impacts.items())
    unknown = {
        "impact_time_error": "no impact time: neither body falls toward the plane at the impacts compared",
        "rebound_velocity_error": "the runs end inside the impacts compared: their rebounds are unknown",
        "apex_height_error": "no apex: gravity does not pull the body back toward the plane (or the runs end in "
                             "contact)",
        "energy_loss_error": "the bodies turn at the impacts compared: the COM's rebound is not the contact point's",
    }
    for metric, values, unit in (("impact_time_error", times, "s"), ("rebound_velocity_error", rebounds, "m/s"),
                                 ("apex_height_error", apexes, "m"), ("energy_loss_error", energies, "1")):
        finite = [v for v in values if math.isfinite(v)]
        why = (unknown[metric] if shared else "the reference has no impact" if not compared else
               "this run has none of the reference's impacts (impacts_missed counts them)")
        out[metric] = Measured(max(finite), unit, note=note) if finite else Measured(math.nan, unit, unmeasurable=why)
    out["impacts_missed"] = (Measured(float(missed), "1", note=note) if compared else
                             Measured(math.nan, "1", unmeasurable="the reference has no impact"))
    out["rest_time_error"] = _rest_time_error(reading.rest_time, truth.rest_time, float(traj.times[-1]))
    if (np.abs(truth.distance[0]) <= TOUCH_GAP).any():
        out["stopping_distance_error"] = _stopping_distance_error(reading, traj, truth, ref)
    else:
        out["stopping_distance_error"] = Measured(math.nan, "m", unmeasurable=(
            "no body starts on a plane in the reference: stopping distance is for sliding"))
    return out


def _rest_time_error(rest: np.ndarray, truth: np.ndarray, end: float) -> Measured:
    """Largest |t_rest - t_rest(reference)| over bodies at rest at the end in either run, read at the samples.
    A body at rest in one run and still moving in the other is off by at least end - its t_rest there: that
    lower bound is the value, and the note says so."""
    either = ~np.isnan(rest) | ~np.isnan(truth)
    if not either.any():
        return Measured(math.nan, "s", unmeasurable="no body comes to rest in this run or the reference")
    late = np.where(np.isnan(rest), end - truth, np.where(np.isnan(truth), end - rest, np.abs(rest - truth)))[either]
    mismatch = (np.isnan(rest) != np.isnan(truth))[either].any()
    note = ("a body rests in one run and still moves in the other: the error is at least this" if mismatch else
            "rest read at the samples (to within one dt)")
    return Measured(float(late.max()), "s", note=note)
