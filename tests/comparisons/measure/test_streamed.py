"""Measuring runs in pieces: the same numbers as the whole run, and memory flat in the number of steps."""

import dataclasses
import tracemalloc
from collections.abc import Iterator

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.measure import streamed
from simparity.comparisons.measure.rows import Case
from simparity.comparisons.measure.series import StreamedEnvelope, envelope
from simparity.comparisons.measure.streamed import AlignedPieces, CaseReading
from simparity.core.model.engine import Engine, PieceSimulation, Simulation, Support, streams_in_pieces
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory, joined, piece_bounds, trajectory_pieces
from tests.helpers import built_engines, builtin, comparable, smoke

SCENES = ("dzhanibekov", "lecture-projectile", "falling-linear-drag", "point-mass-tumble")
"""Scenes whose every conserved quantity, error and series is measured (spin, gravity, drag, several bodies)."""

FLAT_BYTES_PER_STEP = 1.0
"""[bytes] What a case measured in pieces may hold per step beyond its fixed overhead: nothing (a whole trajectory
holds 104 bytes per body and sample, the engine's and the reference's twice that), so one byte per step is
rounding of the allocator's high-water mark, two orders of magnitude below holding the run."""

TEST_PIECE_BYTES = 64 * 2**10
"""[bytes] Pieces this small make a short run one of many pieces (and its reference streamed), so a test of
10^5 steps exercises what 10^7 steps do at the shipped piece size."""


def _fields(traj: Trajectory) -> tuple[np.ndarray, ...]:
    return (traj.times, traj.position_world, traj.quat_wxyz, traj.velocity_world, traj.angular_velocity_world)


def _read(scene: DynamicsScene, traj: Trajectory, ref: Trajectory, engine_cut: int, reference_cut: int) -> CaseReading:
    """A reading of ``traj`` against ``ref``, each cut into pieces of its own size."""
    n = len(traj.times) - 1
    reading = CaseReading(scene, n, True)
    reference = AlignedPieces(trajectory_pieces(ref, reference_cut))
    for piece in trajectory_pieces(traj, engine_cut):
        reading.add(piece, reference.take(len(piece.times)))
    return reading


@pytest.mark.slow  # ~1.5 s of CPU a scene: each run twice
@pytest.mark.parametrize("name", SCENES)
def test_a_run_read_in_pieces_measures_what_the_whole_run_measures(name):
    """Every extent, error and sampled series of a run read in pieces of 7 samples (its reference cut at 11) is
    the whole run's, bit for bit: maxima and first and last samples do not depend on the cuts."""
    scene = builtin(name)
    dt = scene.dts[-1]
    n = scene.n_steps(dt)
    traj = make_engine("core").build_dynamics(scene, "semi_implicit_euler", dt).run(n)
    ref = make_engine(scene.reference).build_dynamics(scene, make_engine(scene.reference).scene_integrators(scene)[0],
                                                      dt).run(n)
    whole, cut = _read(scene, traj, ref, n + 1, n + 1), _read(scene, traj, ref, 7, 11)
    assert n + 1 > 11 * 7
    for a, b in ((whole.run, cut.run), (whole.reference, cut.reference)):
        for field, value in vars(a).items():
            other = getattr(b, field)
            if hasattr(value, "__dataclass_fields__"):
                assert all(np.array_equal(getattr(value, f), getattr(other, f)) for f in vars(value)), field
            else:
                assert np.array_equal(value, other), field
    assert all(np.array_equal(whole.errors.per_body[m], cut.errors.per_body[m]) for m in whole.errors.per_body)
    case = Case(scene.name, "core", "semi_implicit_euler", dt, "ref")
    for a, b in zip(whole.series.records(case, whole.run), cut.series.records(case, cut.run), strict=True):
        assert a.quantity == b.quantity and np.array_equal(a.x, b.x) and np.array_equal(a.value, b.value), a.quantity


def test_the_streamed_envelope_is_the_envelope(rng=np.random.default_rng(11)):
    """Noisy samples with planted spikes, fed in pieces of random lengths: the same samples at the same times as
    :func:`envelope` of the whole (long and short runs); of several columns, the worst column's relative value."""
    for n in (5, 101, 102, 10_007):
        times = np.arange(n) * 0.01
        values = rng.normal(size=(n, 3))
        values[rng.integers(0, n, 3), [0, 1, 2]] = [40.0, -60.0, 50.0]
        scale = np.array([1.0, 3.0, 0.5])
        streamed_envelope, start = StreamedEnvelope(n, 3), 0
        while start < n:
            stop = min(n, start + int(rng.integers(1, 500)))
            streamed_envelope.add(start, times[start:stop], values[start:stop])
            start = stop
        relative = values / scale
        worst = np.take_along_axis(relative, np.argmax(np.abs(relative), axis=1)[:, None], axis=1)[:, 0]
        expected_t, expected_v = envelope(times, worst)
        got_t, got_v = streamed_envelope.worst(scale)
        assert np.array_equal(got_t, expected_t) and np.array_equal(got_v, expected_v), n
        one = StreamedEnvelope(n, 1)
        one.add(0, times, values[:, :1])
        assert all(np.array_equal(a, b) for a, b in zip(one.series(), envelope(times, values[:, 0]))), n


