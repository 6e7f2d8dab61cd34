"""The progress bar: drawn on a terminal, with counts and the time left; elsewhere (a CI log) a plain heartbeat line
after each silence of HEARTBEAT_SECONDS (every case is counted whichever process ran it:
tests/comparisons/execute/test_execution.py; a piped run's lines as they come:
tests/comparisons/cli/test_progress_lines.py)."""

import io
import threading

import pytest

from simparity.comparisons.execute.estimate import RunEstimate
from simparity.comparisons.execute.progress import ProgressBar


@pytest.fixture(autouse=True)
def _wide_terminal(monkeypatch):
    """The bar is cut to the terminal's width (COLUMNS first): a wide one shows the whole line."""
    monkeypatch.setenv("COLUMNS", "200")


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_bar_shows_counts_scene_and_time_left_on_a_terminal():
    clock = iter([0.0, 10.0, 20.0]).__next__   # start, then two cases 10 s apart
    stream = _Terminal()
    bar = ProgressBar(4, stream, clock=clock)
    bar.case_done("wind", "core", "rk4")
    bar.case_done("wind", "mujoco", "euler")
    text = stream.getvalue().split("\r")[-1]
    assert "2/4 cases · wind · mujoco euler" in text and "20s left" in text   # 20 s for 2, 2 to go
    bar.clear()
    assert stream.getvalue().endswith("\r\033[K")


def test_no_bar_is_drawn_when_not_on_a_terminal_and_a_scene_counts_its_cases_once():
    stream = io.StringIO()
    bar = ProgressBar(5, stream)
    bar.case_done("wind", "core", "rk4")
    bar.scene_done("wind", 3)   # its other cases were not reported one by one (a failed reference)
    bar.case_done("drag", "core", "rk4")
    bar.scene_done("drag", 2)
    assert stream.getvalue() == "" and not bar.active and bar.done == 5


def test_a_silent_run_off_a_terminal_says_how_far_it_is_in_a_plain_line():
    """Issue #41: in a CI log, a long scene is not a long silence; the line has no carriage return or ANSI code."""
    times = iter([0.0, 10.0, 29.0, 30.0, 40.0, 59.0, 70.0])
    stream = io.StringIO()
    bar = ProgressBar(4, stream, clock=lambda: next(times), heartbeat=30.0)   # starts at 0
    bar.case_done("wind", "core", "rk4")          # 10 s: one of 4 cases done
    bar.beat()                                    # 29 s: not yet silent for 30 s
    assert stream.getvalue() == ""
    bar.beat()                                    # 30 s
    assert stream.getvalue() == "progress: 1/4 cases · 30s elapsed · 1m30s left\n"
    bar.scene_done("wind", 1)                     # 40 s: a scene line is said
    bar.beat()                                    # 59 s: 19 s after it
    assert stream.getvalue().count("\n") == 1
    bar.beat()                                    # 70 s: 30 s after it
    assert stream.getvalue().splitlines()[-1].startswith("progress: 1/4 cases · 1m10s elapsed")
    assert "\r" not in stream.getvalue() and "\033" not in stream.getvalue()


def test_the_heartbeat_runs_on_its_own_while_the_cases_do():
    """No case needs to finish for the heartbeat to beat: a thread of its own, stopped when the bar closes."""
    written = threading.Event()

    class Log(io.StringIO):
        def flush(self) -> None:
            written.set()

    stream = Log()
    with ProgressBar(2, stream, heartbeat=0.01):
        assert written.wait(timeout=10.0)
    assert stream.getvalue().startswith("progress: 0/2 cases")
    assert not [t for t in threading.enumerate() if t.name == "simparity-heartbeat"]


def test_no_heartbeat_on_a_terminal_where_the_bar_moves():
    stream = _Terminal()
    bar = ProgressBar(2, stream, clock=iter([0.0, 100.0]).__next__, heartbeat=1.0)
    bar.beat()
    assert stream.getvalue() == ""


def test_time_left_is_the_modelled_cost_still_to_run_at_the_pace_measured():
    """Issue #39: a cheap case done in 10 s, a case modelled 99 x costlier to go: 990 s left, not 10 s."""
    clock = iter([0.0, 10.0]).__next__
    stream = _Terminal()
    costs = {("chain", "pinocchio", "recursive"): 1.0, ("chain", "core", "jacobian_sum"): 99.0}
    bar = ProgressBar(2, stream, clock=clock, estimate=RunEstimate(2, 99.0, 2, 100.0, by_case=costs))
    bar.case_done("chain", "pinocchio", "recursive")
    assert "1/2 cases" in stream.getvalue() and "16m30s left" in stream.getvalue()
