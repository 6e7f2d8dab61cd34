"""Issue #12: ``--executor dask`` runs the cases on a Dask distributed cluster (here a LocalCluster of two
workers on the loopback interface) and gives results identical to the local executor."""

from __future__ import annotations

import dataclasses
import socketserver
import threading
import time

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.execute import dask_executor
from simparity.comparisons.execute.dask_executor import DaskExecutor
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.execution import run_scenes
from simparity.comparisons.scenes import library
from simparity.comparisons.execute.isolation import CaseLimits, IsolatedPool
from simparity.core.model.errors import SimparityError
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.results import RESULTS_FILE
from tests.helpers import (LEAN_INTEGRATORS, THROWN_BALL, InProcess, built_engines, comparable, no_leftovers_within,
                           smoke_scenes)

WORKERS = 2

QUIET = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s"}
"""Dask diagnostics the shared cluster goes without (read by no test; they do not touch what a task computes): each
worker's statistical profiler (a stack sample every 10 ms) and every process's blocked-event-loop check (every
20 ms). Measured: an idle cluster of 2 workers took 0.10 CPU-s a second with them, 0.02 without."""

EXECUTOR_IK_ITERATIONS = 30
"""max_iterations of the IK smoke scene run on both executors: what is compared is how the rows and series come
back, not how far a solver gets. At 30 the 2-link arm's solvers still solve 40-100 % of its targets and fail the
rest, as at the scene's 200 (measured), where the IK scene was most of the test's runs."""


def _mixed_scenes():
    """The smoke scenes of every kind (:func:`tests.helpers.smoke_scenes`), IK capped at
    :data:`EXECUTOR_IK_ITERATIONS` iterations, dynamics on :data:`tests.helpers.LEAN_INTEGRATORS` (every engine still
    has cases of each dynamics scene; the projectile and the rotating body cost half as much, ~1.5 CPU-s of the two
    runs)."""
    def lean(scene):
        if isinstance(scene, IKScene):
            return dataclasses.replace(scene, max_iterations=EXECUTOR_IK_ITERATIONS)
        return dataclasses.replace(scene, integrators=LEAN_INTEGRATORS) if hasattr(scene, "integrators") else scene
    return [lean(scene) for scene in smoke_scenes()]


REGISTERED = 60
"""[s] The longest a worker may take to register with the scheduler again (a loaded CI machine once showed 0 workers
registered right after a run whose results were right)."""


@pytest.fixture(scope="module")
def dask():
    """A LocalCluster of :data:`WORKERS` workers shared by the module's tests. Its scheduler allows no retry of a task
    whose worker was lost (the default retries it 3 times): a lost group fails at once, as
    test_a_group_lost_for_good_fails_only_the_cases_that_never_came_back needs; no other test loses a Dask worker.
    Its processes run without the diagnostics of :data:`QUIET`."""
    import dask.config
    import distributed  # noqa: F401 - its defaults loaded before the setting below (unset, it would drop them all)

    with dask.config.set({"distributed.scheduler.allowed-failures": 0, **QUIET}):
        executor = DaskExecutor(None, WORKERS, CaseLimits.default(WORKERS))
    yield executor
    executor.close()


@pytest.mark.slow
def test_a_local_dask_cluster_gives_the_results_of_this_process(dask):
    scenes = _mixed_scenes()
    expected = list(run_scenes(scenes, built_engines(), make_engine, 0, InProcess()))
    got = list(run_scenes(scenes, built_engines(), make_engine, 0, dask))
    assert [s.name for s, _, _ in got] == [s.name for s in scenes]
    assert comparable(got) == comparable(expected)
    dask.client.wait_for_workers(WORKERS, timeout=REGISTERED)  # a nanny's restart under load re-registers its worker
    assert len(dask.client.scheduler_info()["workers"]) == WORKERS
    assert all(address.startswith("tcp://127.0.0.1:") for address in dask.client.scheduler_info()["workers"])


@pytest.mark.slow
def test_a_crash_on_a_dask_worker_fails_its_case_alone(dask):
    scenes = smoke_scenes(("lecture-projectile",))
    engines = built_engines(("core",)) + [make_engine("tests.hostile_engines:SegfaultingEngine")]
    specs = {"segfaulting": "tests.hostile_engines:SegfaultingEngine"}
    [(_, rows, _)] = run_scenes(scenes, engines, make_engine, 0, dask, specs=specs)
    by_engine = {e: {r.status for r in rows if r.engine == e and r.dt == r.dt} for e in ("core", "segfaulting")}
    assert by_engine["core"] == {"ok", "n/a"} and by_engine["segfaulting"] <= {"failed", "n/a"}
    failed = [r for r in rows if r.engine == "segfaulting" and r.status == "failed"]
    assert failed and all("SIGSEGV" in r.detail for r in failed)  # n/a: integrators it refuses before running


