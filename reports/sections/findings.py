"""The summary's flagged findings (energy gained, impacts that gained energy, tunnelling, saturated errors, order
fits flagged) with the tolerances' verdict, and its cases without a result; a sweep's variants share each row."""

from __future__ import annotations

import re
from collections import Counter

import pandas as pd

from simparity.core.model.metric_catalogue import ENERGY_GAIN_MAX
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE
from simparity.reports import summary
from simparity.reports.blocks import Block, Bullets, Details, Heading, Paragraph, Table, number
from simparity.reports.markdown import LINE_CHARS
from simparity.reports.sections.context import ReportContext
from simparity.reports.sections.shared import clip, names
from simparity.reports.sweep_summary import union

REASON_CHARS = 160
"""Characters of a reason in a findings table; the whole reason is the rows' ``detail`` in results.csv."""

_UNRESOLVED_RANK = {FAILED: 0, DIVERGED: 1}
"""The order of the rows of cases without a result: failed, then diverged, then n/a (stable within each), so that a
report.md over its line budget keeps what broke."""

_NUMBER = re.compile(r"[-+]?\d[\d.]*(?:e[-+]?\d+)?")


def _per_engine(frame: pd.DataFrame, variants) -> str:
    """``core: rk4, midpoint (+3 more); mujoco: euler``: each engine's schemes (``integrator``) of ``frame``,
    ``variants(row, lead)`` adding how many of a sweep's variants a row stands for."""
    return "; ".join(f"{engine}: " + names(list(dict.fromkeys(f"{r['integrator']}{variants(r, ' ')}"
                                                               for _, r in g.iterrows())))
                     for engine, g in frame.groupby("engine", sort=False))


def _reason_kind(reason: str) -> str:
    """What a reason says, whatever its numbers and after its first clause (the engine's description): the key
    that groups "energy of rod rose by 1.05 x ..." with "energy of rod rose by 8.9 x ..."."""
    return _NUMBER.sub("#", reason.split("; ")[0])


def _dt_range(dts: list[float]) -> str:
    """``0.0025-0.01 (3)``: the range of time steps and how many; one step as itself; none as ""."""
    if not dts:
        return ""
    return f"{dts[0]:g}" if len(dts) == 1 else f"{min(dts):g}-{max(dts):g} ({len(dts)})"


def section(ctx: ReportContext) -> list[Block]:
    """Flagged findings as one table: a row per finding x scene x engine, its schemes, time steps, largest value
    and what it means; then the tolerances' verdict, with every metric outside its bound folded below. Counts each
    scene's findings (``ctx.findings_per_scene``) for the scenes' verdicts."""
    rows: list[tuple[str, ...]] = []
    gains = ctx.merged(summary.energy_gains(ctx.series), ["engine", "integrator"],
                       gain_max=("gain_max", "max"), dts=("dts", union))
    rows += _finding_rows(ctx, "energy gained", gains, "gain_max",
                          "the scene conserves energy: (E - E(0)) / the body's energy scale rose")
    flags = ctx.merged(summary.contact_flags(ctx.table), ["metric", "engine", "integrator"],
                       value_max=("value_max", "max"), dts=("dts", union))
    for metric, g in flags.groupby("metric", sort=False):
        what, meaning = (("energy gained at an impact", f"`{metric}`: an impact gave the body energy")
                         if metric == ENERGY_GAIN_MAX else ("tunnelling", f"`{metric}`: a body went through a plane"))
        rows += _finding_rows(ctx, what, g, "value_max", meaning)
    saturated = ctx.merged(summary.saturated(ctx.table), ["metric"], n_cases=("n_cases", "sum"))
    for scene, g in saturated.groupby("scene", sort=False):
        counted = ", ".join(f"`{r['metric']}` {r['n_cases']}{ctx.in_variants(r, ' ')}" for _, r in g.iterrows())
        rows.append(("saturated", scene, counted, "", "", "n/a: the error reached its quantity's scale and lost all "
                     "meaning (cases counted per metric)"))
    rows += _order_findings(ctx)
    ctx.findings_per_scene = Counter(row[1] for row in rows)
    blocks: list[Block] = [Heading(3, "Flagged findings")]
    if rows:
        blocks.append(Table(("finding", "scene", "engine × scheme (or metric: cases)", "dt [s]", "largest",
                             "what it means"), tuple(rows), trim_order=2))
    blocks.append(Paragraph(_tolerance_line(ctx)))
    if ctx.verdict and ctx.verdict.violations:
        blocks.append(Details(f"{ctx.verdict.outside_count} metrics outside their bounds",
                              (Bullets(tuple(f"`{clip(v, LINE_CHARS - 10)}`" for v in ctx.verdict.violations)),)))
    return blocks


