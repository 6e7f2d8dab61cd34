"""The progress bar: drawn only on a terminal, with counts and the time left (every case is counted whichever
process ran it: tests/test_execution.py)."""

import io

from simparity.comparisons.execute.progress import ProgressBar


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
    assert "2/4 cases · wind · mujoco euler" in text and "0m20s left" in text   # 20 s for 2, 2 to go
    bar.clear()
    assert stream.getvalue().endswith("\r\033[K")


def test_nothing_is_drawn_when_not_on_a_terminal():
    stream = io.StringIO()
    bar = ProgressBar(3, stream)
    bar.case_done("wind", "core", "rk4")
    bar.scene_done(3)
    assert stream.getvalue() == "" and not bar.active and bar.done == 3
