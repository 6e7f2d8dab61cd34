"""Issue #41: a run ends with where its wall time went (the profile BENCHMARKS.md wants): cases, storing, the report,
and the rest of the command's total."""

from simparity.comparisons.pipeline.session import WallSplit


def test_the_rest_is_what_the_parts_leave_of_the_total():
    line = WallSplit(cases=60.0, storing=2.5, report=20.0).line(total=90.0)
    assert line.startswith("wall time by part: cases 60.0 s, storing 2.5 s, report 20.0 s, the rest 7.5 s (")


def test_the_rest_is_never_negative():
    """The parts are timed inside the command's total; rounding of the clocks never makes the rest below zero."""
    assert "the rest 0.0 s" in WallSplit(cases=1.0, storing=0.5, report=0.0).line(total=1.4)
