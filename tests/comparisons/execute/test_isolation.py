"""Issue #12: every case runs in a worker process with a time and a memory limit; a case that segfaults, hangs
or allocates without bound becomes failed rows naming the cause, and every other case of the run completes."""

from __future__ import annotations

import dataclasses
import os
import io
import sys
import sysconfig
from pathlib import Path

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes import library
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.execution import run_scenes
from simparity.comparisons.common.processes import BLAS_THREAD_VARIABLES, death_cause, worker_environment
from simparity.comparisons.common import zygote
from simparity.comparisons.execute.isolation import CASE_WORKER, CaseLimits, IsolatedPool
from simparity.comparisons.scenes.library import builtin_paths
from tests.helpers import THROWN_BALL, no_leftovers_within

HANG_SECONDS = 2
"""The hanging engine's limit: long enough for any honest case of the tiny scene (milliseconds; core's and MuJoCo's
cases of one time step all completed at --case-timeout's minimum of 1 s on the 2-core machine loaded by three test
runs), short enough that the hang and slow-start tests wait little (a worker's start and imports do not count against
it: test_a_workers_imports_do_not_count_against_its_first_cases_time_limit)."""

CRASH_SECONDS = 120
"""The limit while the hogging engine runs: far more than it needs to pass its memory limit (~0.4 GB/s of
page faults measured on the 2-core machine under load: ~1 s to CASE_GIB), so it is caught by memory, not by time (a
limit of 10 s, to share one run with the hanging engine, caught it by time on a machine loaded ~4 times over: a run
each)."""

CASE_GIB = 0.5
"""The hogging engine's limit: ~2x what a worker running the tiny scene holds (~250 MiB), reached by the hog in half
the time (and page faults) of 1 GiB."""

HANGING = ("tests.hostile_engines:HangingEngine", f"hung: no result within the per-case time limit of {HANG_SECONDS} s")
CRASHING = {
    "segfaulting": ("tests.hostile_engines:SegfaultingEngine", "killed by signal 11 (SIGSEGV)"),
    "hogging": ("tests.hostile_engines:HoggingEngine", "out of memory: the worker's resident memory went past the "
                f"per-case limit of {CASE_GIB:g} GiB; the worker was killed"),  # exactly: rows are the same in every run
}


@dataclasses.dataclass(frozen=True)
class _Run:
    """What ``simparity run`` gave: its exit code, what it printed and its folder."""

    code: int
    printed: str
    out: Path

    @property
    def table(self) -> pd.DataFrame:
        return pd.read_csv(self.out / "results.csv")


HOSTILE_DTS = (0.01,)
"""The time steps [s] of the tiny scene in the segfault, memory and hang runs: one group, so one worker runs every
engine's cases, core's before the hostile engine's and MuJoCo's after them (in the worker that replaces the killed
one). Each worker killed is replaced at once: the scene's two time steps, two groups on two workers, started four
workers a run for the same property."""


def _throw_file(folder: Path, text: str = THROWN_BALL) -> Path:
    """The tiny scene (:data:`tests.helpers.THROWN_BALL`, or ``text``) written to ``folder``; its path."""
    scene = folder / "throw.toml"
    scene.write_text(text, encoding="utf-8")
    return scene


def _run_throw(folder: Path, engines: str, *options: str, text: str = THROWN_BALL) -> _Run:
    """``simparity run`` of the tiny scene (:data:`tests.helpers.THROWN_BALL`, or ``text``) on ``engines``, without a
    report (no test here reads one), into ``folder``/run."""
    printed = io.StringIO()
    code = main(["run", str(_throw_file(folder, text)), "--engines", engines, "--repeats", "0", "--no-report", *options,
                 "--out", str(folder / "run")], printed)
    return _Run(code, printed.getvalue(), folder / "run")


