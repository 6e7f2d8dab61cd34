"""The verdict of ``simparity check`` as JUnit XML (for CI test reports) and as Markdown (for a CI
job summary such as GitHub's ``$GITHUB_STEP_SUMMARY``)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from simparity.comparisons.gate.check import BaselineDiff, CheckResult
from simparity.comparisons.gate.violation import GROUP_METRICS_SHOWN, Violation, grouped
from simparity.reports.tolerance_verdict import ToleranceVerdict  # a dataclass alone: no figure module comes with it


MESSAGE_CHARS = 500
"""Characters of a JUnit message attribute (CI viewers show it on one line; the text holds every line)."""


ENGINES_NAMED = 6
"""Engines the verdict line names before it counts the rest."""


def _engine_list(engines: tuple[str, ...]) -> str:
    named = ", ".join(engines[:ENGINES_NAMED]) + (f", +{len(engines) - ENGINES_NAMED}" if len(engines) > ENGINES_NAMED
                                                   else "")
    return f"{len(engines)} engine{'s' if len(engines) != 1 else ''} ({named or 'none'})"


def held_line(result: CheckResult) -> str:
    """What the gate held, for the verdict line: ``1140 metrics of 3 engines (core, mujoco, myengine) checked``, the
    held engines that measured nothing, and the engines it did not hold with their findings."""
    held = result.held_engines
    others = tuple(e for e in result.engines if e not in held)
    text = f"{result.held_checked} metrics of {_engine_list(held)} checked"
    idle = [e for e in held if e not in result.measured_engines]
    if idle:  # held, but nothing of theirs was measured: a gate with an engine fewer than it says
        text += f" ({', '.join(idle)} measured nothing: every row n/a or failed)"
    if others:
        text += f" (not held: {', '.join(others)}, {len(result.findings)} findings, never blocking)"
    return text


def report_verdict(result: CheckResult, held: tuple[str, ...] | None = None) -> ToleranceVerdict:
    """The verdict as the report shows it: counts, one line per case and reason with the engine it is about, and the
    engines the gate holds (``held``, else the result's; None: every one)."""
    groups = grouped(result.violations + result.findings)
    return ToleranceVerdict(result.checked, result.unchecked, tuple(g.line() for g in groups),
                            len(result.violations) + len(result.findings),
                            tuple(g.violations[0].engine for g in groups), held if held is not None else result.held,
                            tuple((g.violations[0].scene, g.violations[0].metric) for g in groups))


def _case_name(key: tuple) -> tuple[str, str]:
    """(classname, name) of a case: the scene, and engine, integrator and dt."""
    scene, engine, integrator, dt = key
    dt_text = "" if dt == "nan" or (isinstance(dt, float) and math.isnan(dt)) else f" dt={dt:g}"
    return scene, f"{engine} {integrator or '-'}{dt_text}"


def junit_xml(result: CheckResult, diff: BaselineDiff | None = None, unbounded: str = "") -> str:
    """JUnit XML: one test case per scene x engine x integrator x dt; a case with violations fails with
    them as its message and text, a case that measured nothing (every row n/a) is skipped with the reason;
    a baseline comparison is one more test case, and so is the share of series held to a value (``unbounded``:
    the reason it fails, "" when it does not); the user's bounds that matched no row are one skipped test case."""
    suites = ET.Element("testsuites", name="simparity check")
    suite = ET.SubElement(suites, "testsuite", name="simparity")
    failures = skipped = 0
    for key, violations in result.cases.items():
        classname, name = _case_name(key)
        case = ET.SubElement(suite, "testcase", classname=classname, name=name, time="0")
        if key in result.unmeasured:
            skipped += 1
            ET.SubElement(case, "skipped", message=f"n/a: {result.unmeasured[key]}"[:MESSAGE_CHARS])
        elif violations and not result.is_held(key[1]):  # a finding about an engine the gate does not hold
            skipped += 1
            reasons = "; ".join(g.line() for g in grouped(violations))
            ET.SubElement(case, "skipped", message=(f"not held by the gate, {len(violations)} finding(s), never "
                                                    f"blocking: {reasons}")[:MESSAGE_CHARS]).text = "\n".join(
                v.line() for v in violations)
        elif violations:
            failures += 1
            reasons = "; ".join(g.line() for g in grouped(violations))
            failure = ET.SubElement(case, "failure", type="tolerance", message=(
                f"{len(violations)} metric(s) outside their bounds: {reasons}")[:MESSAGE_CHARS])
            failure.text = "\n".join(v.line() for v in violations)
    tests = len(result.cases)
    if diff is not None:
        tests += 1
        case = ET.SubElement(suite, "testcase", classname="baseline", name="unchanged since the baseline", time="0")
        if diff.blocking:
            failures += 1
            failure = ET.SubElement(case, "failure", message=diff.nothing_compared[:MESSAGE_CHARS] or "numerics moved "
                                    "since the baseline", type="baseline")
            failure.text = "\n".join(diff.moved + [f"missing: {m}" for m in diff.missing])
    if result.nothing_checked:
        tests += 1
        failures += 1
        case = ET.SubElement(suite, "testcase", classname="tolerances", name="metrics checked", time="0")
        ET.SubElement(case, "failure", message=result.nothing_checked[:MESSAGE_CHARS], type="nothing-checked")
    if result.absent:
        tests += 1
        failures += 1
        case = ET.SubElement(suite, "testcase", classname="engines", name="required engines measured", time="0")
        ET.SubElement(case, "failure", message="; ".join(result.absent)[:MESSAGE_CHARS],
                      type="required").text = "\n".join(result.absent)
    tests += 1
    case = ET.SubElement(suite, "testcase", classname="tolerances", name="series held to a value", time="0")
    if unbounded:
        failures += 1
        ET.SubElement(case, "failure", message=unbounded[:MESSAGE_CHARS], type="unbounded").text = unbounded
    if result.unmatched:  # loud, never blocking: skipped, as a finding is
        tests += 1
        skipped += 1
        case = ET.SubElement(suite, "testcase", classname="tolerances", name="every bound of the user's held a row",
                             time="0")
        ET.SubElement(case, "skipped", message=(f"{len(result.unmatched)} bound(s) matched no row, never blocking: "
                                                + "; ".join(result.unmatched))[:MESSAGE_CHARS]).text = "\n".join(
            result.unmatched)
    for element in (suites, suite):
        element.set("tests", str(tests))
        element.set("failures", str(failures))
        element.set("skipped", str(skipped))
        element.set("errors", "0")
    return ET.tostring(suites, encoding="unicode", xml_declaration=True) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "/").replace("\n", " ")