def test_aligned_pieces_recut_a_run_to_the_lengths_asked_for():
    """A run cut at 3 and read back at 4, 1, 5, ...: the same samples in order; asking past its end raises."""
    traj = builtin_free_run(20)
    aligned = AlignedPieces(trajectory_pieces(traj, 3))
    got = [aligned.take(k) for k in (4, 1, 5, 2, 9)]
    assert all(np.array_equal(a, b) for a, b in zip(_fields(joined(got)), _fields(traj)))
    with pytest.raises(ValueError, match="ended 1 samples early"):
        aligned.take(1)


def builtin_free_run(n: int) -> Trajectory:
    scene = _drifting_scene(n * 0.01)
    return make_engine("analytic").build_dynamics(scene, "exact", 0.01).run(n)


def _drifting_scene(duration: float) -> DynamicsScene:
    body = RigidBody("b", 2.0, np.diag([1.0, 2.0, 3.0]), np.array([0.0, 1.0, 2.0]), np.array([1.0, 0, 0, 0]),
                     np.array([3.0, -1.0, 0.5]), np.zeros(3))
    return DynamicsScene("drifting", "a free body drifting", "analytic", (body,), Forces(), duration, (0.01,),
                         ("exact",))


class _DriftingSimulation(PieceSimulation):
    """x = x0 + v t, computed a piece at a time (vectorised: 10^5 steps in milliseconds)."""

    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        self._body, self._dt = scene.bodies[0], dt

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        body = self._body
        for start, stop in piece_bounds(n_steps, samples_per_piece):
            t = np.arange(start, stop) * self._dt
            k = len(t)
            yield Trajectory(t, (body.position_world + t[:, None] * body.velocity_world)[:, None],
                             np.tile(body.quat_wxyz, (k, 1, 1)), np.tile(body.velocity_world, (k, 1, 1)),
                             np.zeros((k, 1, 3)))


class _WholeDriftingSimulation(Simulation):
    """The same motion, returned whole only (an engine written before ``Simulation.stream``)."""

    def __init__(self, scene: DynamicsScene, dt: float) -> None:
        self._moving = _DriftingSimulation(scene, dt)

    def run(self, n_steps: int) -> Trajectory:
        return joined(self._moving.stream(n_steps, n_steps + 1))


class _Drifting(Engine):
    """A synthetic engine whose simulation streams (or, with ``whole``, does not)."""

    def __init__(self, whole: bool = False) -> None:
        self.name, self._whole = ("whole" if whole else "drifting"), whole

    def version(self) -> str:
        return "0"

    def integrators(self) -> tuple[str, ...]:
        return ("exact",)

    def supports_dynamics(self, scene, integrator) -> Support:
        return self.check_integrator(integrator)

    def build_dynamics(self, scene, integrator, dt) -> Simulation:
        return _WholeDriftingSimulation(scene, dt) if self._whole else _DriftingSimulation(scene, dt)

    def supports_kinematics(self, chain) -> Support:
        return Support.no("dynamics only")

    def build_kinematics(self, chain):
        raise NotImplementedError("dynamics only")


def _peak_bytes(engine: Engine, n_steps: int) -> tuple[int, list]:
    """(the peak of Python's and NumPy's allocations [bytes] while one case of ``n_steps`` steps runs, its rows)."""
    scene = _drifting_scene(n_steps * 0.01)
    tracemalloc.start()
    try:
        rows = run_scene(scene, [engine], make_engine, repeats=0)
        return tracemalloc.get_traced_memory()[1], rows
    finally:
        tracemalloc.stop()