def _run(tmp_path, hostile: dict, seconds: float) -> _Run:
    """Run the tiny scene on core, MuJoCo and the ``hostile`` engines ({name: (spec, cause)}); check that each hostile
    case failed with its cause, every other case completed, and the run kept its cases for --resume."""
    engines = ",".join(["core"] + [spec for spec, _ in hostile.values()] + ["mujoco"])
    two_steps = "dt = [0.01, 0.005]"
    assert THROWN_BALL.count(two_steps) == 1  # the tiny scene changed: choose its time step anew
    run = _run_throw(tmp_path, engines, "--jobs", "1", "--case-timeout", str(seconds), "--case-memory", str(CASE_GIB),
                     text=THROWN_BALL.replace(two_steps, f"dt = {list(HOSTILE_DTS)}"))
    assert run.code == 1  # failed cases: exit 1, not a crash of the run
    table = run.table
    assert len(table[table.dt.notna()].groupby(["engine", "dt"])) == (2 + len(hostile)) * len(HOSTILE_DTS)  # none lost
    for name, (_, cause) in hostile.items():
        rows = table[(table.engine == name) & table.dt.notna()]
        assert set(rows.status) == {"failed"} and rows.detail.str.contains(cause, regex=False).all(), name
    for honest in ("core", "mujoco"):
        rows = table[(table.engine == honest) & (table.metric == "position_error_max")]
        assert list(rows.status) == ["ok"] * len(HOSTILE_DTS), honest
    assert (run.out / "cases").is_dir()  # kept for --resume, which tries the failed cases again
    return run


@pytest.mark.slow
def test_a_segfault_and_a_memory_blow_up_each_fail_alone(tmp_path):
    run = _run(tmp_path, CRASHING, CRASH_SECONDS)
    assert f"{len(CRASHING) * len(HOSTILE_DTS)} cases did not finish (crashed, hung or out of memory)" in run.printed


@pytest.mark.slow
def test_a_hang_fails_alone(tmp_path):
    _run(tmp_path, {"hanging": HANGING}, HANG_SECONDS)


ONE_WORKER_ENGINES = ("tests.hostile_engines:ExitingEngine", "tests.hostile_engines:MalformedEngine",
                      "tests.hostile_engines:RoundingEngine", "core")
"""Engines run in this order by a single worker: core's cases come after each hostile engine's in the same worker."""


@pytest.fixture(scope="module")
def one_worker_run(tmp_path_factory) -> _Run:
    """One run of the tiny scene on :data:`ONE_WORKER_ENGINES` by one worker, shared by the tests of the exiting,
    malformed and rounding engines (exit 1: the first two's cases fail)."""
    run = _run_throw(tmp_path_factory.mktemp("one-worker"), ",".join(ONE_WORKER_ENGINES), "--jobs", "1")
    assert run.code == 1
    return run


def _core_values(table: pd.DataFrame) -> pd.DataFrame:
    rows = table[(table.engine == "core") & ~table.metric.str.startswith("time_")]
    return rows[["integrator", "dt", "metric", "status", "value"]].reset_index(drop=True)


@pytest.mark.slow
def test_an_engine_that_changes_its_process_cannot_change_another_engines_results(one_worker_run, slow_start_run):
    """The rounding engine switches the FPU to round upward before its cases; core's cases and the reference,
    run after it by the same single worker, are bit-identical to a run without it (core alone, the run of a slow
    worker start: what it changes is when the clock starts, not a value): each engine's cases run in a process of
    their own, forked from a worker no engine's code ran in."""
    alone = _core_values(slow_start_run.table)
    beside = _core_values(one_worker_run.table)
    assert len(alone) > 10 and alone["status"].eq("ok").any()
    pd.testing.assert_frame_equal(alone, beside, check_exact=True)


@pytest.mark.slow
def test_an_engine_that_ends_its_process_quietly_fails_its_case(one_worker_run):
    """os._exit(0) in the middle of a case: failed rows saying so; core, after it in the same worker, completes."""
    table = one_worker_run.table
    exiting = table[(table.engine == "exiting") & table.dt.notna()]
    assert set(exiting.status) == {"failed"}
    assert exiting.detail.str.contains("the case's process exited with code 0 before its cases finished").all()
    core = table[(table.engine == "core") & (table.metric == "position_error_max")]
    assert set(core.status) == {"ok"} and len(core) >= 2


