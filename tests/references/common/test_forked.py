"""A question asked in a forked child (``references.common.forked``): its answer, its exception as text, or the
signal that ended it, never the end of the asking process."""

from __future__ import annotations

import os
import signal

from simparity.references.common.forked import asked_in_child


def test_an_answer_an_exception_and_a_crash_are_each_an_answer():
    assert asked_in_child(lambda: "fine") == ("fine", None)
    assert asked_in_child(lambda: str(1 / 0)) == ("division by zero", None)
    assert asked_in_child(lambda: str(os.abort())) == ("", signal.SIGABRT)
