"""Shared test set-up: runs the tests make never touch the user's run history, and the inner loop stays fast."""

import os
import time
from collections import Counter

import pytest

from simparity.comparisons.common.zygote import children_usage
from simparity.comparisons.gate.history import HISTORY_ENV

UNMARKED_CPU_SECONDS_MAX = 3.0
"""CPU seconds (this process's and the child processes it waited for: worker pools, `simparity` subprocesses) a test
not marked ``slow`` may spend in its set-up and call. The marker's own definition (pyproject's markers) is "a second or
more"; the tests measured over ~1.2 s here are marked, and three seconds leaves them room on a machine up to ~2.5 times
slower (a fresh CI machine), so a test near a second does not flip from one machine to the next. CPU time, not the clock: a
machine loaded by other work does not make a test slow. A child still running when the test ends is not counted."""
UNMARKED_WALL_SECONDS_MAX = 60.0
"""Seconds by the clock an unmarked test may take (a test that waits spends no CPU): the inner loop's whole budget
(README, "under a minute"), which no single test of it may use up, even on a machine loaded several times over."""
_SPENT = pytest.StashKey[list]()


@pytest.fixture(autouse=True)
def _private_history(tmp_path_factory, monkeypatch):
    """Every test records runs into its own history database, not simparity-results/ in the checkout."""
    monkeypatch.setenv(HISTORY_ENV, str(tmp_path_factory.mktemp("history") / "history.sqlite"))


def _cpu_and_wall_seconds() -> tuple[float, float]:
    """CPU [s] of this process and its ended children (case workers forked by the zygote included), and the clock [s]."""
    times = os.times()
    return times.user + times.system + children_usage().cpu_seconds, time.perf_counter()


def _measured(item):
    """Adds what the wrapped phase of ``item`` spent to ``item.stash[_SPENT]`` ([CPU s, wall s])."""
    cpu, wall = _cpu_and_wall_seconds()
    try:
        return (yield)
    finally:
        spent = item.stash.setdefault(_SPENT, [0.0, 0.0])
        now_cpu, now_wall = _cpu_and_wall_seconds()
        spent[0] += now_cpu - cpu
        spent[1] += now_wall - wall


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item):
    return (yield from _measured(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item):
    return (yield from _measured(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    """A passing test not marked ``slow`` that spent more than the limits above fails, naming the marker to add."""
    report = yield
    if call.when == "call" and report.passed and item.get_closest_marker("slow") is None:
        cpu, wall = item.stash.get(_SPENT, [0.0, 0.0])
        if cpu > UNMARKED_CPU_SECONDS_MAX or wall > UNMARKED_WALL_SECONDS_MAX:
            report.outcome = "failed"
            report.longrepr = (
                f"{item.nodeid} took {cpu:.1f} s of CPU and {wall:.1f} s by the clock (set-up and call), more than an"
                f" unmarked test may ({UNMARKED_CPU_SECONDS_MAX} s of CPU, {UNMARKED_WALL_SECONDS_MAX} s by the clock,"
                ' tests/conftest.py): mark it @pytest.mark.slow, or make it faster, so `python -m pytest -m "not slow"`'
                " stays the inner loop"
            )
    return report


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items):
    """Files holding the most ``slow`` tests first, each file's tests in their own order. With ``--dist loadfile``
    a file is one worker's serial job, handed out in this order (pyproject's ``--no-loadscope-reorder``): the long
    files start at once, and the many short ones fill in after them, so the two workers end together instead of one
    starting a long file when the other is nearly done. Runs after ``-m`` deselected what it deselects."""
    slow = Counter(item.path for item in items if item.get_closest_marker("slow") is not None)
    first_seen = {path: index for index, path in enumerate(dict.fromkeys(item.path for item in items))}
    items.sort(key=lambda item: (-slow[item.path], first_seen[item.path]))
