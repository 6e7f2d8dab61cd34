"""JUnit XML a JUnit reader accepts, and a Markdown summary for CI job pages."""

import junitparser

from simparity.comparisons.gate.check import BaselineDiff, CheckResult, Violation
from simparity.comparisons.gate.check_output import junit_xml, summary_markdown


def _result():
    broken = Violation("s", "core", "rk4", 0.01, "order_position", "2.9", "in [3.5, 4.5]", "fourth order")
    return CheckResult(checked=3, unchecked=1, violations=[broken],
                       cases={("s", "core", "rk4", 0.01): [broken], ("s", "mujoco", "rk4", 0.01): [],
                              ("k", "core", "", "nan"): []})


def test_junit_has_one_test_case_per_case_and_failures_with_their_violations(tmp_path):
    path = tmp_path / "junit.xml"
    path.write_text(junit_xml(_result(), BaselineDiff(moved=["s core rk4 dt=0.01 x: 1 -> 2"])), encoding="utf-8")
    xml = junitparser.JUnitXml.fromfile(str(path))
    cases = [case for suite in xml for case in suite]
    assert len(cases) == 5  # three cases, the baseline and the share of series held to a value
    failed = {(c.classname, c.name): c for c in cases if not c.is_passed}
    assert set(failed) == {("s", "core rk4 dt=0.01"), ("baseline", "unchanged since the baseline")}
    assert "order_position: 2.9, bound in [3.5, 4.5] (fourth order)" in failed[("s", "core rk4 dt=0.01")].result[0].text
    assert ("k", "core -") in {(c.classname, c.name) for c in cases}


def test_summary_names_the_verdict_and_each_violation():
    text = summary_markdown(_result())
    assert text.startswith("## simparity check: failed")
    assert "| s | core | rk4 | 0.01 | order_position | 2.9 | in [3.5, 4.5] | fourth order |" in text
    assert summary_markdown(CheckResult(checked=1)).startswith("## simparity check: passed")


def test_a_case_with_nothing_measured_is_skipped_with_its_reason_not_passed(tmp_path):
    result = _result()
    result.unmeasured[("k", "core", "", "nan")] = "core cannot do a URDF chain"
    path = tmp_path / "junit.xml"
    path.write_text(junit_xml(result), encoding="utf-8")
    xml = junitparser.JUnitXml.fromfile(str(path))
    skipped = [case for suite in xml for case in suite if case.is_skipped]
    assert [(c.classname, c.name) for c in skipped] == [("k", "core -")]
    assert skipped[0].result[0].message == "n/a: core cannot do a URDF chain"
    assert '<testsuite name="simparity" tests="4" failures="1" skipped="1"' in path.read_text(encoding="utf-8")


def test_too_few_value_bounds_is_a_failing_test_case(tmp_path):
    path = tmp_path / "junit.xml"
    path.write_text(junit_xml(CheckResult(checked=1), unbounded="3 of 3 series have no bound on any value"),
                    encoding="utf-8")
    failed = [case for suite in junitparser.JUnitXml.fromfile(str(path)) for case in suite if not case.is_passed]
    assert [(c.classname, c.name) for c in failed] == [("tolerances", "series held to a value")]