def summary_markdown(result: CheckResult, diff: BaselineDiff | None = None, unbounded: str = "") -> str:
    """A short Markdown verdict: counts, then each violation, each finding about an engine the gate does not hold
    (never blocking) and each move (``unbounded``: the reason the run fails for too few value bounds, "" when it
    does not)."""
    verdict = "passed" if result.passed and not (diff and diff.blocking) and not unbounded else "failed"
    lines = [f"## simparity check: {verdict}", "",
             f"{held_line(result)}, {len(result.violations)} outside their bounds, "
             f"{result.unchecked} without a bound; {len(result.cases)} cases, {len(result.unmeasured)} without a "
             f"result (n/a); {len(result.unbounded_series)} of {len(result.series)} series without a value bound.", ""]
    if unbounded:
        lines += [f"**Too few value bounds:** {_cell(unbounded)}", ""]
    lines += [f"**Nothing checked:** {_cell(line)}" for line in (result.nothing_checked, diff and diff.nothing_compared)
              if line]
    lines += [f"**Required engine without a measured row:** {_cell(line)}" for line in result.absent]
    lines += [f"- tolerances: {_cell(line)}" for line in result.unmatched]
    lines += _violation_table(result.violations)
    if result.findings:
        lines += ["", "Findings about engines the gate does not hold (never blocking):", ""]
        lines += _violation_table(result.findings)
    if diff is not None:
        lines += ["", f"Since the baseline: {len(diff.moved)} moved, {len(diff.missing)} missing, "
                      f"{len(diff.new)} new; timing changed in {len(diff.timing)} scenes (not blocking). "
                      f"{diff.scope_line()}", ""]
        lines += [f"- moved: {_cell(m)}" for m in diff.moved] + [f"- missing: {_cell(m)}" for m in diff.missing]
        lines += [f"- new: {_cell(m)}" for m in diff.new]
    return "\n".join(lines) + "\n"


def _violation_table(violations: list[Violation]) -> list[str]:
    """One table row per case and reason (none: no table)."""
    if not violations:
        return []
    lines = ["| scene | engine | integrator | dt | metrics | found | bound | reason |", "|---|---|---|---|---|---|---|---|"]
    for group in grouped(violations):
        v, metrics = group.violations[0], [m.metric for m in group.violations]
        shown = ", ".join(metrics[:GROUP_METRICS_SHOWN]) + (f" (+{len(metrics) - GROUP_METRICS_SHOWN})"
                                                             if len(metrics) > GROUP_METRICS_SHOWN else "")
        lines.append("| " + " | ".join(_cell(str(x)) for x in (
            v.scene, v.engine, v.integrator or "-", "" if math.isnan(v.dt) else f"{v.dt:g}", shown, v.found,
            v.bound, v.reason)) + " |")
    return lines
