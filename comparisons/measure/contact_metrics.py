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

Over 600 lines: one protocol. The impact episodes (:func:`read_contact`) and every contact metric
read the same :class:`ContactReading`; apart, each metric module would re-derive the episodes' conventions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simparity.comparisons.measure.body_scales import (
    contact_of,
    body_sizes,
    lift_energies,
    shape_points_body,
    shape_reach,
    touch_gaps,
)
from simparity.comparisons.measure.invariants import kinetic_energy, potential_energy
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.results import NOTHING_TO_MEASURE
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.references.common.conventions import quat_wxyz_to_matrix
from simparity.core.model.metric_catalogue import (
    units,
    APEX_HEIGHT_ERROR, ENERGY_GAIN_MAX, ENERGY_KEPT_MAX, ENERGY_KEPT_MEDIAN, ENERGY_KEPT_MIN, ENERGY_LOSS_ERROR,
    IMPACTS_MISSED, IMPACT_TIME_ERROR, PENETRATION_MAX, REBOUND_VELOCITY_ERROR, RESTITUTION_ERROR, RESTITUTION_MAX,
    RESTITUTION_MEASURED, RESTITUTION_MEDIAN, RESTITUTION_MIN, REST_JITTER, REST_TIME_ERROR, STOPPING_DISTANCE,
    STOPPING_DISTANCE_ERROR, TUNNELLED,
)

CONTACT_METRICS = units(
    IMPACT_TIME_ERROR,
    REBOUND_VELOCITY_ERROR,
    APEX_HEIGHT_ERROR,
    IMPACTS_MISSED,
    RESTITUTION_MEASURED,
    RESTITUTION_ERROR,
    RESTITUTION_MIN,
    RESTITUTION_MEDIAN,
    RESTITUTION_MAX,
    ENERGY_KEPT_MIN,
    ENERGY_KEPT_MEDIAN,
    ENERGY_KEPT_MAX,
    ENERGY_LOSS_ERROR,
    PENETRATION_MAX,
    TUNNELLED,
    ENERGY_GAIN_MAX,
    REST_TIME_ERROR,
    REST_JITTER,
    STOPPING_DISTANCE,
    STOPPING_DISTANCE_ERROR,
)
"""Per-case contact metrics (units); see the module docstring and docs/metrics.md."""

IMPACTS_COMPARED = 10
"""Impacts compared with the reference's: the issue's first ten bounces; later ones are ever
shorter (k^n) and fall below any sampling."""

HOP_FRACTION = 0.01
"""An episode is an impact only if the body falls into it from at least this fraction of its size (its impact
speed at least sqrt(2 |g_n| HOP_FRACTION size)): lower hops are a soft contact's jitter or a sliding body's
friction hops, not bounces (MuJoCo's block sliding at 2 m/s hops 0.1 mm, a thousandth of its size, at
"restitutions" of 1.2-1.5; PyBullet's resting box jitters 0.1 mm). Relative to the body's size, so it moves
with the scene's length unit; a body that rises less than a hundredth of its size off a plane rests on it."""

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
        The body turns around the impact (its points move by rotation faster than the least impact
        speed at the sample before or after): the COM's normal velocity is then not the contact
        point's, and the impact gives no restitution.
    before, after : (N,) ndarray of int
        The free samples either side of the impact's episode (``after``: the last sample when the run
        ends inside it).
    """

    time: np.ndarray
    velocity_in: np.ndarray
    velocity_out: np.ndarray
    apex: np.ndarray
    turning: np.ndarray
    before: np.ndarray
    after: np.ndarray

    @property
    def measured(self) -> np.ndarray:
        """(N,) bool: the impact's outcome (a rebound, or staying: 0) is known."""
        return np.isfinite(self.velocity_out)

    @property
    def rebound_ratio(self) -> np.ndarray:
        """(N,) v_out / |v_in|: the restitution of each impact (NaN where its outcome is unknown)."""
        return self.velocity_out / -self.velocity_in

    @property
    def restituting(self) -> np.ndarray:
        """(N,) bool: impacts that give a restitution (outcome known, the body does not turn)."""
        return self.measured & ~self.turning


