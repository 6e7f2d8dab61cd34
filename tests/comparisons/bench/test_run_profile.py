"""The bench's profile of a run: stack samples charged to simparity's folders, phases that add up."""

import time

import numpy as np
import pytest

from simparity.comparisons.bench.run_profile import (
    OUTSIDE, StackSampler, folder_of, profile_markdown, run_profile,
)
from simparity.core import rotations
from simparity.core.dynamics import tableau
from tests.reports.undrawn import undrawn_figures

BUSY_SECONDS = 0.3
"""How long the sampled thread works: some 60 samples at 5 ms."""


def test_folder_of_names_the_simparity_folder_of_a_file_and_none_outside():
    assert folder_of(tableau.__file__) == "core/dynamics"
    assert folder_of(rotations.__file__) == "core"
    assert folder_of(np.__file__) is None
    assert folder_of(__file__) is None  # a checkout's tests sit beside the package's folders, not in them


def test_samples_are_charged_to_the_innermost_simparity_frame_not_to_numpy():
    a = np.ones((4, 3))
    end = time.perf_counter() + BUSY_SECONDS
    with StackSampler() as sampler:
        while time.perf_counter() < end:
            rotations.cross(a, a)
    assert sampler.counts, "no sample taken"
    # the loop itself is in this test file (outside the package): only cross's own frames are simparity's
    assert set(sampler.counts) <= {"core", OUTSIDE}
    assert sampler.counts["core"] > 0


@pytest.mark.slow  # runs a scene in process and starts an interpreter that imports every engine
def test_a_profiled_run_has_every_phase_and_charges_the_cases_to_core():
    with undrawn_figures():   # the report phase makes its figures; no assertion reads a saved one
        parts = run_profile(["lecture-projectile"], ("core", "analytic"))
    phases = {p.phase for p in parts}
    assert phases == {"load scenes", "cases", "report", "worker start"}
    cases = {p.part: p.seconds for p in parts if p.phase == "cases"}
    assert any(part.startswith("core") for part in cases), cases
    assert all(p.seconds >= 0 for p in parts)
    text = "\n".join(profile_markdown(parts, "simparity bench"))
    assert "| cases |" in text and "## Where a run spends its time" in text