def test_the_cause_of_a_death_names_the_signal_and_where():
    stderr = 'Fatal Python error: Segmentation fault\n\nCurrent thread 0x1 (most recent call first):\n  File "/x/eng.py", line 7 in run\n'
    assert death_cause(-11, stderr) == 'crashed: the worker was killed by signal 11 (SIGSEGV), in File "/x/eng.py", line 7 in run'
    ctypes_frame = f'File "{sysconfig.get_paths()["stdlib"]}/ctypes/__init__.py", line 519 in string_at'
    in_ctypes = f'Fatal Python error: Segmentation fault\n\nCurrent thread 0x1 (most recent call first):\n  {ctypes_frame}\n  File "/x/eng.py", line 7 in run\n'
    assert death_cause(-11, in_ctypes, "the case's process") == (
        f"crashed: the case's process was killed by signal 11 (SIGSEGV), in {ctypes_frame}, called from File "
        '"/x/eng.py", line 7 in run')
    assert "out-of-memory killer" in death_cause(-9, "")
    assert death_cause(1, "Traceback ...\nValueError: bad\n") == "crashed: the worker exited with code 1: ValueError: bad"


@pytest.mark.parametrize("option, value", [("--case-timeout", "0"), ("--case-timeout", "nan"), ("--case-memory", "-1"),
                                           ("--case-memory", "inf")])