def extreme_distances(scene: DynamicsScene, traj: Trajectory, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest): the signed distance [m] of each body's lowest and highest point from each plane at
    every sample, each (T, B, P); highest < 0 means wholly beyond the plane. ``rotation`` (T, B, 3, 3): the
    samples' body-to-world rotations."""
    contact = contact_of(scene)
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
    return 0.0 if gravity is None else float(gravity @ contact_of(scene).planes[p].normal_world)


def _episodes(touch: np.ndarray, jump: np.ndarray) -> list[tuple[int, int]]:
    """Runs of event steps [(first step, last step)]: step i (samples i -> i + 1) is an event step when
    either sample touches or the normal velocity jumps up within it."""
    event = touch[:-1] | touch[1:] | jump
    starts = np.flatnonzero(event & ~np.concatenate([[False], event[:-1]]))
    ends = np.flatnonzero(event & ~np.concatenate([event[1:], [False]]))
    return list(zip(starts.tolist(), ends.tolist()))


def episode_samples(times: np.ndarray, distance: np.ndarray, normal_velocity: np.ndarray, normal_gravity: float,
                    nearest: np.ndarray | None = None, touch_gap: float = 0.0) -> list[tuple[int, int]]:
    """(sample before, sample after) of every contact episode of one body against one plane (see
    :func:`impacts` for the arguments): the samples either side of a run of steps that touch the plane or
    in which the normal velocity jumps up."""
    dt = float(times[1] - times[0]) if len(times) > 1 else 0.0
    touch = distance <= touch_gap
    rise = np.diff(normal_velocity) - normal_gravity * dt
    jump = rise > JUMP_RTOL * (np.abs(normal_velocity[:-1]) + abs(normal_gravity) * dt)
    if nearest is not None:
        jump &= nearest
    return [(first, last + 1) for first, last in _episodes(touch, jump)]


