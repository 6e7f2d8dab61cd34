"""The typed IK failure reason: each member is the text results have always carried."""

import numpy as np

from simparity.core.model.ik_result import REASONS, IKReason

WRITTEN = ("", "unreachable", "singular", "limit_blocked", "iteration_cap", "outside_limits")
"""The reasons as results.csv details and stored runs spell them (before the enum: string literals)."""


def test_each_reason_is_written_as_its_text():
    assert REASONS == WRITTEN
    for member, text in zip(IKReason, WRITTEN):
        assert member == text and str(member) == text and f"{member}" == text and hash(member) == hash(text)
    mixed = np.full(3, IKReason.ITERATION_CAP, dtype=object)
    mixed[1] = IKReason.SOLVED
    assert mixed.astype(str).tolist() == ["iteration_cap", "", "iteration_cap"]
    assert np.where([True, False], IKReason.UNREACHABLE, IKReason.SINGULAR).tolist() == ["unreachable", "singular"]
