"""Issue #38: the report answers "is my engine right?" first, for each user's engine the gate holds: its schemes
beside the built-in schemes of the same kind at each time step, every finding about it; and "cheapest" says what it
counts (force evaluations per simulated second) beside the measured wall time. On hand-made rows whose answers are
known without the code under test."""

import pandas as pd

from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import SERIES_COLUMNS, ResultRow
from simparity.reports import own_engine
from simparity.reports.content import build
from simparity.reports.tolerance_verdict import ToleranceVerdict
from simparity.reports.markdown import LINE_CHARS, to_markdown
from tests.reports.undrawn import undrawn_figures

STEPS = (0.02, 0.01)
"""The time steps of every scheme here [s]."""
ERRORS = {  # (engine, integrator, scheme kind) -> position error [m] at each of STEPS
    ("core", "rk4", "rk4"): (1.6e-8, 1e-9),
    ("mujoco", "rk4", "rk4"): (2e-8, 1.25e-9),
    ("mine", "my_rk4", "rk4"): (3e-5, 1e-6),           # 1500 and 800 times the largest built-in rk4's
    ("mine", "my_leapfrog", "leapfrog"): (1e-4, 2.5e-5),  # no built-in of its kind
}
WORST_RATIO = "×1.5e+03"
"""3e-5 / 2e-8 at dt 0.02 (against 1e-6 / 1.25e-9 = 800 at 0.01)."""
STAGES = {"rk4": 4, "leapfrog": 1}
WALL_PER_STEP = 1e-5
"""Every case's wall time per step [s]: at dt 0.02, 0.5 ms of wall time per simulated second."""

MINE_FINDING = "s mine my_rk4 dt=0.02 position_error_max: 3e-05 m, bound <= 4e-08 m (cross-check)"
CORE_FINDING = "s core rk4 order_position: 3, bound >= 3.5 (RK4)"


def _rows() -> list[ResultRow]:
    rows = []
    for (engine, integrator, kind), errors in ERRORS.items():
        for dt, error in zip(STEPS, errors):
            rows += [ResultRow("s", engine, integrator, dt, "position_error_max", error, "m", "analytic:exact", "ok",
                               scheme=kind),
                     ResultRow("s", engine, integrator, dt, "time_per_step", WALL_PER_STEP, "s", "analytic:exact",
                               "ok", scheme=kind),
                     ResultRow("s", engine, integrator, dt, "evaluations_per_second", STAGES[kind] / dt, "1/s",
                               "analytic:exact", "ok", scheme=kind)]
    return rows


def _table(engines=None) -> pd.DataFrame:
    return pd.DataFrame([r.as_dict() for r in _rows() if engines is None or r.engine in engines])


def _report(tmp_path, verdict: ToleranceVerdict | None) -> str:
    """The whole report.md (its figures made, not saved: no test here reads them)."""
    with undrawn_figures():
        blocks, _ = build(_table(), RunInfo(), pd.DataFrame(columns=list(SERIES_COLUMNS)), verdict, tmp_path)
    return to_markdown(blocks)


def _own(verdict: ToleranceVerdict | None, engines=None) -> str:
    """The "is my engine right?" sections alone, as report.md has them."""
    findings = None if verdict is None else {e: tuple(v for v, x in zip(verdict.violations, verdict.engines) if x == e)
                                             for e in set(verdict.engines)}
    return to_markdown(own_engine.sections(_table(engines), {}, verdict.held if verdict else None, findings))


def _section(text: str, heading: str) -> str:
    return text.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]


def _verdict(held=None) -> ToleranceVerdict:
    return ToleranceVerdict(40, 0, (MINE_FINDING, CORE_FINDING), 2, ("mine", "core"), held)


def test_the_users_engine_comes_first_and_cheapest_says_what_it_counts_beside_the_wall_time(tmp_path):
    """Before: no such section; "cheapest at error ≤ 1e-06" and "core rk4 @ 0.02 (200/s)": a reader could take
    200/s for a speed."""
    text = _report(tmp_path, _verdict())
    headings = [line for line in text.splitlines() if line.startswith("## ")]
    assert headings[:2] == ["## Is mine right?", "## Summary"]
    assert f"`{MINE_FINDING}`" in _section(text, "Is mine right?")
    summary = _section(text, "Summary")
    assert "cheapest at error ≤ 1e-06 (force evals/s; wall ms/s)" in summary
    # within 1e-6 the fewest evaluations are core's and MuJoCo's rk4 at 0.02: 4 / 0.02 = 200/s, 1e-5 / 0.02 s/s wall
    assert "rk4 @ 0.02 (200/s, 0.5 ms; +1 as cheap)" in summary
    assert max(len(line) for line in text.splitlines()) <= LINE_CHARS


def test_the_users_schemes_stand_beside_the_same_built_in_schemes_with_every_finding_about_it():
    section = _own(_verdict())
    assert section.startswith("## Is mine right?")
    rows = [line for line in section.splitlines() if line.startswith("| s |")]
    assert rows[0] == ("| s | my_rk4 (rk4) vs core rk4, mujoco rk4 | 0.02: 3e-05 vs 1.6e-08–2e-08; 0.01: 1e-06 vs "
                       f"1e-09–1.25e-09 | {WORST_RATIO} |")
    assert rows[1] == "| s | my_leapfrog (leapfrog): no built-in of its kind | 0.02: 0.0001; 0.01: 2.5e-05 | — |"
    assert f"`{MINE_FINDING}`" in section and CORE_FINDING not in section  # every finding about it, only its


def test_no_section_for_an_engine_the_gate_does_not_hold_nor_for_the_built_ins():
    assert _own(_verdict(held=("core", "mujoco"))).strip() == ""
    assert _own(_verdict(), engines=("core", "mujoco")).strip() == ""


def test_a_users_engine_without_findings_says_so_and_an_unchecked_run_says_it_was_not_checked():
    assert "**Findings about mine**: none" in _own(ToleranceVerdict(40, 0))
    assert "not held to tolerances" in _own(None)