def impacts(times: np.ndarray, distance: np.ndarray, normal_velocity: np.ndarray, normal_gravity: float,
            min_speed: float = 0.0, spin_speed: np.ndarray | None = None,
            episodes: list[tuple[int, int]] | None = None, touch_gap: float = 0.0) -> Impacts:
    """The impact episodes of one body against one plane from its samples; episodes whose impact speed is
    below ``min_speed`` [m/s] are settling, jitter or hops, not impacts, and are left out. ``spin_speed`` (T,)
    [m/s]: how fast the body's points move by its rotation (|omega| x its extent); an impact where it exceeds
    ``min_speed`` is marked turning. ``episodes``: :func:`episode_samples` of these samples when already
    found (None: found here, every step counted). ``touch_gap`` [m]: a support distance within which a sample
    touches the plane.

    An episode the run ends inside has an unknown outcome (NaN rebound and apex), unless the body is on the
    plane and no longer moving along its normal faster than ``min_speed`` there: it stayed (a rebound of 0).

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
    touch = distance <= touch_gap
    last = len(times) - 1
    out: list[tuple[float, float, float, float, bool, int, int]] = []
    if episodes is None:
        episodes = episode_samples(times, distance, normal_velocity, normal_gravity, touch_gap=touch_gap)
    for before, after in episodes:
        if touch[before] or normal_velocity[before] ** 2 + 2 * g * distance[before] < 0:
            continue  # starts in contact (a body placed on the plane): not an impact
        d, v = distance[before], normal_velocity[before]
        speed_in = math.sqrt(max(v * v + 2 * g * d, 0.0))
        if speed_in < min_speed:
            continue
        backed = (v + speed_in) / g if g > 0 else (d / -v if v < 0 else math.nan)
        v_out = apex = math.nan  # the run ends inside the episode: the rebound is unknown
        if not touch[after] and normal_velocity[after] > 0:
            d1, v1 = distance[after], normal_velocity[after]
            v_out = math.sqrt(max(v1 * v1 + 2 * g * d1, 0.0))
            apex = d1 + v1 * v1 / (2 * g) if g > 0 else math.nan
        elif after < last or (touch[after] and abs(normal_velocity[after]) <= min_speed):
            v_out = apex = 0.0  # the body stayed on the plane: a rebound of 0, measured
        spin = 0.0 if spin_speed is None else max(spin_speed[before], spin_speed[after])
        out.append((times[before] + backed, -speed_in, v_out, apex, spin > min_speed, before, after))
    columns = np.array(out, dtype=float).reshape(-1, 7).T
    return Impacts(columns[0], columns[1], columns[2], columns[3], columns[4].astype(bool), columns[5].astype(int),
                   columns[6].astype(int))


@dataclass(frozen=True)
class ContactReading:
    """What a trajectory shows about contact, per body and plane.

    Attributes
    ----------
    impacts : dict of (body, plane) to Impacts
    episodes : dict of (body, plane) to list of (int, int)
        (sample before, sample after) of every contact episode.
    distance, highest : (T, B, P) ndarray
        Support distances [m], and the distances of the highest points (negative: wholly beyond the plane).
    rest_time : (B,) ndarray
        First sample time after which the body stays at rest [s]; NaN if never.
    energy, kinetic : (T, B) ndarray
        Kinetic + potential, kinetic [J].
    energy_scale : (B,) ndarray
        What energy gained at a contact is relative to [J]: the body's largest kinetic energy of the run, at
        least the energy that lifts it by its own size (a body resting on a plane has no other).
    energy_kept : dict of (body, plane) to (N,) ndarray
        Per impact, the energy it keeps (:func:`_energy_kept`); NaN where the outcome is unknown.
    impact_budgets : dict of (body, plane) to dict of int to float
        Per impact, keyed by the sample before its episode: its energy budget [J], the body's energy above the plane
        there (kinetic + m |g_n| height of its support), what it may keep at most.
    touch_gap : (B,) ndarray
        The support distance within which each body touches a plane [m].
    """

    impacts: dict[tuple[int, int], Impacts]
    episodes: dict[tuple[int, int], list[tuple[int, int]]]
    distance: np.ndarray
    highest: np.ndarray
    rest_time: np.ndarray
    energy: np.ndarray
    kinetic: np.ndarray
    energy_scale: np.ndarray
    energy_kept: dict[tuple[int, int], np.ndarray]
    touch_gap: np.ndarray
    impact_budgets: dict[tuple[int, int], dict[int, float]]

    def starts_on_plane(self) -> np.ndarray:
        """(B,) bool: bodies that touch a plane at the first sample."""
        return (np.abs(self.distance[0]) <= self.touch_gap[:, None]).any(axis=1)


def _rest_times(scene: DynamicsScene, traj: Trajectory) -> np.ndarray:
    """(B,) the first sample time from which every later sample's speed (COM speed plus |omega| times
    the body's extent) is within the scene's rest speed; NaN where the body is still moving at the end."""
    speed = (np.linalg.norm(traj.velocity_world, axis=-1)
             + np.linalg.norm(traj.angular_velocity_world, axis=-1) * shape_reach(scene))
    moving = speed > contact_of(scene).rest_speed
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


def least_impact_speeds(scene: DynamicsScene) -> np.ndarray:
    """(B, P) [m/s] the slowest episode that counts as an impact of each body on each plane: the scene's
    settling speed (:func:`_settling_speed`), or the speed of a fall from :data:`HOP_FRACTION` of the body's
    size where that is faster."""
    sizes = body_sizes(scene)
    out = np.empty((len(scene.bodies), len(contact_of(scene).planes)))
    for b in range(len(scene.bodies)):
        for p in range(len(contact_of(scene).planes)):
            hop = math.sqrt(2 * abs(_normal_gravity(scene, p)) * HOP_FRACTION * sizes[b])
            out[b, p] = max(_settling_speed(contact_of(scene).rest_speed, contact_of(scene).restitution[b, p]), hop)
    return out


def _flight_peak(distance: np.ndarray, start: int, stop: int) -> int:
    """The sample of a flight (samples ``start`` to ``stop``, both free) farthest from the plane: where no contact
    can act, even one that acts before its body touches (a collision margin, a speculative contact)."""
    return start + int(np.argmax(distance[start:stop + 1]))


def _energy_kept(found: Impacts, episodes: list[tuple[int, int]], energy: np.ndarray, above: np.ndarray,
                 distance: np.ndarray) -> np.ndarray:
    """(N,) per impact, 1 + (the energy it gained) / (the body's energy above the plane before it), each read at
    the peak of the flight before and after it (:func:`_flight_peak`; the sample after the impact when the body
    stays on the plane): the energy kept, e.g. h_after / h_before for a ball bouncing straight up and down (a
    turning body whose centre of mass drops further than its lowest point as it settles keeps at least 0). NaN
    where the outcome is unknown.

    ``energy`` (T,) kinetic + potential [J] (conserved in flight), ``above`` (T,) kinetic + m |g_n| height of the
    support [J], ``distance`` (T,) support distances [m]; ``episodes`` all of the body's episodes on the plane."""
    starts = [after for _, after in episodes]
    ends = [before for before, _ in episodes]
    last = len(distance) - 1
    kept = np.full(len(found.time), math.nan)
    for i, (before, after, known) in enumerate(zip(found.before, found.after, found.measured)):
        if not known:
            continue
        k = ends.index(before)
        peak_before = _flight_peak(distance, starts[k - 1] if k > 0 else 0, before)
        stays = found.velocity_out[i] == 0
        peak_after = after if stays else _flight_peak(distance, after, ends[k + 1] if k + 1 < len(ends) else last)
        if above[peak_before] > 0:
            kept[i] = max(0.0, 1 + (energy[peak_after] - energy[peak_before]) / above[peak_before])
    return kept


def read_contact(scene: DynamicsScene, traj: Trajectory) -> ContactReading:
    """Everything the contact metrics need from one trajectory."""
    rotation = quat_wxyz_to_matrix(traj.quat_wxyz)  # SciPy's
    distance, highest = extreme_distances(scene, traj, rotation)
    mass = np.array([b.mass for b in scene.bodies])
    inertia = np.stack([b.inertia_body for b in scene.bodies])
    kinetic = kinetic_energy(mass, inertia, traj.velocity_world, traj.angular_velocity_world, rotation)
    potential = (np.zeros_like(kinetic) if scene.forces.gravity_world is None
                 else potential_energy(mass, scene.forces.gravity_world, traj.position_world))
    found, episodes, kept, budgets = {}, {}, {}, {}
    least = least_impact_speeds(scene)
    gaps = touch_gaps(scene)
    spin = np.linalg.norm(traj.angular_velocity_world, axis=-1) * shape_reach(scene)
    closest = np.minimum(distance[:-1], distance[1:]).argmin(axis=-1)  # (T - 1, B): each step's nearest plane
    for b in range(len(scene.bodies)):
        for p, plane in enumerate(contact_of(scene).planes):
            normal_velocity, g_n = traj.velocity_world[:, b] @ plane.normal_world, _normal_gravity(scene, p)
            episodes[b, p] = episode_samples(traj.times, distance[:, b, p], normal_velocity, g_n, closest[:, b] == p,
                                             gaps[b])
            found[b, p] = impacts(traj.times, distance[:, b, p], normal_velocity, g_n, least[b, p], spin[:, b],
                                  episodes[b, p], gaps[b])
            above = kinetic[:, b] + mass[b] * abs(g_n) * np.maximum(distance[:, b, p], 0.0)
            kept[b, p] = _energy_kept(found[b, p], episodes[b, p], kinetic[:, b] + potential[:, b], above,
                                      distance[:, b, p])
            budgets[b, p] = {int(before): float(above[before]) for before in found[b, p].before}
    scale = np.maximum(kinetic.max(axis=0), lift_energies(scene))
    return ContactReading(found, episodes, distance, highest, _rest_times(scene, traj), kinetic + potential, kinetic,
                          scale, kept, gaps, budgets)


def _nothing(unit: str, why: str) -> Measured:
    """An n/a value because the run's physics offers nothing to measure (no impact, no motion)."""
    return Measured(math.nan, unit, flag=NOTHING_TO_MEASURE, unmeasurable=why)


def _spread(values: list[float], unit: str, what: str, why: str) -> tuple[Measured, Measured, Measured]:
    """(min, median, max) of ``values`` over the run's impacts, or three n/a with ``why`` when there are none."""
    if not values:
        return _nothing(unit, why), _nothing(unit, why), _nothing(unit, why)
    note = f"over {len(values)} impacts: {what}"
    low, middle, high = (Measured(float(f(values)), unit, note=note) for f in (np.min, np.median, np.max))
    return low, middle, high


def _restitution_metrics(scene: DynamicsScene, reading: ContactReading) -> dict[str, Measured]:
    """Restitution at the first impact (against the requested k) and at every impact (min / median / max), and
    the energy each impact keeps (min / median / max)."""
    out: dict[str, Measured] = {}
    worst, measured, requested = -1.0, math.nan, math.nan
    turning = any(found.turning.any() for found in reading.impacts.values())
    ratios, kept = [], []
    for (b, p), found in reading.impacts.items():
        known = found.restituting
        ratios += found.rebound_ratio[known].tolist()
        kept += reading.energy_kept[b, p][found.measured].tolist()
        if known.any():
            k = float(contact_of(scene).restitution[b, p])
            e = float(found.rebound_ratio[int(np.argmax(known))])  # the body's first impact with a known outcome
            if abs(e - k) > worst:
                worst, measured, requested = abs(e - k), e, k
    impacted = any(len(found.time) for found in reading.impacts.values())
    none = ("the body turns at its impacts: the COM's rebound is not the contact point's" if turning else
            "the run ends inside its impact: the rebound is unknown" if impacted else
            "no impact: nothing to measure restitution on")
    if worst < 0:
        out[RESTITUTION_MEASURED] = out[RESTITUTION_ERROR] = _nothing("1", none)
    else:
        note = f"first impact: measured {measured:.6g}, requested {requested:.6g}"
        out[RESTITUTION_MEASURED] = Measured(measured, "1", note=note)
        out[RESTITUTION_ERROR] = Measured(worst, "1", note=note)
    requested_k = ", ".join(f"{k:g}" for k in sorted({float(k) for k in np.ravel(contact_of(scene).restitution)}))
    out[RESTITUTION_MIN], out[RESTITUTION_MEDIAN], out[RESTITUTION_MAX] = _spread(
        ratios, "1", f"v_out / |v_in| of each, requested {requested_k}", none)
    out[ENERGY_KEPT_MIN], out[ENERGY_KEPT_MEDIAN], out[ENERGY_KEPT_MAX] = _spread(
        kept, "1", "the body's energy above the plane after each over before it (above 1: gained)",
        "no impact with a known outcome: nothing to measure the energy kept on")
    return out


def _own_metrics(scene: DynamicsScene, reading: ContactReading, traj: Trajectory) -> dict[str, Measured]:
    """Metrics that need no reference: restitution against the requested one, penetration, tunnelling,
    energy gained, resting jitter, stopping distance."""
    out = _restitution_metrics(scene, reading)
    out[PENETRATION_MAX] = Measured(float(max(0.0, -reading.distance.min())), "m")
    out[TUNNELLED] = Measured(float(_tunnelled(scene, reading, traj).sum()), "1",
                                note="bodies wholly beyond a plane at the end and still moving away from it")
    out[ENERGY_GAIN_MAX] = _energy_gain(reading)
    out[REST_JITTER] = _rest_jitter(scene, reading, traj)
    out[STOPPING_DISTANCE] = _stopping_distance(reading, traj)
    return out


def _tunnelled(scene: DynamicsScene, reading: ContactReading, traj: Trajectory) -> np.ndarray:
    """(B,) bool: the body went through a plane and is still going: at the last sample its highest point is
    beyond the plane, as deep as it has ever been, and it moves farther in faster than the scene's rest
    speed. (A plane is a half-space, so a body deep inside one may still be pushed back: the depth alone is
    ``penetration_max``. A body resting in a soft or penalty contact sits slightly inside, and a soft
    contact's jitter moves it in and out, but never deeper than its impact took it.)"""
    normals = np.stack([p.normal_world for p in contact_of(scene).planes])  # (P, 3)
    inward = traj.velocity_world[-1] @ normals.T < -contact_of(scene).rest_speed  # (B, P)
    deepest = reading.highest[-1] <= reading.highest.min(axis=0)
    return ((reading.highest[-1] < 0) & deepest & inward).any(axis=1)


def resting_phases(scene: DynamicsScene, reading: ContactReading) -> list[tuple[int, int] | None]:
    """Per body, (first sample, plane) of the final run of samples in which it rests on a plane, or None: its
    energy above the plane it ends nearest (kinetic + m |g_n| height of its support) stays within that of a hop
    of :data:`HOP_FRACTION` of its size, so it cannot rise off the plane by more than a hop."""
    sizes = body_sizes(scene)
    out: list[tuple[int, int] | None] = []
    for b, body in enumerate(scene.bodies):
        p = int(np.argmin(reading.distance[-1, b]))
        lift = body.mass * abs(_normal_gravity(scene, p))
        above = reading.kinetic[:, b] + lift * np.maximum(reading.distance[:, b, p], 0.0)
        resting = above <= lift * HOP_FRACTION * sizes[b]
        if lift == 0 or not resting[-1]:
            out.append(None)
            continue
        moving = np.flatnonzero(~resting)
        out.append((int(moving[-1]) + 1 if moving.size else 0, p))
    return out


def _rest_jitter(scene: DynamicsScene, reading: ContactReading, traj: Trajectory) -> Measured:
    """The largest peak-to-peak support distance [m] of a body over its final resting phase
    (:func:`resting_phases`): 0 for a body held exactly on its plane, a soft contact's persistent jitter else."""
    jitters, spans = [], []
    for b, phase in enumerate(resting_phases(scene, reading)):
        if phase is not None and phase[0] < len(traj.times) - 1:
            start, p = phase
            jitters.append(float(np.ptp(reading.distance[start:, b, p])))
            spans.append(float(traj.times[-1] - traj.times[start]))
    if not jitters:
        return _nothing("m", "no body rests on a plane at the end of the run")
    worst = int(np.argmax(jitters))
    return Measured(jitters[worst], "m", note=f"peak-to-peak support distance over the last {spans[worst]:.3g} s, "
                                              "in which the body rests")


def contact_energy_gains(reading: ContactReading, per_impact: bool = False) -> np.ndarray:
    """(B,) the largest rise of kinetic + potential energy across a contact episode of each body (from the
    sample before it to the sample after it), relative to the body's energy scale (its largest kinetic energy
    of the run, at least the energy that lifts it by its own size); 0 where it has none. Contact and friction
    only take energy away; a free flight's own drift between episodes is the integrator's, not the contact's,
    and is not counted.

    ``per_impact``: an impact's rise is relative to its own budget instead, the body's energy above the plane
    before it (:attr:`ContactReading.impact_budgets`, what ``energy_kept`` is relative to), so that both read one
    impact alike; an episode that is no impact (a touch slower than one: settling, resting, sliding) keeps the
    body's energy scale, the physical floor of a body whose energy above the plane is all but 0."""
    scale = reading.energy_scale
    gains = np.zeros(reading.energy.shape[1])
    for (b, p), bounds in reading.episodes.items():
        if bounds and scale[b] > 0:
            budgets = reading.impact_budgets[b, p] if per_impact else {}
            rise = max(((reading.energy[after, b] - reading.energy[before, b]) / budgets.get(before, scale[b])
                        for before, after in bounds if budgets.get(before, scale[b]) > 0), default=0.0)
            gains[b] = max(gains[b], rise)
    return gains


def _energy_gain(reading: ContactReading) -> Measured:
    """:func:`contact_energy_gains` per impact, the worst body's."""
    if not any(reading.episodes.values()):
        return _nothing("1", "no contact: no energy to gain at one")
    if not (reading.energy_scale > 0).any():
        return _nothing("1", "no body moved and none has weight: no energy to gain")
    gain = float(contact_energy_gains(reading, per_impact=True).max())
    if gain <= ENERGY_GAIN_ROUNDING:
        return Measured(0.0, "1", note=f"rises below {ENERGY_GAIN_ROUNDING:g} of the energy scale are rounding")
    return Measured(gain, "1", note=(
        "across a contact episode, relative to the impact's budget (the body's energy above the plane before it, "
        "as energy_kept); a touch that is no impact relative to the body's largest kinetic energy (at least "
        "m |g| size)"))


UNSTABLE_ENERGY_GAIN = 0.1
"""Energy gained across one contact above 10 % of the body's energy scale is a blow-up, not an error: a
stable scheme errs by a few per cent of the impact's energy at the steps run here, while an unstable one
multiplies the energy by a growing factor each oscillation of a contact spring."""

REBOUND_GAIN_TOLERANCE = 0.05
"""An impact after which the body has more than (1 + 0.05)^2 of its energy above the plane (a rebound 5 %
faster than the impact: 10 % of the impact's energy gained) gains energy beyond what a soft or penalty contact
stores and gives back at one impact (MuJoCo and PyBullet show ~1e-4 of it). Read from the energy, not the COM's
normal rebound: a turning body's rebound is not its contact point's, and a contact that acts on samples that
look free (PyBullet's speculative contacts at coarse steps) makes the normal rebound read high while the energy
is kept."""

SUSTAINED_GAIN_IMPACTS = 3
"""Impacts of one body on one plane that each gain more than :data:`REBOUND_GAIN_TOLERANCE` allows, at least this
many and either in succession or at most of its impacts (more than half of those with a known outcome), are a
contact that pumps energy in (a penalty spring past its integrator's stability limit), not an error: diverged. One
or two such impacts, or a few among many that lose energy, stay numbers (``energy_kept_max``, ``restitution_max``,
``energy_gain_max``): a grazing impact spread over steps of comparable gravity can gain once."""


@dataclass(frozen=True)
class SustainedGain:
    """The impacts of one body on one plane that gain energy (each keeps more than (1 +
    :data:`REBOUND_GAIN_TOLERANCE`)^2 of its budget, the body's energy above the plane before it).

    Attributes
    ----------
    body, plane : int
        -1 when no impact gains.
    gaining : int
        How many gain.
    impacts : int
        How many have a known outcome.
    successive : int
        The longest run of successive gaining impacts.
    kept : list of float
        The energy each gaining impact kept, in time order.
    """

    body: int = -1
    plane: int = -1
    gaining: int = 0
    impacts: int = 0
    successive: int = 0
    kept: tuple[float, ...] = ()

    @property
    def sustained(self) -> bool:
        """At least :data:`SUSTAINED_GAIN_IMPACTS` gain, in succession or at more than half of the impacts."""
        return self.gaining >= SUSTAINED_GAIN_IMPACTS and (self.successive >= SUSTAINED_GAIN_IMPACTS
                                                           or 2 * self.gaining > self.impacts)


def sustained_gain(reading: ContactReading) -> SustainedGain:
    """The body and plane whose impacts gain energy the most sustainedly (:attr:`SustainedGain.sustained` first,
    then the most gaining impacts); an empty :class:`SustainedGain` when none gains."""
    best = SustainedGain()
    for (b, p), found in reading.impacts.items():
        kept = reading.energy_kept[b, p][found.measured]
        gains = kept > (1 + REBOUND_GAIN_TOLERANCE) ** 2
        if not gains.any():
            continue
        runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[0], gains.astype(int), [0]]))))[::2]
        here = SustainedGain(b, p, int(gains.sum()), len(kept), int(runs.max()), tuple(kept[gains].tolist()))
        if (here.sustained, here.gaining) > (best.sustained, best.gaining):
            best = here
    return best


