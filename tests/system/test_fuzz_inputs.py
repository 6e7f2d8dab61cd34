"""Issue #39's fuzz pass: a few hundred malformed or hostile inputs over stored run folders, history databases,
tolerance files, command-line options and joint inputs (tests/fuzz/, generated from one seed), each tried through
the command (in this process, a few as subprocesses) under a per-input timeout. A bad input ends in exit 2 with one
line on stderr naming its file, key or option, never a traceback or a warning; none passes silently (exit 0); the
valid controls pass. The pass is a sweep (python -m pytest -m sweep tests/system/test_fuzz_inputs.py; ~2 minutes of CPU
when every bad input is refused up front); ``python -m tests.fuzz`` prints its failures grouped by class. The fast
tests here check the harness itself: the same inputs in every process, and an oracle that tells each failure."""

from __future__ import annotations

import warnings
from collections import Counter
from functools import partial

import pytest

from tests.fuzz.base import make_base
from tests.fuzz.families import FAMILIES, all_cases
from tests.fuzz.oracle import EITHER, FAILS, REFUSED, VALID, Call, Case, Outcome, judge, try_call

CASES = all_cases()
FAMILY_SIZE = (30, 100)
"""Inputs per family, at least and at most: enough to draw every class, few enough for the sweep's time."""


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """The valid stored run and history database every damaged input starts from (one quick run, ~20 s)."""
    return make_base(tmp_path_factory.mktemp("fuzz-base"))


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[case.id for case in CASES])
def test_fuzzed_input_is_refused_in_one_line_or_passes_as_valid(case, base, tmp_path):
    call = case.build(tmp_path, base)
    verdict = judge(case, call, try_call(call, tmp_path))
    assert verdict is None, f"{case.id}: {verdict}" + (f" ({case.note})" if case.note else "")


def test_the_same_seed_gives_the_same_inputs_and_every_family_its_share():
    again = all_cases()
    assert [case.id for case in again] == [case.id for case in CASES]
    sizes = Counter(case.family for case in CASES)
    assert len(sizes) == len(FAMILIES)
    assert all(FAMILY_SIZE[0] <= size <= FAMILY_SIZE[1] for size in sizes.values()), sizes
    assert sum(case.accept == VALID for case in CASES) >= len(FAMILIES)  # every family has a control...
    assert sum(case.accept == REFUSED for case in CASES) > len(CASES) // 2  # ...and is mostly bad input


def _case(accept=REFUSED) -> Case:
    return Case("harness", "synthetic", lambda folder, base: Call(), accept)


ONE_LINE = "simparity: error: run/results.csv: row 3: value 'abc' is not a number (allowed: ...)\n"


@pytest.mark.parametrize("accept, outcome, names, verdict", [
    (REFUSED, Outcome(code=2, err=ONE_LINE), ("results.csv",), None),
    (REFUSED, Outcome(code=None, timed_out=True), (), "timeout"),
    (REFUSED, Outcome(code=None, escaped="ValueError: x"), (), "traceback"),
    (REFUSED, Outcome(code=2, err=ONE_LINE, warned=["RuntimeWarning: overflow"]), (), "warning"),
    (REFUSED, Outcome(code=0), (), "silent pass"),
    (REFUSED, Outcome(code=1, out="check FAILED"), (), "not refused (exit 1)"),
    (REFUSED, Outcome(code=2, err=ONE_LINE * 2), (), "refusal not one line"),
    (REFUSED, Outcome(code=2, err="Traceback (most recent call last):\n"), (), "refusal not one line"),
    (REFUSED, Outcome(code=2, err=ONE_LINE), ("run.json",), "refusal names nothing"),
    (VALID, Outcome(code=2, err=ONE_LINE), (), "refused a valid input"),
    (VALID, Outcome(code=0), (), None),
    (FAILS, Outcome(code=1), (), None),
    (FAILS, Outcome(code=0), (), "silent pass"),
    (EITHER, Outcome(code=0), (), None),
])
def test_the_oracle_tells_each_class_of_failure(accept, outcome, names, verdict):
    found = judge(_case(accept), Call(names=names), outcome)
    assert (found if found is None else found.split(":")[0]) == verdict


def _raise(error):
    raise error


def _warn():
    warnings.warn("overflow encountered in multiply", RuntimeWarning)


def _spin():
    while True:
        pass


@pytest.mark.slow  # imports the whole command (the engines): seconds
def test_an_input_tried_in_process_is_captured_and_cannot_hang(tmp_path):
    """A refusal's line is captured, an escaped exception and a warning are seen, a loop ends at the timeout, and
    the working directory the input ran in is given back."""
    from simparity.core.model.errors import ResultsError

    refused = try_call(Call(argv=("check", str(tmp_path / "no-such-run"))), tmp_path)
    assert refused.code == 2 and refused.err.startswith("simparity: error: ") and refused.err.count("\n") == 1
    assert try_call(Call(function=partial(_raise, ResultsError("x.csv: bad"))), tmp_path).err == \
        "simparity: error: x.csv: bad\n"
    assert try_call(Call(function=partial(_raise, KeyError("scheme"))), tmp_path).escaped == "KeyError: 'scheme'"
    assert try_call(Call(function=_warn), tmp_path).warned == ["RuntimeWarning: overflow encountered in multiply"]
    assert try_call(Call(function=_spin), tmp_path, cpu_seconds=0.2, wall_seconds=5.0).timed_out