@pytest.mark.slow
def test_the_cli_runs_on_dask_and_writes_the_local_executor_results(tmp_path, dask):
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL, encoding="utf-8")
    # One small dynamics scene: this test is of the command's --executor dask (its executor, its results.csv);
    # scenes of every kind on Dask against this process are test_a_local_dask_cluster_gives_the_results_of_this_process
    # (a cluster of WORKERS workers). No report (the test reads results.csv); one worker process. The command runs on
    # the module's cluster, named by --scheduler (no second cluster: starting one cost a few CPU-s); the LocalCluster
    # the command starts without --scheduler is the fixture's, DaskExecutor(None, ...), the same call.
    args = ["run", str(scene), "--quick", "--no-report", "--jobs", "1"]
    assert main(args + ["--out", str(tmp_path / "local")]) == 0
    on_dask = ["--executor", "dask", "--scheduler", dask.client.scheduler.address]
    assert main(args + on_dask + ["--out", str(tmp_path / "dask")]) == 0
    tables = [pd.read_csv(tmp_path / name / RESULTS_FILE, dtype=str, keep_default_na=False) for name in ("local", "dask")]
    for table in tables:
        table.loc[table.metric.str.startswith("time_"), "value"] = "timing"
    pd.testing.assert_frame_equal(*tables)


UNREACHABLE_SECONDS = 10.0
"""A refused connection fails at once; this allows for the imports of a loaded machine (before: Dask's 30 s)."""

SHORT_IDENTIFY_SECONDS = 2.0
"""How long the tests give a server to say it is a Dask scheduler (a scheduler answers in milliseconds): the banner's
bytes are read within it, so what is told is Dask's protocol error, not the end of the wait."""

SILENT_IDENTIFY_SECONDS = 0.5
"""The same for the silent server, which never answers: the test waits all of it, and what it tells (the wait ends,
in one line) holds whatever its length."""


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:9", "127.0.0.1:9", "no-port-here"])
def test_an_unreachable_scheduler_is_a_one_line_error_at_once_and_makes_no_folder(tmp_path, capsys, address):
    out = tmp_path / "run"
    start = time.monotonic()
    assert main(["run", "lecture-projectile", "--executor", "dask", "--scheduler", address, "--out", str(out)]) == 2
    assert time.monotonic() - start < UNREACHABLE_SECONDS
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot reach a Dask scheduler" in err
    assert not out.exists()


class _NotDask(socketserver.BaseRequestHandler):
    """A service that is not Dask: a banner (as SSH sends), or silence until the client speaks HTTP."""

    banner = b""

    def handle(self) -> None:
        if self.banner:
            self.request.sendall(self.banner)
        else:
            self.request.recv(1 << 16)
            time.sleep(UNREACHABLE_SECONDS)  # a web server waiting for the rest of a request


class _NotDaskServer(socketserver.ThreadingTCPServer):
    """Its handlers' threads are not waited for when it closes: the silent one sleeps on after the client gave up."""

    daemon_threads = True
    block_on_close = False


@pytest.mark.parametrize("banner, identify_seconds", [(b"SSH-2.0-OpenSSH_9.6 not dask\r\n" * 4, SHORT_IDENTIFY_SECONDS),
                                                      pytest.param(b"", SILENT_IDENTIFY_SECONDS, marks=pytest.mark.slow)])
def test_a_service_that_is_not_dask_at_the_scheduler_address_is_a_one_line_error(tmp_path, capsys, monkeypatch,
                                                                                   banner, identify_seconds):
    """Dask's own client raised a MemoryError from the banner's bytes read as a frame length, and waited for ever
    on a silent server (a web server: the dashboard's port given by mistake)."""
    monkeypatch.setattr(dask_executor, "IDENTIFY_SECONDS", identify_seconds)
    handler = type("Handler", (_NotDask,), {"banner": banner})
    with _NotDaskServer(("127.0.0.1", 0), handler) as server:
        threading.Thread(target=server.serve_forever, daemon=True).start()
        out = tmp_path / "run"
        address = f"tcp://127.0.0.1:{server.server_address[1]}"
        start = time.monotonic()
        assert main(["run", "lecture-projectile", "--executor", "dask", "--scheduler", address, "--out", str(out)]) == 2
        assert time.monotonic() - start < UNREACHABLE_SECONDS
        server.shutdown()
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot reach a Dask scheduler: something listens there but" in err
    assert not out.exists()


@pytest.mark.slow
def test_a_running_scheduler_is_reached_and_a_worker_address_is_refused(dask):
    """A real cluster's scheduler, named by its address, takes the run (and its memory limits are its nodes')."""
    scheduler = DaskExecutor(dask.client.scheduler.address, WORKERS, CaseLimits(60.0, None))
    try:
        assert scheduler.client.scheduler_info()["workers"].keys() == dask.client.scheduler_info()["workers"].keys()
    finally:
        scheduler.close()
    worker = next(iter(dask.client.scheduler_info()["workers"]))
    with pytest.raises(SimparityError, match="a Dask Worker answers there, not a scheduler"):
        DaskExecutor(worker, WORKERS, CaseLimits(60.0, None))


