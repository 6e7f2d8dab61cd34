"""The references' own evaluation of loads that change with time agrees with core's at any time (two
implementations that share no code: Horner and a sorted search against powers and floor/ceil), and the jumps a
solver must restart at are the holds' instants inside the run."""

from __future__ import annotations

import numpy as np

from simparity.core.dynamics.time_loads import value_in_step
from simparity.core.model.scenes.time_functions import HeldFunction, Sinusoid, SmoothFunction
from simparity.references.common.time_loads import at, jump_times

AGREEMENT = 4e-15
"""|core - reference| allowed [the values' unit]: two orders of summation of terms of size ~1-10."""


def test_the_references_evaluate_every_function_as_core_does():
    rng = np.random.default_rng(42)
    smooth = SmoothFunction(rng.normal(size=(4, 3)), tuple(Sinusoid(rng.normal(size=3), f, p)
                                                         for f, p in ((0.7, 0.1), (3.0, -2.0))))
    held = HeldFunction(rng.normal(size=(12, 3)), period_s=0.07, phase_s=0.02)
    for t in rng.uniform(0.0, 1.0, size=200):
        start = t - rng.choice([0.0, 0.005, 0.01])
        for function in (smooth, held):
            np.testing.assert_allclose(at(function, t, start), value_in_step(function, t, start), rtol=0,
                                       atol=AGREEMENT)


def test_stages_on_an_instant_take_the_side_of_their_step():
    held = HeldFunction(np.array([[1.0], [2.0]]), period_s=0.1, phase_s=0.0)
    end = 0.1 * 3 / 3  # an instant reached by a step's sum
    assert at(held, end, 0.0)[0] == 1.0 and at(held, end, end)[0] == 2.0 and at(held, end)[0] == 2.0


def test_the_jumps_are_the_instants_inside_the_run():
    held = HeldFunction(np.zeros((5, 1)), period_s=0.1, phase_s=0.0)
    smooth = SmoothFunction(np.zeros((1, 1)))
    np.testing.assert_allclose(jump_times([held, smooth], 0.35), [0.1, 0.2, 0.3])
    assert len(jump_times([smooth], 1.0)) == 0