@pytest.mark.slow  # ~5 s of CPU: long runs, their memory measured
def test_memory_is_flat_in_the_number_of_steps(monkeypatch):
    """A case of 10^5 steps holds no more than one of 10^4 (its reference, the closed form, streamed beside it),
    and its numbers are right (exact against exact); an engine that returns whole trajectories still runs, its
    memory growing by at least the trajectory it returns (so the measure sees a run held whole), and its detail
    says so."""
    monkeypatch.setattr(streamed, "PIECE_BYTES", TEST_PIECE_BYTES)
    engine = _Drifting()
    assert streams_in_pieces(engine.build_dynamics(_drifting_scene(1.0), "exact", 0.01))
    short, _ = _peak_bytes(engine, 10_000)
    long, rows = _peak_bytes(engine, 100_000)
    assert (long - short) / 90_000 < FLAT_BYTES_PER_STEP, (short, long)
    errors = [r for r in rows if r.engine == "drifting" and r.metric == "position_error_max"]
    assert errors and all(r.status == "ok" and r.value < 1e-9 for r in errors)
    whole = _Drifting(whole=True)
    assert not streams_in_pieces(whole.build_dynamics(_drifting_scene(1.0), "exact", 0.01))
    # A tenth of the streamed runs' steps (still runs of many pieces): a run held whole grows by the same ~580 bytes a
    # step at any length (measured from 10^3 to 10^5 steps), 5.6 times the bound; a streamed one by under 1.
    held_short, _ = _peak_bytes(whole, 1_000)
    held_long, rows = _peak_bytes(whole, 10_000)
    assert (held_long - held_short) / 9_000 > streamed.SAMPLE_BYTES, (held_short, held_long)
    mine = [r for r in rows if r.engine == "whole" and r.metric == "position_error_max"]
    assert mine and all(r.status == "ok" and "its memory grew with the steps" in r.detail for r in mine)


PIECE_SCENES = ("dzhanibekov", "point-force-torque")
"""Free bodies against both kinds of streamed reference (a closed form with Jacobi's elliptic functions, DOP853's
dense output), spinning, one under an applied force and torque, run by every built-in engine."""

TINY_PIECE_SAMPLES = 7
"""Samples per piece of the run in pieces: a scene's :data:`PIECE_STEPS` steps in 8 pieces, its reference streamed
too."""

PIECE_STEPS = 50
"""Steps of each scene run in pieces: 51 samples, 7 whole pieces and a short last one (every piece costs the same,
whatever its length: half a smoke scene's 100 steps halves the test)."""


@pytest.mark.slow
def test_a_run_in_many_pieces_has_the_rows_and_series_of_one_piece(monkeypatch):
    """Every row (timing aside) and every series point of every built-in engine on scenes without planes, run in
    pieces of 7 samples (the reference streamed beside each case) and in one piece: the same bits."""
    scenes = [smoke(builtin(name)) for name in PIECE_SCENES]
    scenes = [dataclasses.replace(scene, dts=scene.dts[-1:], duration=PIECE_STEPS * scene.dts[-1]) for scene in scenes]

    def results():
        out = []
        for scene in scenes:
            series: list = []
            out.append((scene, run_scene(scene, built_engines(), make_engine, repeats=0, series=series), series))
        return comparable(out)

    whole = results()
    bodies = max(len(scene.bodies) for scene in scenes)
    monkeypatch.setattr(streamed, "PIECE_BYTES", TINY_PIECE_SAMPLES * bodies * streamed.SAMPLE_BYTES)
    assert streamed.samples_per_piece(scenes[0]) >= TINY_PIECE_SAMPLES
    assert results() == whole


class _BlowingUp(_DriftingSimulation):
    """The drifting body, its position non-finite from sample 700 on (its second piece): a run that blew up mid-stream."""

    def stream(self, n_steps: int, samples_per_piece: int) -> Iterator[Trajectory]:
        for start, piece in zip(range(0, n_steps + 1, samples_per_piece), super().stream(n_steps, samples_per_piece)):
            position = np.array(piece.position_world)
            position[max(0, 700 - start):] = np.nan
            yield Trajectory(piece.times, position, piece.quat_wxyz, piece.velocity_world, piece.angular_velocity_world)


def test_a_run_that_blows_up_between_pieces_is_diverged(monkeypatch):
    """Found on the way (fast-spinner): a piece with NaN is not read further (its energies would fail), and the case
    is diverged with "non-finite state", as a whole run is, not failed."""
    monkeypatch.setattr(streamed, "PIECE_BYTES", TEST_PIECE_BYTES)
    engine = _Drifting()
    engine.build_dynamics = lambda scene, integrator, dt: _BlowingUp(scene, dt)
    rows = run_scene(_drifting_scene(10.0), [engine], make_engine, repeats=0)
    mine = [r for r in rows if r.engine == "drifting" and r.metric == "position_error_max"]
    assert mine and all(r.status == "diverged" and r.detail.startswith("non-finite state") for r in mine)