def test_a_scheduler_without_dask_is_refused(tmp_path, capsys):
    assert main(["run", "lecture-projectile", "--scheduler", "tcp://127.0.0.1:8786", "--out", str(tmp_path)]) == 2
    assert "--executor dask" in capsys.readouterr().err


SWEEP = THROWN_BALL + """
[sweep]
"body[ball].velocity_world[0]" = {start = 0.0, stop = 9.0, num = 10}
"world.gravity_world[2]" = {start = -10.0, stop = -1.0, num = 10}
"""


@pytest.mark.slow
@pytest.mark.sweep  # a sweep of 100 variants, run twice: with the metamorphic sweep in .ci/run, not the default run
def test_a_sweep_of_100_variants_on_two_dask_workers_gives_the_local_results(tmp_path, dask):
    """Issue #12's done-when: 100 scene variants on a local Dask cluster of 2 workers give, bit for bit, the
    results of the local executor's 2 worker processes."""
    scene = tmp_path / "throw.toml"
    scene.write_text(SWEEP, encoding="utf-8")
    variants = library.load([str(scene)])
    assert len(variants) == 100 and len({v.name for v in variants}) == 100
    engines = built_engines(("core", "mujoco"))
    with IsolatedPool(WORKERS, CaseLimits.default(WORKERS)) as pool:
        local = list(run_scenes(variants, engines, make_engine, 0, pool))
    on_dask = list(run_scenes(variants, engines, make_engine, 0, dask))
    assert comparable(on_dask) == comparable(local)
    assert [s.name for s, _, _ in on_dask] == [v.name for v in variants]


STREAM_LIMIT_SECONDS = 3.0
"""The per-case time limit of the streaming test: the hanging case fails this long after it starts. Core's case of
the tiny scene takes milliseconds (its cases completed at --case-timeout's minimum of 1 s on the loaded 2-core
machine; a worker's start does not count against the limit), so it arrives ~3 s before the hanging case fails, and
sent group by group both would arrive together: the half-limit margin of the test tells the two apart."""


@pytest.mark.slow
def test_cases_stream_back_one_by_one_while_their_group_still_runs(tmp_path, dask):
    """A finished case comes back (and is journaled) while a later case of its group still runs: core's case
    arrives a good part of the time limit before the hanging engine's case of the same group fails (sent
    group by group, both would arrive together)."""
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL.replace("dt = [0.01, 0.005]", "dt = [0.01]"), encoding="utf-8")
    engines = built_engines(("core",)) + [make_engine("tests.hostile_engines:HangingEngine")]
    specs = {"hanging": "tests.hostile_engines:HangingEngine"}
    arrivals = {}
    kept, dask.limits = dask.limits, CaseLimits(STREAM_LIMIT_SECONDS, None)
    try:
        [(_, rows, _)] = run_scenes(library.load([str(scene)]), engines, make_engine, 0, dask, specs=specs,
                                    on_case=lambda s, engine, i: arrivals.setdefault(engine, time.monotonic()))
    finally:
        dask.limits = kept
    assert {r.status for r in rows if r.engine == "core"} == {"ok"}
    assert all(r.status == "failed" and r.detail.startswith("hung:") for r in rows if r.engine == "hanging")
    assert arrivals["hanging"] - arrivals["core"] > STREAM_LIMIT_SECONDS / 2


@pytest.mark.slow
def test_a_group_lost_for_good_fails_only_the_cases_that_never_came_back(tmp_path, dask):
    """A lost node (here: a case kills its Dask worker, and the cluster allows no retry) fails the cases of its
    group that were not back yet, with the cause; the cases already back keep their results."""
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL.replace("dt = [0.01, 0.005]", "dt = [0.01]"), encoding="utf-8")
    engines = built_engines(("core",)) + [make_engine("tests.hostile_engines:HostKillingEngine")]
    specs = {"host-killing": "tests.hostile_engines:HostKillingEngine"}
    [(_, rows, _)] = run_scenes(library.load([str(scene)]), engines, make_engine, 0, dask, specs=specs)
    assert {r.status for r in rows if r.engine == "core"} == {"ok"}
    lost = [r for r in rows if r.engine == "host-killing"]
    assert lost and all(r.status == "failed" and "the Dask task was lost: KilledWorker" in r.detail for r in lost)


@pytest.mark.slow
def test_what_an_engine_starts_and_leaves_running_ends_with_its_cases_on_dask(tmp_path, dask):
    """A Dask worker keeps its pool between tasks, so nothing closes it after a run: the processes an engine
    started and left running are killed when its cases end (held-out test: they were orphaned)."""
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL, encoding="utf-8")
    engines = [make_engine("core"), make_engine("tests.hostile_engines:ForkingEngine")]
    [(_, rows, _)] = run_scenes(library.load([str(scene)]), engines, make_engine, 0, dask,
                                specs={"forking": "tests.hostile_engines:ForkingEngine"})
    assert {r.status for r in rows if r.engine == "forking" and r.metric == "position_error_max"} == {"ok"}
    assert no_leftovers_within()