def test_limits_out_of_range_are_one_line_errors(option, value, capsys, tmp_path):
    assert main(["run", "lecture-projectile", option, value, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and option in err and "allowed" in err


@pytest.mark.slow
def test_a_trajectory_that_cannot_be_measured_fails_with_the_error_not_as_a_crash(one_worker_run):
    table = one_worker_run.table
    rows = table[(table.engine == "malformed") & table.dt.notna()]
    assert set(rows.status) == {"failed"}
    assert rows.detail.str.contains("its trajectory does not sample the scene: run() returned a value of type dict",
                                    regex=False).all()


@pytest.mark.slow
def test_two_engines_or_two_scenes_of_one_name_are_refused(tmp_path, capsys):
    twins = "tests.hostile_engines:HangingEngine,tests.hostile_engines:HangingTwin"
    assert main(["run", "lecture-projectile", "--engines", twins, "--out", str(tmp_path / "a")]) == 2
    assert "are both named hanging" in capsys.readouterr().err
    copy = tmp_path / "wind.toml"
    copy.write_text(builtin_paths()["wind"].read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["run", "wind", str(copy), "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "a second scene named wind" in err and err.count("\n") == 1
    for key, values in (("body[ball].mass", "[1.0, 2.0]"), ("simulation.duration", "[0.5, 1.0]")):
        (tmp_path / f"{key}.toml").write_text(THROWN_BALL + f'[sweep]\n"{key}" = {values}\n', encoding="utf-8")
    assert main(["run", str(tmp_path / "body[ball].mass.toml"), str(tmp_path / "simulation.duration.toml"),
                 "--out", str(tmp_path / "c")]) == 2  # variants of distinct names, but one sweep name: "throw"
    err = capsys.readouterr().err
    assert "a second sweep named throw" in err and err.count("\n") == 1


def test_the_cause_of_an_exit_is_the_exit_code_and_the_error():
    stderr = 'Traceback (most recent call last):\n  File "/a.py", line 1, in main\n  File "/b.py", line 9, in f\nKeyError: 3\n'
    assert death_cause(1, stderr) == 'crashed: the worker exited with code 1: KeyError: 3 (File "/b.py", line 9, in f)'


def test_workers_use_one_blas_thread_whatever_the_user_set(monkeypatch):
    """Determinism across worker counts rests on it: a sum split over BLAS threads rounds differently."""
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "8")
    env = worker_environment()
    assert all(env[variable] == "1" for variable in BLAS_THREAD_VARIABLES)


@pytest.mark.slow
def test_what_an_engine_starts_and_leaves_running_ends_with_its_cases(tmp_path):
    """An engine that starts a process in every case and never stops it: the processes are killed when its
    cases end, while the pool's workers live on (as a Dask worker's pool does between tasks)."""
    engines = [make_engine("core"), make_engine("tests.hostile_engines:ForkingEngine")]
    with IsolatedPool(1, CaseLimits.default(1)) as pool:  # one worker: the forking engine's cases after core's
        [(_, rows, _)] = run_scenes(library.load([str(_throw_file(tmp_path))]), engines, make_engine, 0, pool,
                                    specs={"forking": "tests.hostile_engines:ForkingEngine"})
        assert {r.status for r in rows if r.engine == "forking" and r.metric == "position_error_max"} == {"ok"}
        assert no_leftovers_within()


SLOW_IMPORT_SECONDS = HANG_SECONDS + 1
"""A worker's start made longer than the case time limit (a machine loaded many times over, a cold disk): its imports
must not count against the first case handed to it."""


@pytest.fixture(scope="module")
def slow_start_run(tmp_path_factory) -> _Run:
    """One run of the tiny scene on core alone by one worker whose start (a ``sitecustomize`` that sleeps) takes
    longer than the per-case limit, shared by the test of slow starts and, as the run without a hostile engine, by
    the test of the rounding engine."""
    folder = tmp_path_factory.mktemp("slow-start")
    slow = folder / "slow-start"
    slow.mkdir()
    (slow / "sitecustomize.py").write_text(f"import time\ntime.sleep({SLOW_IMPORT_SECONDS})\n", encoding="utf-8")
    with pytest.MonkeyPatch.context() as monkeypatch:
        monkeypatch.syspath_prepend(str(slow))  # a worker's import path is this process's (worker_environment)
        return _run_throw(folder, "core", "--jobs", "1", "--case-timeout", str(HANG_SECONDS))


@pytest.mark.slow
def test_a_workers_imports_do_not_count_against_its_first_cases_time_limit(slow_start_run):
    """The worker (started when its first job is handed over) takes longer to import than the per-case limit; its
    cases, milliseconds each, complete: the clock starts when it says it is ready (before: every case 'hung')."""
    run = slow_start_run
    assert run.code == 0, run.printed
    assert set(run.table[run.table.dt.notna()].status) <= {"ok", "n/a"}


def _live_workers() -> int:
    """Case workers of this process still alive (not zombies): its children started as case workers, and the children
    of its zygotes (each forked to be a worker or a probe; no probe runs here)."""
    processes = _processes()
    zygotes = {pid for pid, (_, parent, command) in processes.items()
               if parent == os.getpid() and command.startswith(ZYGOTE_COMMAND)}
    return sum(1 for state, parent, command in processes.values()
               if state != "Z" and (parent in zygotes or (parent == os.getpid() and CASE_WORKER in command)))


ZYGOTE_COMMAND = f"{sys.executable} -m {zygote.__name__}"


def _processes() -> dict[int, tuple[str, int, str]]:
    """Every process: {pid: (state, parent pid, command line with spaces)}."""
    found = {}
    for entry in Path("/proc").iterdir():
        try:
            stat = (entry / "stat").read_text()
            fields = stat[stat.rindex(")") + 2:].split()
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            found[int(entry.name)] = (fields[0], int(fields[1]), command)
        except (OSError, ValueError):  # not a process, or one that ended while read
            continue
    return found


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="counts processes through Linux's /proc")
def test_a_worker_killed_for_the_last_case_is_not_replaced_for_nothing(tmp_path):
    """The hanging engine's case, the run's last, kills the only worker: no job waits, so no worker is started in its
    place (before: one, started for nothing); core's case before it completed in that worker."""
    engines = [make_engine("core"), make_engine(HANGING[0])]
    scene = _throw_file(tmp_path, THROWN_BALL.replace("dt = [0.01, 0.005]", f"dt = {list(HOSTILE_DTS)}"))
    with IsolatedPool(1, CaseLimits(HANG_SECONDS, None)) as pool:
        [(_, rows, _)] = run_scenes(library.load([str(scene)]), engines, make_engine, 0, pool,
                                    specs={"hanging": HANGING[0]})
        assert _live_workers() == 0
    finished = {r.engine: r.status for r in rows if r.metric == "position_error_max"}
    assert finished == {"core": "ok", "hanging": "failed"}
