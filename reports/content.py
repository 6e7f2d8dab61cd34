"""What a report says, as blocks (:mod:`reports.blocks`), in order: the run's header, "is my engine right?" for a
user's engines (:mod:`reports.own_engine`), the summary (:mod:`reports.sections.summary_tables`), the hard cases,
the definitions, the sweeps' sections (:mod:`reports.sweep_sections`), a section per dynamics or IK scene
(:mod:`reports.sections.dynamics`, :mod:`reports.sections.ik`), then one section for every kinematics scene and one
for every joint-dynamics scene. Each kind of scene's section is a module of :mod:`reports.sections`; this one puts
them in order. Reads a stored run only; figures are drawn and saved here.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from simparity.core.model.results import STATUSES, case_counts
from simparity.core.model.run_info import RunInfo
from simparity.reports import figure_writer, figures, own_engine, sweep_sections, sweep_summary
from simparity.reports.blocks import Block, Bullets, Details, Heading, Paragraph, scene_heading
from simparity.reports.markdown import LINE_CHARS
from simparity.reports.sections import (
    dynamics, hard_cases, ik, joint_dynamics, kinematics, robots, summary_tables,
)
from simparity.reports.sections.context import TABULATED_KINDS, ReportContext, heading_kind, headline, scene_kind
from simparity.reports.sections.shared import clip, engine_notes
from simparity.reports.tolerance_verdict import ToleranceVerdict

FIGURES_DIR = "figures"
"""Sub-folder of the run folder the figures are written to (SVG and PNG)."""

_DEFINITIONS = (
    "Statuses: `ok` measured; `n/a` not measured, with the reason: the engine cannot do what the scene asks, "
    "or the metric means nothing here (saturated: an orientation error at >= pi/2, another error at >= 1/4 of "
    "its quantity's scale, a drift above 100 %; errors at the rounding floor; too few time steps or no asymptotic "
    "range for an order; a point-mass rule that does not move orientation; nothing to compare against); `diverged` "
    "non-finite, or faster than the scene's forces allow, or a conserved quantity more than doubled, or a contact "
    "that gains energy; `failed` the engine raised. A status cell names the metrics it is about. "
    "Energy drift is max |E(t) - E(0)| / the body's energy scale (KE(0) plus the largest drop of its potential "
    "energy, at least m |g| size: not |E(0)|, which depends on where the origin is); angular momentum drift is "
    "max |L(t) - L(0)| / |L(0)|. Cost is compute per simulated second, time per step / dt. Definitions: "
    "docs/metrics.md."
)


def build(table: pd.DataFrame, info: RunInfo, series: pd.DataFrame, verdict: ToleranceVerdict | None,
          run_dir: Path) -> tuple[list[Block], dict[str, str]]:
    """(the report's blocks, the SVG text of each figure by name); figures are written to
    ``run_dir/figures`` (:class:`reports.figure_writer.FigureWriter`: a few in this process, many on one process per CPU),
    each in the order drawn. ``verdict``: the run held to tolerances, None if it was not."""
    with figure_writer.FigureWriter() as writer:
        ctx = ReportContext(table, info, series, verdict, Path(run_dir) / FIGURES_DIR, writer,
                            sweep_summary.sweeps(table, info))
        blocks = _blocks(ctx, table, info)
    return blocks, {name: figure.result() for name, figure in ctx.svgs.items()}


def _blocks(ctx: ReportContext, table: pd.DataFrame, info: RunInfo) -> list[Block]:
    """Every block of the report, in order."""
    versions = ", ".join(f"{k} {v}" for k, v in info.engine_versions.items())
    m = info.machine
    counts = _case_counts(table)
    blocks: list[Block] = [
        Heading(1, "simparity report"),
        Paragraph(f"Run {info.created_utc} · commit {info.git_commit} · "
                  f"{m.get('platform', '?')} · {m.get('cpu_count', '?')} CPUs · Python {m.get('python', '?')}"),
        Paragraph(f"Engines: {versions}"),
        Paragraph("Cases: " + ", ".join(f"{s} {counts[s]}" for s in STATUSES)
                  + " (failed or diverged if any row is, ok if anything was measured; n/a rows say why). Errors: "
                  "maxima over bodies and samples; times: the best repeat, indicative (`simparity bench` measures "
                  "speed). Values: `results.csv`; definitions: docs/metrics.md."),
    ]
    blocks += _own_engines(ctx)
    blocks += summary_tables.section(ctx)
    blocks += hard_cases.section(table, info, ctx.groups)
    blocks += [Details("Definitions", (Paragraph(_DEFINITIONS), Paragraph(ik.PROTOCOL)), markdown=False)]
    blocks += sweep_sections.sections(ctx.sweeps, ctx.figure, info.theoretical_orders, info.integrator_variants)
    kinds = {scene: scene_kind(rows) for scene, rows in table.groupby("scene", sort=False)}
    for scene, rows in table.groupby("scene", sort=False):
        own_section = kinds[scene] not in TABULATED_KINDS and ctx.listed(scene)
        blocks += _scene(ctx, scene, rows) if own_section else []
    robot_files = robots.robot_scenes(table, [s for s in ctx.joint_dynamics_scenes if s not in ctx.sweep_of])
    blocks += robots.section(ctx, robot_files) if robot_files else []
    for kind, section in (("joint_dynamics", joint_dynamics.section), ("kinematics", kinematics.section)):
        chosen = table[(table["scene"].map(kinds) == kind) & ~table["scene"].isin(ctx.sweep_of)]
        blocks += section(ctx, chosen) if not chosen.empty else []
    return blocks


def _case_counts(table: pd.DataFrame) -> dict[str, int]:
    """:func:`case_counts` of the table's rows, each case's statuses gathered by pandas: a row at a time, a sweep of
    1,000 IK variants (429,000 rows) took 24 s."""
    cases = table.groupby(["scene", "engine", "integrator", "dt"], sort=False, dropna=False)["status"].unique()
    return case_counts({"scene": key, "engine": "", "integrator": "", "dt": 0.0, "status": status}
                       for key, statuses in cases.items() for status in statuses)


def _own_engines(ctx: ReportContext) -> list[Block]:
    """"Is my engine right?" for each user's engine the gate holds (:mod:`reports.own_engine`)."""
    verdict = ctx.verdict
    findings: dict[str, tuple[str, ...]] | None = None
    if verdict is not None:
        findings = {}
        for engine, line in zip(verdict.engines, verdict.violations):
            findings[engine] = findings.get(engine, ()) + (clip(line, LINE_CHARS - 10),)
    headlines = {scene: headline(about) for scene, about in ctx.info.scenes.items()}
    return own_engine.sections(ctx.table, headlines, verdict.held if verdict else None, findings)


def _scene(ctx: ReportContext, scene: str, rows: pd.DataFrame) -> list[Block]:
    """The section of a dynamics or IK scene: its verdict in one line and what the scene is, then its figures
    and tables."""
    kind, about = scene_kind(rows), ctx.about(scene)
    reference = rows["reference"].iloc[0]
    series = ctx.series[ctx.series["scene"] == scene]
    run = dynamics.section if kind == "dynamics" else ik.section
    verdict, body = run(ctx, scene, rows, about, reference, series)
    lead = Bullets((f"**Verdict**: {verdict}", f"**Scene**: {ctx.introduction(scene, rows)}"))
    return [scene_heading(scene, heading_kind(about, kind)), lead, *body, *engine_notes(rows)]
