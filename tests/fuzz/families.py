"""Every family of fuzzed inputs, generated from one seed: what tests/system/test_fuzz_inputs.py and ``python -m
tests.fuzz`` try."""

from __future__ import annotations

import numpy as np

from tests.fuzz import history_dbs, joint_inputs, options, run_folders, tolerance_files
from tests.fuzz.oracle import Case

SEED = 39
"""The issue's number: the seed every family's generator is made from (``[SEED, k]`` for the k-th family)."""

FAMILIES = (run_folders.results_cases, run_folders.info_cases, history_dbs.cases, tolerance_files.cases,
            options.run_cases, options.check_cases, joint_inputs.cases)


def all_cases(seed: int = SEED) -> list[Case]:
    """Every input of every family, in a fixed order (the same ids in every process)."""
    found = []
    for k, family in enumerate(FAMILIES):
        found += family(np.random.default_rng([seed, k]))
    ids = [case.id for case in found]
    duplicated = sorted({i for i in ids if ids.count(i) > 1})
    if duplicated:
        raise ValueError(f"fuzz cases with the same id: {duplicated[:5]}")
    return found