def contact_blow_up(scene: DynamicsScene, reading: ContactReading) -> str:
    """Why a run counts as diverged at a contact, or "": energy gained across one contact beyond
    :data:`UNSTABLE_ENERGY_GAIN` of the body's energy scale, or a gain sustained over its impacts
    (:attr:`SustainedGain.sustained`), each judged against the impact's own budget."""
    gains = contact_energy_gains(reading)
    if gains.max(initial=0.0) > UNSTABLE_ENERGY_GAIN:
        b = int(np.argmax(gains))
        return (f"energy of {scene.bodies[b].name} rose by {gains[b]:.3g} of its energy scale across a contact "
                f"(limit {UNSTABLE_ENERGY_GAIN:.0%}: contact only takes energy away)")
    gain = sustained_gain(reading)
    if gain.sustained:
        shown = ", ".join(f"{k:.3g}" for k in gain.kept[:6]) + (", ..." if gain.gaining > 6 else "")
        return (f"{scene.bodies[gain.body].name} gained energy at {gain.gaining} of its {gain.impacts} impacts on "
                f"{contact_of(scene).planes[gain.plane].name} ({gain.successive} in succession; energy kept {shown} "
                f"> (1 + {REBOUND_GAIN_TOLERANCE:g})^2 of the energy above the plane before each: contact only "
                "takes energy away)")
    return ""