def _finding_rows(ctx: ReportContext, finding: str, frame: pd.DataFrame, value: str,
                  meaning: str) -> list[tuple[str, ...]]:
    """One row per scene of ``frame`` (scene, engine, integrator, ``value``, dts): its engines' schemes named
    compactly, the time steps' range and the largest value."""
    out: list[tuple[str, ...]] = []
    for scene, g in frame.groupby("scene", sort=False):
        out.append((finding, scene, _per_engine(g, ctx.in_variants), _dt_range(union(g["dts"])),
                    number(g[value].max()), meaning))
    return out


def _tolerance_line(ctx: ReportContext) -> str:
    """The tolerances' verdict in one sentence."""
    verdict = ctx.verdict
    if verdict is None:
        return "**Tolerances**: not checked in this report."
    unbounded = f"; {verdict.unchecked} without a bound, so not held to anything" if verdict.unchecked else ""
    if verdict.violations:
        return (f"**Outside the tolerances**: {verdict.outside_count} of {verdict.checked} checked metrics: an "
                f"engine disagreeing with the truth or the others beyond its bound (listed below, one line per "
                f"case and reason){unbounded}.")
    if verdict.checked:
        return f"**Tolerances**: all {verdict.checked} checked metrics inside their bounds{unbounded}."
    return f"**Tolerances**: nothing checked: no bound matches this run's metrics ({verdict.unchecked} without a bound)."


def _order_findings(ctx: ReportContext) -> list[tuple[str, ...]]:
    """One row per scene x flag x engine of order fits flagged as findings (:func:`reports.summary.order_findings`),
    each scheme with its fitted orders."""
    what = {"not-converging": ("orders that do not converge", "errors far from saturation and rounding that do "
                               "not fall with dt: an alarm"),
            "below-theory": ("orders below theory", "clean fits more than 0.5 under the scheme's order"),
            "superconvergent": ("superconvergent orders", "clean fits more than 0.5 above the scheme's order: "
                                "error terms cancel, or the steps are before the asymptotic range"),
            "pre-asymptotic": ("orders not in the asymptotic range", "local slopes disagree: finer steps needed")}
    rows: list[tuple[str, ...]] = []
    for (scene, flag), g in summary.order_findings(ctx.table).groupby(["scene", "flag"], sort=False):
        fitted = g.assign(integrator=[f"{r['integrator']} " + "/".join(number(v) if v == v else "n/a"
                                                                        for v in r["values"]) for _, r in g.iterrows()])
        rows.append((what[flag][0], scene, _per_engine(fitted, lambda r, lead: ""), "", "", what[flag][1]))
    return rows


def unresolved(ctx: ReportContext) -> list[Block]:
    """Every case without a result, as one table: a row per status and kind of reason (:func:`_reason_kind`: the
    same words, other numbers), with the scenes, engines and schemes it covers, the count and the time steps."""
    cases = summary.unresolved_cases(ctx.table)
    if cases.empty:
        return [Heading(3, "Cases without a result"), Paragraph("None: every case was measured.")]
    cases = ctx.merged(cases, ["status", "order_fit", "engine", "integrator", "reason"],
                       n_cases=("n_cases", "sum"), dts=("dts", union))
    cases = cases.assign(kind=cases["reason"].fillna("").map(_reason_kind))
    rows = []
    for (status, order_fit, _), g in cases.groupby(["status", "order_fit", "kind"], sort=False, dropna=False):
        label = status if status != NOT_AVAILABLE else f"n/a ({'order fit' if order_fit else 'run'})"
        rows.append((label, names(list(dict.fromkeys(g["scene"]))), _per_engine(g, ctx.in_variants),
                     str(g["n_cases"].sum()), _dt_range(union(g["dts"])),
                     clip(g["reason"].iloc[0] or "no reason given", REASON_CHARS)
                     + (f" (and {g['reason'].nunique() - 1} more like it)" if g["reason"].nunique() > 1 else "")))
    rows.sort(key=lambda row: _UNRESOLVED_RANK.get(row[0], len(_UNRESOLVED_RANK)))  # what broke first
    return [Heading(3, "Cases without a result"),
            Table(("status", "scenes", "engine × scheme", "cases", "dt [s]", "reason (the first; others alike but for "
                   "their numbers; each in full: its `detail` in `results.csv`)"), tuple(rows), trim_order=1)]
