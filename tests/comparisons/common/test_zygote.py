"""Workers and probes forked from one zygote per process: each as a fresh interpreter would be (the environment,
folder and import path of its request), its exit status and its resources reported, a dead zygote replaced."""

from __future__ import annotations

import os
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.common import zygote
from simparity.comparisons.engines.probe import probe_engines
from simparity.comparisons.execute.isolation import CASE_WORKER
from simparity.core.inhouse import InHouseEngine

MARK = "SIMPARITY_ZYGOTE_TEST_MARK"

BURN_SECONDS = 0.3
"""CPU time [s] the engine below spends as it is described: far above what an idle forked probe spends (~10 ms)."""

BALLAST = "SIMPARITY_ZYGOTE_TEST_BALLAST"
"""Names the memory [bytes] it touches as it is described."""

MORE_BYTES = 64 * 1024 ** 2
"""How much more than any child before it the probe below holds [bytes]."""

SPEC = "tests.comparisons.common.test_zygote"


class EnvironmentEngine(InHouseEngine):
    """Says, as its version, what its process was given: the marked variable, its folder and its parent's pid."""

    name = "environment"

    def version(self) -> str:
        return f"{os.environ.get(MARK, 'unset')}|{os.getcwd()}|{os.getppid()}"


class BurningEngine(InHouseEngine):
    """Spends :data:`BURN_SECONDS` of CPU and holds the bytes :data:`BALLAST` names as it is described."""

    name = "burning"

    def version(self) -> str:
        ballast = np.ones(int(os.environ[BALLAST]) // 8)  # written, so resident
        start = time.process_time()
        while time.process_time() - start < BURN_SECONDS:
            pass
        return f"{ballast.sum():.0f}"


def _described(monkeypatch) -> tuple[str, str, int]:
    """(mark, folder, parent pid) of a probe of :class:`EnvironmentEngine` asked now."""
    spec = f"{SPEC}:EnvironmentEngine"
    mark, folder, parent = probe_engines([spec])[spec].version().split("|")
    return mark, folder, int(parent)


def _command(pid: int) -> str:
    return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads parents' command lines in Linux's /proc")
def test_processes_forked_one_after_another_share_a_zygote_and_each_sees_its_requests_environment(monkeypatch):
    monkeypatch.setenv(MARK, "first")
    first = _described(monkeypatch)
    monkeypatch.setenv(MARK, "second")
    second = _described(monkeypatch)
    assert (first[0], second[0]) == ("first", "second")  # the environment of the request, not of the zygote's start
    assert first[2] == second[2] != os.getpid()  # one zygote forked both
    assert f"-m {zygote.__name__} " in _command(first[2])


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads parents' command lines in Linux's /proc")
def test_another_folder_gets_a_zygote_of_its_own_and_a_dead_zygote_is_replaced(monkeypatch, tmp_path):
    folder = os.getcwd()
    _, here, parent = _described(monkeypatch)
    monkeypatch.chdir(tmp_path)
    _, there, other = _described(monkeypatch)
    assert (here, there) == (folder, str(tmp_path.resolve())) and other != parent  # ``-m`` puts the folder on the path
    os.kill(other, signal.SIGKILL)
    _, _, replacing = _described(monkeypatch)
    assert replacing not in (other, parent, os.getpid())


@pytest.mark.slow  # after a run's workers, the probe touches more memory than the largest of them: a second or more
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="ru_maxrss in KiB: Linux")
def test_what_a_forked_process_used_counts_once_it_has_exited(monkeypatch):
    """Without the zygote's reports a process it forked is in no usage of this one until the zygote itself is reaped:
    a run would record no worker's peak memory, and a test's CPU time would leave its workers out."""
    before = zygote.children_usage()
    monkeypatch.setenv(BALLAST, str(before.max_resident_bytes + MORE_BYTES))
    probe_engines([f"{SPEC}:BurningEngine"])
    after = zygote.children_usage()
    assert after.cpu_seconds - before.cpu_seconds >= BURN_SECONDS
    assert after.max_resident_bytes >= before.max_resident_bytes + MORE_BYTES


def test_only_the_preloaded_modules_are_run():
    with tempfile.TemporaryFile() as stderr:
        process = zygote.start("os", None, stderr, ())
        assert process.wait() == 1
        stderr.seek(0)
        assert "os is not one the zygote runs" in stderr.read().decode()


def test_where_no_zygote_can_start_a_fresh_interpreter_runs_the_process(monkeypatch):
    """macOS has no SOCK_SEQPACKET socket pairs: the worker starts as ``python -m`` and runs as it always did."""
    def no_pair(*args, **kwargs):
        raise OSError("socket type not supported")

    monkeypatch.setattr(zygote, "_zygotes", {})
    monkeypatch.setattr(zygote.socket, "socketpair", no_pair)
    child_reads, parent_writes = os.pipe()
    parent_reads, child_writes = os.pipe()
    with tempfile.TemporaryFile() as stderr:
        process = zygote.start(CASE_WORKER, None, stderr, (child_reads, child_writes))
        for fd in (child_reads, child_writes, parent_writes):  # its inbox closed: it says it is ready, then exits
            os.close(fd)
        with os.fdopen(parent_reads, "rb") as outbox:
            ready = outbox.read()
        assert isinstance(process, subprocess.Popen) and process.wait() == 0 and b"ready" in ready