def _stops(reading: ContactReading, traj: Trajectory) -> np.ndarray:
    """(B,) how far each body that starts on a plane has moved when at rest at the end [m]: |x(end) - x(0)|;
    NaN for a body that does not start on a plane or is still moving at the end."""
    moved = np.linalg.norm(traj.position_world[-1] - traj.position_world[0], axis=-1)
    return np.where(reading.starts_on_plane() & ~np.isnan(reading.rest_time), moved, np.nan)


def _stopping_distance(reading: ContactReading, traj: Trajectory) -> Measured:
    """The largest stopping distance [m] over bodies that start on a plane and come to rest (sliding)."""
    if not reading.starts_on_plane().any():
        return _nothing("m", "no body starts on a plane: stopping distance is for sliding")
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


_UNKNOWN = {
    IMPACT_TIME_ERROR: "no impact time: neither body falls toward the plane at the impacts compared, or they "
                         "fall in the first step, where both runs back them up from the same initial state",
    REBOUND_VELOCITY_ERROR: "the runs end inside the impacts compared: their rebounds are unknown",
    APEX_HEIGHT_ERROR: "no apex: gravity does not pull the body back toward the plane (or the runs end in "
                         "contact)",
    ENERGY_LOSS_ERROR: "the runs end inside the impacts compared (their rebounds are unknown), or the bodies turn "
                         "at them (the COM's rebound is not the contact point's)",
}
"""Why an impact comparison has no value although both runs share impacts."""


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
        backed_apart = (got.before[:m] > 0) | (expected.before[:m] > 0)  # not both from the initial state
        times.append(_compare(got.time[:m][backed_apart], expected.time[:m][backed_apart]))
        rebounds.append(_compare(got.velocity_out[:m], expected.velocity_out[:m]))
        apexes.append(_compare(got.apex[:m], expected.apex[:m]))
        still = ~got.turning[:m] & ~expected.turning[:m]
        energies.append(_compare(got.rebound_ratio[:m][still] ** 2, expected.rebound_ratio[:m][still] ** 2))
    note = f"over the reference's first {IMPACTS_COMPARED} impacts per body and plane ({compared} here)"
    shared = sum(min(len(truth.impacts[key].time), IMPACTS_COMPARED, len(got.time))
                 for key, got in reading.impacts.items())
    for metric, values, unit in ((IMPACT_TIME_ERROR, times, "s"), (REBOUND_VELOCITY_ERROR, rebounds, "m/s"),
                                 (APEX_HEIGHT_ERROR, apexes, "m"), (ENERGY_LOSS_ERROR, energies, "1")):
        finite = [v for v in values if math.isfinite(v)]
        if finite:
            out[metric] = Measured(max(finite), unit, note=note)
        elif shared:
            out[metric] = _nothing(unit, _UNKNOWN[metric])
        elif compared:
            out[metric] = Measured(math.nan, unit, unmeasurable=(
                "this run has none of the reference's impacts (impacts_missed counts them)"))
        else:
            out[metric] = _nothing(unit, "the reference has no impact")
    out[IMPACTS_MISSED] = (Measured(float(missed), "1", note=note) if compared else
                             _nothing("1", "the reference has no impact"))
    out[REST_TIME_ERROR] = _rest_time_error(reading.rest_time, truth.rest_time, float(traj.times[-1]))
    if truth.starts_on_plane().any():
        out[STOPPING_DISTANCE_ERROR] = _stopping_distance_error(reading, traj, truth, ref)
    else:
        out[STOPPING_DISTANCE_ERROR] = _nothing("m", "no body starts on a plane in the reference: stopping "
                                                       "distance is for sliding")
    return out


def _rest_time_error(rest: np.ndarray, truth: np.ndarray, end: float) -> Measured:
    """Largest |t_rest - t_rest(reference)| over bodies at rest at the end in either run, read at the samples.
    A body at rest in one run and still moving in the other is off by at least end - its t_rest there: that
    lower bound is the value, and the note says so."""
    either = ~np.isnan(rest) | ~np.isnan(truth)
    if not either.any():
        return _nothing("s", "no body comes to rest in this run or the reference")
    late = np.where(np.isnan(rest), end - truth, np.where(np.isnan(truth), end - rest, np.abs(rest - truth)))[either]
    mismatch = (np.isnan(rest) != np.isnan(truth))[either].any()
    note = ("a body rests in one run and still moves in the other: the error is at least this" if mismatch else
            "rest read at the samples (to within one dt)")
    return Measured(float(late.max()), "s", note=note)
