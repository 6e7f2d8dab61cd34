"""What a report says, as blocks (:mod:`reports.blocks`): the summary first, then per scene its figures,
a compact table and (folded) the full one; a sweep's variants are one row, line or section wherever the report
lists scenes (:mod:`reports.sweep_sections`). Reads a stored run only; figures are drawn and saved here.
"""

from __future__ import annotations

import concurrent.futures
import math
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import (
    DIVERGED,
    FAILED,
    GROUND_TRUTH_ENGINES,
    HARD_VERDICT_SUFFIXES,
    NOT_AVAILABLE,
    OK,
    STATUSES,
    case_counts,
    case_status,
)
from simparity.reports import engine_summary, figures, own_engine, summary, sweep_sections, sweep_summary, tables
from simparity.reports.blocks import (
    Block,
    Bullets,
    Details,
    Figure,
    Heading,
    Paragraph,
    Table,
    number,
    scene_heading,
)
from simparity.reports.markdown import LINE_CHARS
from simparity.reports.sweep_summary import Sweep, merge_variants, union
from simparity.core.model.metric_catalogue import (
    APEX_HEIGHT_ERROR, CROSS_EVAL_SOLVE_RATE_MIN, ENERGY_GAIN_MAX, IMPACT_TIME_ERROR, ITERATIONS_MEDIAN,
    LIMIT_VIOLATIONS, ORIENTATION_ERROR_MAX, OWN_STOP_POSITION_TOLERANCE, PENETRATION_MAX, POSITION_ERROR_MAX,
    POSITION_RESIDUAL_MEDIAN, RESTITUTION_MEASURED, REST_TIME_ERROR, SOLVE_RATE, SOLVE_RATE_OWN_STOP, STOPPING_DISTANCE,
    TIME_PER_FK, TIME_PER_SOLVE, TIME_PER_STEP, MASS_MATRIX_ERROR_MAX, BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX,
    FORWARD_DYNAMICS_ERROR_MAX, GRAVITY_IDENTITY_RESIDUAL, MASS_COLUMN_RESIDUAL, ROUND_TRIP_RESIDUAL,
    MASS_MATRIX_ASYMMETRY, KINETIC_ENERGY_RESIDUAL, JOINT_ANGLE_ERROR_MAX, REFERENCE_PARTING_TIME, SELF_PARTING_TIME,
)

FIGURES_DIR = "figures"
"""Sub-folder of the run folder the figures are written to (SVG and PNG)."""

@dataclass(frozen=True)
class ToleranceVerdict:
    """The run held to tolerances, as the report's flagged findings show it: how many metrics had a bound,
    how many had none, and the lines saying which metrics were outside their bounds."""

    checked: int
    unchecked: int
    violations: tuple[str, ...] = ()
    outside: int | None = None
    """Metrics outside their bounds (``violations`` may say them in fewer lines: one per case and reason); None:
    one per line."""

    engines: tuple[str, ...] = ()
    """The engine each line of ``violations`` is about (empty: not said)."""
    held: tuple[str, ...] | None = None
    """The engines the gate holds (None: every engine of the run): a user's engine among them has a section of its
    own first (:mod:`reports.own_engine`)."""

    @property
    def outside_count(self) -> int:
        return len(self.violations) if self.outside is None else self.outside


SCENE_SUMMARY_TRIM_ORDER = 4
"""Where the summary's row per scene stands among the tables report.md may shorten to stay within its line budget
(:attr:`reports.blocks.Table.trim_order`): last, after a user's engine's table, and down to no row if it must, since
every scene's own section below opens with the same verdict (a suite past ~26 scenes outgrew 400 lines with every
other table at its minimum)."""


_IK_COMPACT = (SOLVE_RATE, POSITION_RESIDUAL_MEDIAN, ITERATIONS_MEDIAN, TIME_PER_SOLVE, LIMIT_VIOLATIONS,
               CROSS_EVAL_SOLVE_RATE_MIN)
_IK_PROTOCOL = (
    "Protocol (TRAC-IK): seeded random reachable targets (end-effector poses of seeded random configurations "
    "within the limits), every solve from the scene's one start pose, success when the residuals are within "
    "the scene's tolerances and the joint values within their limits (an engine's solver that leaves them "
    "fails with `outside_limits`), time per solve = batch time / batch size with failed solves included. Each "
    "solution is also put through every engine's forward kinematics (worst solve rate and largest "
    "disagreement shown), so no solver passes on its own kinematics alone."
)
_TIMING_METRICS = (TIME_PER_STEP, TIME_PER_FK, TIME_PER_SOLVE)
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
_HEADLINE_NAMES = {POSITION_ERROR_MAX: ("position error max", "m"),
                   ORIENTATION_ERROR_MAX: ("orientation error max", "rad"),
                   JOINT_ANGLE_ERROR_MAX: ("joint angle error max", "rad")}


def _notes(scene_rows: pd.DataFrame) -> list[Block]:
    timed = scene_rows["metric"].isin(_TIMING_METRICS)
    ok = scene_rows[timed & (scene_rows["status"] == OK)].drop_duplicates(["engine", "integrator"])
    items = tuple(f"**{' '.join(filter(None, (r['engine'], r['integrator'])))}**: {r['detail']}" for _, r in ok.iterrows())
    return [Details("What each engine was given", (Bullets(items),), markdown=False)] if items else []


def _fits(orders: pd.DataFrame) -> list[Block]:
    fitted = orders[orders["status"] == OK]
    return [Bullets(tuple(f"{r['engine']} {r['integrator']} `{r['metric']}` = {number(r['value'])}: {r['detail']}"
                          for _, r in fitted.iterrows()))] if not fitted.empty else []


def _hard_solved(rows: pd.DataFrame) -> tuple[int, int]:
    """(hard IK solves that succeeded, hard IK solves measured) of a scene's rows."""
    verdicts = rows[rows["metric"].str.startswith("hard_") & rows["metric"].str.endswith("_solved")
                    & (rows["status"] == OK)]
    return int(verdicts["value"].sum()), len(verdicts)


def _hard_cell(row) -> str:
    if row["status"] != OK:
        return row["status"]
    verdict = row["detail"].split(";")[0]
    return f"{'✓' if verdict == 'solved' else '✗ ' + verdict.removeprefix('failed: ')} {number(row['value'])} m"


def _hard_table(rows: pd.DataFrame) -> list[Block]:
    """Engine x solver against each hard target: solved or the reason, with the position residual."""
    hard = rows[rows["metric"].str.startswith("hard_") & ~rows["metric"].str.endswith(HARD_VERDICT_SUFFIXES)]
    if hard.empty:
        return []
    names = list(dict.fromkeys(hard["metric"]))
    table_rows = []
    for (engine, solver), group in hard.groupby(["engine", "integrator"], sort=False):
        cells = {r["metric"]: _hard_cell(r) for _, r in group.iterrows()}
        table_rows.append(tuple([engine, solver] + [cells.get(n, "—") for n in names]))
    notes = hard[hard["status"] == OK].drop_duplicates("metric")
    return [Paragraph("Hard targets (✓ solved, ✗ the reason; position residual):"),
            Table(tuple(["engine", "solver"] + [n.removeprefix("hard_") for n in names]), tuple(table_rows)),
            Bullets(tuple(f"`{r['metric'].removeprefix('hard_')}`: {r['detail'].split('; ')[-1]}"
                          for _, r in notes.iterrows()))]


def _dynamics_verdicts(rows: pd.DataFrame) -> Table:
    """Engine x integrator against each time step: the status each case earned."""
    per_dt = rows[rows["dt"].notna()]
    dts = sorted(per_dt["dt"].unique())
    out = []
    for (engine, integrator), group in per_dt.groupby(["engine", "integrator"], sort=False):
        status = {dt: case_status(g["status"]) for dt, g in group.groupby("dt")}
        out.append(tuple([engine, integrator] + [status.get(dt, "—") for dt in dts]))
    return Table(tuple(["engine", "integrator"] + [f"dt {dt:g} s" for dt in dts]), tuple(out))


def _verdict_line(name: str, rows: pd.DataFrame) -> str:
    """One line per hard dynamics scene (or sweep: its variants' cases together): how many cases earned each
    status, and which diverged."""
    per_dt = rows[rows["dt"].notna()]
    statuses = per_dt.groupby(["scene", "engine", "integrator", "dt"], sort=False)["status"].agg(case_status)
    counts = statuses.value_counts()
    diverged = sorted({f"{e} {i}" for (_, e, i, _), s in statuses.items() if s == "diverged"})
    text = f"**{name}**: " + ", ".join(f"{s} {counts[s]}" for s in STATUSES if s in counts)
    return text + (f"; diverged: {_names(diverged)}" if diverged else "")


def _hard_cases(table: pd.DataFrame, info: RunInfo, groups: dict[str, str]) -> list[Block]:
    """The verdict every engine earned on each scene of the hard suite in the run; a sweep's variants (``groups``:
    {variant: its sweep's label}) share one line, with no grid of their own (the sweep's section has one)."""
    names = [name for name, about in info.scenes.items() if "hard" in about.get("suites", ())]
    names = [name for name in names if (table["scene"] == name).any()]
    if not names:
        return []
    table = table.assign(_group=table["scene"].map(lambda scene: groups.get(scene, scene)))
    scenes = list(dict.fromkeys(groups.get(name, name) for name in names))
    swept = set(groups.values())
    blocks: list[Block] = [
        Heading(2, "Hard cases"),
        Paragraph("The `hard` suite's numerical-stability cases: `diverged` when a conserved quantity or a speed left "
                  "its bound, `ok` when it stayed bounded; the verdict each must earn is in the shipped tolerances.")]
    lines = []
    for name in scenes:
        rows = table[table["_group"] == name]
        if _kind(rows) == "ik":
            solved, total = _hard_solved(rows)
            lines.append(f"**{name}**: {solved} of {total} hard IK solves succeeded")
        else:
            lines.append(_verdict_line(name, rows))
    blocks.append(Bullets(tuple(lines)))
    for name in (name for name in scenes if name not in swept):
        rows = table[table["scene"] == name]
        grid = _hard_table(rows) if _kind(rows) == "ik" else [_dynamics_verdicts(rows)]
        blocks.append(Details(f"{name}: every verdict", tuple(grid), markdown=False))
    return blocks


def _kind(rows: pd.DataFrame) -> str:
    if (rows["metric"] == SOLVE_RATE).any():
        return "ik"
    if (rows["metric"] == MASS_MATRIX_ERROR_MAX).any():
        return "joint_dynamics"
    return "dynamics" if rows["dt"].notna().any() else "kinematics"


_UNRESOLVED_RANK = {FAILED: 0, DIVERGED: 1}
"""The order of the rows of cases without a result: failed, then diverged, then n/a (stable within each), so that a
report.md over its line budget keeps what broke."""


def _predictability(rows: pd.DataFrame) -> list[Block]:
    """A chaotic scene's predictability at its finest time step (Chung and Pollard): when each scheme's run parts
    from its own run from a perturbed start, beside when it parts from the reference; nothing where not measured."""
    parting = rows[rows["metric"].isin([SELF_PARTING_TIME, REFERENCE_PARTING_TIME]) & rows["dt"].notna()]
    if parting.empty:
        return []
    finest = parting[parting["dt"] == parting["dt"].min()]
    cells = {(r["engine"], r["integrator"], r["metric"]): (f"{r['value']:.3g}" if r["status"] == OK else "not within "
                                                             "the run" if "whole run" in str(r["detail"]) else r["status"])
             for _, r in finest.iterrows()}
    cases = list(dict.fromkeys(zip(finest["engine"], finest["integrator"])))
    return [Paragraph(f"Predictability at dt = {finest['dt'].iloc[0]:g} s: when each scheme's run parts (a joint 1e-3 "
                      "rad off) from its own run from a start perturbed by the scene's perturbation, and from the "
                      "reference's; parting from the reference no later than from itself is the chain's chaos, not a "
                      "defect."),
            Table(("engine", "integrator", "parts from itself [s]", "parts from the reference [s]"),
                  tuple((e, i, cells.get((e, i, SELF_PARTING_TIME), "—"), cells.get((e, i, REFERENCE_PARTING_TIME), "—"))
                        for e, i in cases))]


def _heading_kind(about: dict, kind: str) -> str:
    return summary.heading_kind(kind, about.get("headline_metric", ""))


def _headline(about: dict) -> str:
    return about.get("headline_metric", POSITION_ERROR_MAX)


def _scheme(case: pd.Series | None, unit: str) -> str:
    """A case the summary picked for its accuracy: ``mujoco rk4 @ 0.01: 1.09e-08 rad``."""
    if case is None:
        return "none"
    return f"{case['engine']} {case['integrator']} @ {number(case['dt'])}: {number(case['error'])} {unit}"


def _ranking_text(by: str) -> str:
    """What the summary ranks by, and why that is fair."""
    truths = f"Ground truths ({', '.join(GROUND_TRUTH_ENGINES)}) are not ranked."
    if by == summary.WALL:
        return ("Ranked by wall time per simulated second [s/s]: this run has no force evaluation counts (its "
                "engines declare no stages). Within one engine that is fair (its per-call overhead is shared); across "
                f"engines it also measures each one's overhead per call. {truths}")
    return ("Ranked by force evaluations per simulated second (stages / dt: Hairer's hardware-neutral work, blind to "
            "per-call overhead), ties by wall time: \"cheapest\" counts force evaluations, never the clock, and each "
            "pick shows them (\"400/s\") beside its measured wall time per simulated second (\"2.1 ms\"; "
            "report.html has it per scheme, and the batched time). "
            f"{truths[:-1]}; schemes without a stage count only within their engine.")


_OVERHEAD_MARK = "†"


def _overhead_mark(engine: str, about: dict) -> str:
    """A mark on core's time when the scene's batch is small enough for per-call overhead to dominate."""
    bodies = about.get("bodies")
    return f" {_OVERHEAD_MARK}" if engine == "core" and bodies is not None and bodies < summary.OVERHEAD_DOMINATED_BODIES else ""


@dataclass(frozen=True)
class _Contact:
    """What a contact scene's section adds: its height figure, per engine (its measured restitution's range, its
    worst penetration) as cells, and its blocks after the tables."""

    figure: list[Block]
    per_engine: dict[str, tuple[str, str]]
    blocks: list[Block]


def _value_range(values: pd.Series) -> str:
    """``0.486-0.601``: the range of the measured values; one value as itself; none as an em dash."""
    measured = values.dropna()
    if measured.empty:
        return "—"
    low, high = number(float(measured.min())), number(float(measured.max()))
    return low if low == high else f"{low}-{high}"


class _Builder:
    def __init__(self, table: pd.DataFrame, info: RunInfo, series: pd.DataFrame, verdict: ToleranceVerdict | None,
                 figure_dir: Path, writer: figures.FigureWriter, sweeps: list[Sweep]) -> None:
        self.table, self.info, self.series, self.verdict = table, info, series, verdict
        self.figure_dir, self.writer = figure_dir, writer
        self.svgs: dict[str, concurrent.futures.Future] = {}
        self.sweeps = sweeps
        self.sweep_of = {name: sweep for sweep in sweeps for name in sweep.variants}
        self.groups = sweep_summary.groups(sweeps)
        self.counts = sweep_summary.counts(sweeps)
        self.cases = {scene: summary.dynamics_cases(rows, _headline(self.about(scene)))
                      for scene, rows in table.groupby("scene", sort=False)
                      if _kind(rows) == "dynamics" and scene not in self.sweep_of}
        self.joint_dynamics_scenes = [scene for scene, rows in table.groupby("scene", sort=False)
                                      if _kind(rows) == "joint_dynamics"]
        ranked = list(self.cases.values()) + [s.across for s in sweeps if s.kind == "dynamics"]
        self.by = summary.ranking_cost(pd.concat(ranked)) if ranked else summary.WALL
        self.findings_per_scene: Counter = Counter()
        self._choices: dict[str, dict] = {}

    def choices(self, scene: str, cases: pd.DataFrame) -> dict:
        """Each engine's choices on ``scene`` (:func:`reports.engine_summary.choices`), computed once for the
        summary's tally and the scene's table."""
        if scene not in self._choices:
            self._choices[scene] = engine_summary.choices(cases, self.by)
        return self._choices[scene]

    def findings_of(self, scene: str) -> int:
        """How many rows of the flagged findings are about ``scene`` (a sweep's variant: about its sweep)."""
        return self.findings_per_scene.get(self.groups.get(scene, scene), 0)

    def listed(self, scene: str) -> bool:
        """Whether ``scene`` has a section of its own: a scene outside a sweep, or a variant the sweep shows."""
        return scene not in self.sweep_of or scene in self.sweep_of[scene].shown

    def about(self, scene: str) -> dict:
        return self.info.scenes.get(scene, {})

    def figure(self, fig, name: str, caption: str) -> list[Block]:
        if fig is None:
            return []
        name = figures.figure_stem(name)  # a stored run's scene name never leads out of figures/
        self.svgs[name] = self.writer.submit(fig, self.figure_dir, name)
        return [Figure(name, caption)]

    def own_engines(self) -> list[Block]:
        """"Is my engine right?" for each user's engine the gate holds (:mod:`reports.own_engine`)."""
        verdict = self.verdict
        findings: dict[str, tuple[str, ...]] | None = None
        if verdict is not None:
            findings = {}
            for engine, line in zip(verdict.engines, verdict.violations):
                findings[engine] = findings.get(engine, ()) + (_clip(line, LINE_CHARS - 10),)
        headlines = {scene: _headline(about) for scene, about in self.info.scenes.items()}
        return own_engine.sections(self.table, headlines, verdict.held if verdict else None, findings)

    # -- summary -------------------------------------------------------------------------------

    def summary(self) -> list[Block]:
        blocks: list[Block] = [Heading(2, "Summary")]
        dyn_rows: list[tuple[str, ...]] = []
        ik_rows: list[tuple[str, ...]] = []
        swept: set[str] = set()
        by = self.by
        for scene, rows in self.table.groupby("scene", sort=False):
            kind, about = _kind(rows), self.about(scene)
            if scene in self.sweep_of:
                sweep = self.sweep_of[scene]
                if sweep.base not in swept and kind in ("dynamics", "ik"):
                    (dyn_rows if kind == "dynamics" else ik_rows).append(_sweep_row(sweep, by))
                swept.add(sweep.base)
            elif kind == "dynamics":
                name, unit = _HEADLINE_NAMES[_headline(about)]
                cases = self.cases[scene]
                cells = [f"[{scene}](#{scene_heading(scene, _heading_kind(about, kind)).anchor})",
                         f"{name.removesuffix(' error max')} [{unit}] vs `{rows['reference'].iloc[0]}`"]
                cells += [engine_summary.overall(cases, b, by) for b in summary.ERROR_BUDGETS]
                cells += [_scheme(summary.most_accurate_within(cases, b, by), unit) for b in summary.cost_budgets(by)]
                dyn_rows.append(tuple(cells))
            elif kind == "ik":
                best, fastest = summary.best_ik(summary.ik_solvers(rows[~rows["metric"].str.startswith("hard_")]))
                tolerance = about.get("position_tolerance")
                ik_rows.append((f"[{scene}](#{scene_heading(scene, kind).anchor})", _solver(best, tolerance),
                                _solver(fastest, tolerance)))
        if dyn_rows:
            blocks += [Heading(3, "Which integrator?"), Paragraph(_ranking_text(by)), *self.per_engine_table(),
                       Table(("scene", "error (reference)") + tuple(engine_summary.cheapest_head(by, b)
                                                                    for b in summary.ERROR_BUDGETS)
                             + tuple(f"most accurate at {summary.cost_label(by, b)}" for b in summary.cost_budgets(by)),
                             tuple(dyn_rows), trim_order=SCENE_SUMMARY_TRIM_ORDER, keep_at_least=0),
                       *([_SWEEP_ROWS_DYNAMICS] if any(s.kind == "dynamics" for s in self.sweeps) else [])]
        if ik_rows:
            blocks += [Heading(3, "Which IK solver?"),
                       Paragraph(f"Best solve rate (the faster on a tie) and the fastest at ≥ "
                                 f"{summary.SOLVED_ENOUGH:.0%}, at the scene's position tolerance (a solver with a "
                                 "looser rule of its own: its rate at that rule beside it)."),
                       Table(("scene", "best solve rate", f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}"),
                             tuple(ik_rows)),
                       *([_SWEEP_ROWS_IK] if any(s.kind == "ik" for s in self.sweeps) else [])]
        return blocks + self.joint_dynamics_summary() + self.findings() + self.unresolved()

    def joint_dynamics_summary(self) -> list[Block]:
        """One line per engine and method over the run's joint-dynamics scenes (two or more): its worst error against the
        references and its worst identity residual (the section "Joint-space dynamics" has them per scene)."""
        rows = self.table[self.table["scene"].isin(self.joint_dynamics_scenes)]
        if len(self.joint_dynamics_scenes) < 2:  # one scene: its section's table says the same
            return []
        cells = [f"{engine} {method} {_worst_cell(case)}"
                 for (engine, method), case in rows.groupby(["engine", "integrator"], sort=False)]
        return [Paragraph(f"**Joint-space dynamics** over {len(self.joint_dynamics_scenes)} scenes, each engine's "
                          "worst relative error of M, h, tau and qddot against the references, then (\"id\") its "
                          "worst identity residual: " + "; ".join(cells) + ".")]

    def per_engine_table(self) -> list[Block]:
        """The per-engine answer over the run's dynamics scenes (sweeps have theirs in their section): how often each
        scheme of an engine was its own cheapest within each error budget and most accurate within each cost
        budget."""
        per_scene = [self.choices(scene, cases) for scene, cases in self.cases.items()]
        if not per_scene:
            return []
        tallies = engine_summary.tally(per_scene, self.info.integrator_variants)
        columns = [f"error ≤ {b:g}" for b in summary.ERROR_BUDGETS] + [summary.cost_label(self.by, b)
                                                                       for b in summary.cost_budgets(self.by)]
        head = ("engine",) + tuple(engine_summary.cheapest_head(self.by, b) for b in summary.ERROR_BUDGETS) + tuple(
            f"most accurate at {c}" for c in columns[len(summary.ERROR_BUDGETS):])
        return [Paragraph(f"Each engine's own scheme (its variants together) over {len(per_scene)} scenes (\"rk4 ×9\": "
                          "on 9; \"none\": no "
                          "scheme of it reached the budget; n/a, diverged: why it had none), then the overall best per "
                          "scene (\"+k as cheap\": k others do the same work)."),
                Table(head, tuple((_ran_on(engine, per_scene),) + tuple(cells.get(c, "none") for c in columns)
                                  for engine, cells in tallies.items()))]

    def merged(self, frame: pd.DataFrame, keys: list[str], **aggregations) -> pd.DataFrame:
        """``frame`` with each sweep's variants merged (:func:`reports.sweep_summary.merge_variants`); as it is in a
        run without a sweep."""
        return merge_variants(frame, self.groups, keys, **aggregations) if self.groups else frame

    def in_variants(self, row: pd.Series, lead: str = " ") -> str:
        """"in K of N variants" after ``lead`` for a row standing for a sweep's variants; nothing for a scene of its
        own."""
        count = self.counts.get(row["scene"])
        return f"{lead}in {row['variants']} of {count} variants" if count else ""

    def findings(self) -> list[Block]:
        """Flagged findings as one table: a row per finding x scene x engine, its schemes, time steps, largest value
        and what it means; then the tolerances' verdict, with every metric outside its bound folded below."""
        rows: list[tuple[str, ...]] = []
        gains = self.merged(summary.energy_gains(self.series), ["engine", "integrator"],
                            gain_max=("gain_max", "max"), dts=("dts", union))
        rows += self.finding_rows("energy gained", gains, "gain_max",
                                  "the scene conserves energy: (E - E(0)) / the body's energy scale rose")
        flags = self.merged(summary.contact_flags(self.table), ["metric", "engine", "integrator"],
                            value_max=("value_max", "max"), dts=("dts", union))
        for metric, g in flags.groupby("metric", sort=False):
            what, meaning = (("energy gained at an impact", f"`{metric}`: an impact gave the body energy")
                             if metric == ENERGY_GAIN_MAX else ("tunnelling", f"`{metric}`: a body went through a plane"))
            rows += self.finding_rows(what, g, "value_max", meaning)
        saturated = self.merged(summary.saturated(self.table), ["metric"], n_cases=("n_cases", "sum"))
        for scene, g in saturated.groupby("scene", sort=False):
            counted = ", ".join(f"`{r['metric']}` {r['n_cases']}{self.in_variants(r, ' ')}" for _, r in g.iterrows())
            rows.append(("saturated", scene, counted, "", "", "n/a: the error reached its quantity's scale and lost all "
                         "meaning (cases counted per metric)"))
        rows += self.order_findings()
        self.findings_per_scene = Counter(row[1] for row in rows)
        blocks: list[Block] = [Heading(3, "Flagged findings")]
        if rows:
            blocks.append(Table(("finding", "scene", "engine × scheme (or metric: cases)", "dt [s]", "largest",
                                 "what it means"), tuple(rows), trim_order=2))
        blocks.append(Paragraph(self.tolerance_line()))
        if self.verdict and self.verdict.violations:
            blocks.append(Details(f"{self.verdict.outside_count} metrics outside their bounds",
                                  (Bullets(tuple(f"`{_clip(v, LINE_CHARS - 10)}`" for v in self.verdict.violations)),)))
        return blocks

    def finding_rows(self, finding: str, frame: pd.DataFrame, value: str, meaning: str) -> list[tuple[str, ...]]:
        """One row per scene of ``frame`` (scene, engine, integrator, ``value``, dts): its engines' schemes named
        compactly, the time steps' range and the largest value."""
        out: list[tuple[str, ...]] = []
        for scene, g in frame.groupby("scene", sort=False):
            out.append((finding, scene, _per_engine(g, self.in_variants), _dt_range(union(g["dts"])),
                        number(g[value].max()), meaning))
        return out

    def tolerance_line(self) -> str:
        """The tolerances' verdict in one sentence."""
        verdict = self.verdict
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

    def order_findings(self) -> list[tuple[str, ...]]:
        """One row per scene x flag x engine of order fits flagged as findings (:func:`reports.summary.order_findings`),
        each scheme with its fitted orders."""
        what = {"not-converging": ("orders that do not converge", "errors far from saturation and rounding that do "
                                   "not fall with dt: an alarm"),
                "below-theory": ("orders below theory", "clean fits more than 0.5 under the scheme's order"),
                "superconvergent": ("superconvergent orders", "clean fits more than 0.5 above the scheme's order: "
                                    "error terms cancel, or the steps are before the asymptotic range"),
                "pre-asymptotic": ("orders not in the asymptotic range", "local slopes disagree: finer steps needed")}
        rows: list[tuple[str, ...]] = []
        for (scene, flag), g in summary.order_findings(self.table).groupby(["scene", "flag"], sort=False):
            fitted = g.assign(integrator=[f"{r['integrator']} " + "/".join(number(v) if v == v else "n/a"
                                                                            for v in r["values"]) for _, r in g.iterrows()])
            rows.append((what[flag][0], scene, _per_engine(fitted, lambda r, lead: ""), "", "", what[flag][1]))
        return rows

    def unresolved(self) -> list[Block]:
        """Every case without a result, as one table: a row per status and kind of reason (:func:`_reason_kind`: the
        same words, other numbers), with the scenes, engines and schemes it covers, the count and the time steps."""
        cases = summary.unresolved_cases(self.table)
        if cases.empty:
            return [Heading(3, "Cases without a result"), Paragraph("None: every case was measured.")]
        cases = self.merged(cases, ["status", "order_fit", "engine", "integrator", "reason"],
                            n_cases=("n_cases", "sum"), dts=("dts", union))
        cases = cases.assign(kind=cases["reason"].fillna("").map(_reason_kind))
        rows = []
        for (status, order_fit, _), g in cases.groupby(["status", "order_fit", "kind"], sort=False, dropna=False):
            label = status if status != NOT_AVAILABLE else f"n/a ({'order fit' if order_fit else 'run'})"
            rows.append((label, _names(list(dict.fromkeys(g["scene"]))), _per_engine(g, self.in_variants),
                         str(g["n_cases"].sum()), _dt_range(union(g["dts"])),
                         _clip(g["reason"].iloc[0] or "no reason given", REASON_CHARS)
                         + (f" (and {g['reason'].nunique() - 1} more like it)" if g["reason"].nunique() > 1 else "")))
        rows.sort(key=lambda row: _UNRESOLVED_RANK.get(row[0], len(_UNRESOLVED_RANK)))  # what broke first
        return [Heading(3, "Cases without a result"),
                Table(("status", "scenes", "engine × scheme", "cases", "dt [s]", "reason (the first; others alike but for "
                       "their numbers; each in full: its `detail` in `results.csv`)"), tuple(rows), trim_order=1)]

    # -- scenes --------------------------------------------------------------------------------

    def introduction(self, scene: str, rows: pd.DataFrame) -> str:
        """What the scene is (a sweep's variant: its values), its reference and the name of its file (run.json has
        the path)."""
        about = self.about(scene)
        sweep = about.get("sweep")
        shown = (f" ({sweep_sections.roles(self.sweep_of[scene], scene)})"
                 if scene in self.sweep_of and scene in self.sweep_of[scene].shown else "")
        return ((f"{about['description']} " if about.get("description") else "")
                + (f"Variant {sweep['index'] + 1} of {sweep['count']} of the [sweep of {sweep['base']}]"
                   f"(#{sweep_sections.heading(sweep['base']).anchor}){shown}: "
                   + ", ".join(f"`{key}` = {value}" for key, value in sweep["values"].items()) + ". " if sweep else "")
                + f"Reference: `{rows['reference'].iloc[0]}`."
                + (f" Scene file: `{Path(about['source']).name}`." if about.get("source") else ""))

    def scene(self, scene: str, rows: pd.DataFrame) -> list[Block]:
        """The section of a dynamics or IK scene: its verdict in one line and what the scene is, then its figures
        and tables."""
        kind, about = _kind(rows), self.about(scene)
        reference = rows["reference"].iloc[0]
        series = self.series[self.series["scene"] == scene]
        run = self.dynamics if kind == "dynamics" else self.ik
        verdict, body = run(scene, rows, about, reference, series)
        lead = Bullets((f"**Verdict**: {verdict}", f"**Scene**: {self.introduction(scene, rows)}"))
        return [scene_heading(scene, _heading_kind(about, kind)), lead, *body, *_notes(rows)]

    def kinematics(self, rows: pd.DataFrame) -> list[Block]:
        """One section for every kinematics scene: in report.md each scene's frame position error per engine (the
        status where it was not measured); in report.html frame and Jacobian errors and times per scene × engine."""
        scenes = list(dict.fromkeys(rows["scene"]))
        engines = list(dict.fromkeys(rows["engine"]))
        compact = []
        for scene in scenes:
            own = rows[rows["scene"] == scene]
            cells = []
            for engine in engines:
                cell = own[(own["engine"] == engine) & (own["metric"] == POSITION_ERROR_MAX)]
                cells.append("—" if cell.empty else number(cell["value"].iloc[0]) if cell["status"].iloc[0] == OK
                             else cell["status"].iloc[0])
            compact.append((scene, *cells))
        full = tables.metric_table(rows, tables.KINEMATICS_COLUMNS, ["scene", "engine"])
        blocks: list[Block] = [Heading(2, "Kinematics"),
                               Bullets(tuple(f"**{scene}**: {self.introduction(scene, rows[rows['scene'] == scene])}"
                                             for scene in scenes)),
                               Paragraph("Frame position error max [m] against each scene's reference; orientation and "
                                         "Jacobian errors, times and the reasons for n/a: the HTML report."),
                               Table(("scene", *engines), tuple(compact)),
                               Details("Every kinematics metric", (full,), markdown=False, open=True)]
        return blocks + _notes(rows)

    def joint_dynamics(self, rows: pd.DataFrame) -> list[Block]:
        """One section for every joint-dynamics scene: in report.md each scene's worst relative error (of M, h, tau
        and qddot against the reference) per engine and method, and its worst identity residual; in report.html every
        metric per scene x engine x method."""
        scenes = list(dict.fromkeys(rows["scene"]))
        cases = list(dict.fromkeys(zip(rows["engine"], rows["integrator"])))
        cells = {(scene, case): _worst_cell(rows[(rows["scene"] == scene) & (rows["engine"] == case[0])
                                                 & (rows["integrator"] == case[1])])
                 for scene in scenes for case in cases}
        labels = [f"{e} {m}" for e, m in cases]
        by_scene = Table(("scene", *labels), tuple((scene, *(cells[scene, c] for c in cases)) for scene in scenes))
        by_engine = Table(("engine method", *scenes), tuple((label, *(cells[s, c] for s in scenes))
                                                            for label, c in zip(labels, cases)))
        # a row per scene when its row fits a line (few lines in a default run), else the fewer of the two across
        fits = _row_width(by_scene) <= LINE_CHARS
        table = by_scene if fits or len(cases) <= len(scenes) else by_engine
        full = tables.metric_table(rows, tables.JOINT_DYNAMICS_COLUMNS, ["scene", "engine", "integrator"])
        blocks: list[Block] = [Heading(2, "Joint-space dynamics"),
                Bullets(tuple(f"**{scene}**: {self.introduction(scene, rows[rows['scene'] == scene])}"
                              for scene in scenes)
                        + ("Each cell: the largest relative error of M, h, tau (RNEA) and qddot (ABA) against the "
                           "reference, then ('id') the largest residual of the identities of the engine's own outputs; "
                           "each metric, times and the reasons for n/a: the HTML report (docs/metrics.md).",)),
                table, Details("Every joint-dynamics metric", (full,), markdown=False, open=True)]
        return blocks + _notes(rows)

    def dynamics(self, scene, rows, about, reference, series) -> tuple[str, list[Block]]:
        """(the scene's verdict in one line, its blocks): figures, a row per engine in report.md (its most accurate
        scheme, its cheapest within each error budget, its orders or contact measures, its cases), and in report.html
        the row per engine × integrator and every engine × integrator × dt."""
        headline = _headline(about)
        name, unit = _HEADLINE_NAMES[headline]
        cases = self.cases[scene] if scene in self.cases else summary.dynamics_cases(rows, headline)
        observed = summary.orders(rows, headline)
        theory = self.info.theoretical_orders
        blocks = self.figure(figures.work_precision_figure(scene, cases, headline, reference,
                                                           self.info.integrator_variants),
                             f"{scene}-work-precision",
                             f"Work-precision: x = {name} [{unit}] (log), y = wall time per simulated second [s/s] "
                             "(log; below, where counted: force evaluations per simulated second, the hardware-neutral "
                             "cost); one point per dt, lower left is better. A scheme's variants share its colour, one "
                             "marker each; dotted: the summary's error budgets.")
        if not about.get("contact"):  # with contact the error has no order (impacts), so no convergence figure
            order_rows = rows[rows["dt"].isna() & (rows["metric"] == summary.ORDER_METRICS[headline])
                              & (rows["status"] != OK)]
            unfitted = {(r["engine"], r["integrator"]): r["detail"] for _, r in order_rows.iterrows()}
            blocks += self.figure(figures.convergence_figure(scene, cases, headline, reference, observed, theory,
                                                             unfitted),
                                  f"{scene}-convergence", f"Convergence: x = time step dt [s] (log), y = {name} "
                                  f"[{unit}] (log); observed order (theory) in the legend, grey dashed: a line of each "
                                  "theoretical order's slope; schemes whose errors agree to 0.1 % share one line.")
        blocks += self.figure(figures.drift_figure(scene, series, reference), f"{scene}-drift",
                              "Drift over time at the coarsest dt, from the stored series.")
        fits = engine_summary.fitted_orders(rows, headline, theory)
        contact = self.contact(scene, rows, about, reference, series) if about.get("contact") else None
        blocks += contact.figure if contact else []
        blocks += [self.per_engine(scene, cases, fits, unit, contact), self.per_scheme(cases, observed, about, unit)]
        blocks += contact.blocks if contact else []
        blocks += _predictability(rows)
        columns, order_columns = ((tables.JOINT_MOTION_COLUMNS, tables.JOINT_ORDER_COLUMNS)
                                  if headline == JOINT_ANGLE_ERROR_MAX else (tables.DYNAMICS_COLUMNS, tables.ORDER_COLUMNS))
        full: list[Block] = [tables.metric_table(rows[rows["dt"].notna()], columns, ["engine", "integrator", "dt"])]
        orders = rows[rows["dt"].isna()]
        if not orders.empty:
            explained: list[Block] = [
                Paragraph("Observed order of convergence: slope of log(error max) against log(dt) over the finest "
                          "time steps whose local slopes agree; errors at the rounding floor or saturated are left out."),
                tables.metric_table(orders, order_columns, ["engine", "integrator"])]
            full += explained + _fits(orders)
        verdict = engine_summary.dynamics_verdict(cases, fits, self.findings_of(scene), unit,
                                                  engine_summary.order_alarms(rows, headline))
        return verdict, blocks + [Details(f"{scene}: every engine × integrator × dt", tuple(full), markdown=False)]

    def per_engine(self, scene: str, cases: pd.DataFrame, fits: pd.DataFrame, unit: str,
                   contact: _Contact | None) -> Table:
        """report.md's table of a dynamics scene: a row per engine (the user's first) with its most accurate scheme,
        its cheapest within each error budget (by the summary's cost), its fitted orders against theory (a contact
        scene: its measured restitution and worst penetration) and how its cases ended."""
        choices = self.choices(scene, cases)
        rows = []
        for engine, picks in choices.items():
            own = cases[cases["engine"] == engine]
            best = engine_summary.most_accurate(own)
            accurate = engine_summary.pick(best if best is not None else engine_summary.unmeasured(own), self.by,
                                           show_error=True)
            ranked_by = engine_summary.own_cost(own, self.by)
            budgets = [engine_summary.pick(picks[f"error ≤ {b:g}"], ranked_by, show_error=False)
                       for b in summary.ERROR_BUDGETS]
            measures = (contact.per_engine.get(engine, ("—", "—")) if contact else
                        (engine_summary.orders_text(fits[fits["engine"] == engine]),))
            statuses = ", ".join(f"{k} {n}" for k, n in own["status"].value_counts().items())
            rows.append((engine, accurate, *budgets, *measures, statuses))
        measured = (("restitution measured", "penetration max [m]") if contact else ("orders vs theory",))
        return Table(("engine", f"most accurate [{unit}]") + tuple(engine_summary.cheapest_head(self.by, b)
                                                                 for b in summary.ERROR_BUDGETS)
                     + measured + ("cases",), tuple(rows))

    def per_scheme(self, cases: pd.DataFrame, observed: dict, about: dict, unit: str) -> Details:
        """Per engine × integrator (variants of a scheme on one row): the time step of least error with its error,
        wall time, force evaluations and batched time per simulated second, time per step, observed order (theory)
        and how its time steps ended; unfolded in report.html, not in report.md (which has a row per engine)."""
        theory = self.info.theoretical_orders
        best = summary.best_per_scheme(cases)
        variants = self.info.integrator_variants
        per_scheme: dict[tuple[str, str], list[tuple[str, tuple[str, ...]]]] = {}
        for _, b in best[best["any_result"]].iterrows():
            p = theory.get(b["engine"], {}).get(b["integrator"])
            fitted = observed.get((b["engine"], b["integrator"]), math.nan)
            scheme, variant = variants.get(b["engine"], {}).get(b["integrator"], (b["integrator"], ""))
            per_scheme.setdefault((b["engine"], scheme), []).append((variant, (
                number(b["dt"]), number(b["error"]), number(b["cost"]), number(b[summary.EVALUATIONS]),
                number(b["batched_cost"]), number(b[TIME_PER_STEP]) + _overhead_mark(b["engine"], about),
                f"{number(fitted)} ({p})" if p else number(fitted), b["statuses"])))
        table = Table(("engine", "integrator", "best dt [s]", f"error [{unit}]", "cost [s/s]", "evaluations [1/s]",
                       "batched cost [s/s]", "time per step [s]", "order (theory)", "time steps"),
                      tuple(_scheme_row(engine, scheme, members) for (engine, scheme), members in per_scheme.items()))
        return Details("Per engine × integrator: the time step of least error (batched cost: one copy's share of a "
                       "batch stepped together, where the engine can batch)", (table,), markdown=False, open=True)

    def contact(self, scene, rows, about, reference, series) -> _Contact:
        """The height figure; per engine its measured restitution's range and worst penetration; in report.html the
        contact table (restitution at every dt, the worst penetration and energy gain, errors at the finest dt); the
        penalty method's measured stability limits (one line in report.md, with how each was found in the HTML)."""
        figure = self.figure(figures.contact_height_figure(scene, series, reference), f"{scene}-height",
                             "Height of the lowest point above the plane against time, from the stored series.")
        cases = summary.contact_cases(rows)
        dts = sorted(cases["dt"].unique())
        requested = sorted({k for row in about["contact"]["restitution"] for k in row})
        table = []
        for (engine, integrator), g in cases.groupby(["engine", "integrator"], sort=False):
            g = g.sort_values("dt")
            finest = g[g["status"] == OK].head(1)
            at = (lambda m: number(float(finest[m].iloc[0])) if not finest.empty else "—")
            table.append((engine, integrator)
                         + tuple(number(float(g.loc[g["dt"] == dt, RESTITUTION_MEASURED].max())) for dt in dts)
                         + (number(float(g[PENETRATION_MAX].max())), number(float(g[ENERGY_GAIN_MAX].max())),
                            at("dt"), at(IMPACT_TIME_ERROR), at(APEX_HEIGHT_ERROR), at(REST_TIME_ERROR),
                            at(STOPPING_DISTANCE), " · ".join(dict.fromkeys(g["status"]))))
        per_engine = {engine: (_value_range(g[RESTITUTION_MEASURED]), number(float(g[PENETRATION_MAX].max())))
                      for engine, g in cases.groupby("engine", sort=False)}
        blocks: list[Block] = [Details(
            f"Contact, per engine × integrator: requested restitution {', '.join(f'{k:g}' for k in requested)}",
            (Paragraph("Restitution measured from each run's first rebound (v_out / |v_in|, extrapolated along the "
                       "free flight from the samples either side), at each dt. Penetration and energy gained: the "
                       "worst over the time steps; the errors after them at the finest time step measured (named)."),
             Table(("engine", "integrator") + tuple(f"restitution at dt {dt:g}" for dt in dts)
                   + ("penetration max [m]", "energy gained max (rel.)", "finest ok dt [s]", "impact time error [s]",
                      "apex height error [m]", "rest time error [s]", "stopping distance [m]", "time steps"),
                   tuple(table))), markdown=False, open=True)]
        limits = summary.stability_limits(rows)
        if not limits.empty:
            values = "; ".join(f"{r['engine']} {r['integrator']} "
                               + (f"{number(r['value'])} s" if r["status"] == OK else r["status"])
                               for _, r in limits.iterrows())
            items = tuple(f"{r['engine']} {r['integrator']}: {r['detail']}" for _, r in limits.iterrows())
            blocks += [Paragraph("Penalty method, measured stability limit (the largest step that neither blows up "
                                 f"nor gains energy at an impact): {values}."),
                       Details("How each stability limit was found", (Bullets(items),), markdown=False)]
        return _Contact(figure, per_engine, blocks)

    def ik(self, scene, rows, about, reference, series) -> tuple[str, list[Block]]:
        """(the scene's verdict in one line, its blocks): figures, a row per engine in report.md (its best solver and
        its fastest reliable one), and in report.html the row per solver, every metric and the hard targets."""
        solvers = summary.ik_solvers(rows[~rows["metric"].str.startswith("hard_")])
        tolerance = about.get("position_tolerance")
        blocks = self.figure(figures.ik_rate_figure(scene, solvers, reference), f"{scene}-solve-rate",
                             "Solve rate against time per solve.")
        blocks += self.figure(figures.ik_distribution_figure(scene, series, tolerance),
                              f"{scene}-residuals", "Distributions of the position residual [m] and the iterations.")
        blocks += self.figure(figures.fk_matrix_figure(scene, series), f"{scene}-fk-agreement",
                              "Cross-engine FK agreement on every solution [m].")
        per_engine = []
        for engine in engine_summary.engine_order(solvers["engine"], truths=True):
            own = solvers[solvers["engine"] == engine]
            best, fastest = summary.best_ik(own)
            solved = int((own[SOLVE_RATE] > 0).sum())
            per_engine.append((engine, _rate_and_time(best), _rate_and_time(fastest),
                               f"{solved} of {len(own)} solve any target"))
        blocks.append(Table(("engine", "best solve rate, time per solve", f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}",
                             "solvers"),
                            tuple(per_engine)))
        plain = rows[~rows["metric"].str.startswith("hard_")].rename(columns={"integrator": "solver"})
        measured = plain.groupby(["engine", "solver"], sort=False)["status"].transform(lambda s: (s != NOT_AVAILABLE).any())
        compact = [c for c in tables.IK_COLUMNS if c[0] in _IK_COMPACT]
        blocks.append(Details("Per engine × solver", (*_own_rules(solvers, tolerance),
                                                      tables.metric_table(plain[measured], compact, ["engine", "solver"])),
                              markdown=False, open=True))
        hard = _hard_table(rows)
        blocks.append(Details(f"{scene}: every metric and hard target",
                              (tables.metric_table(plain, tables.IK_COLUMNS, ["engine", "solver"]), *hard),
                              markdown=False))
        return _ik_verdict(solvers, tolerance, _hard_solved(rows), self.findings_of(scene)), blocks


def _ran_on(engine: str, per_scene: list[dict]) -> str:
    """An engine in the per-engine table: its name, and on how many of the scenes it ran where not on all."""
    ran = sum(engine in scene for scene in per_scene)
    return engine if ran == len(per_scene) else f"{engine} ({ran} of {len(per_scene)} scenes)"


def _rate_and_time(solver: pd.Series | None) -> str:
    """A solver in an engine's row: ``dls: 90.0 %, 0.000949 s``."""
    return "none" if solver is None else f"{solver['integrator']}: {solver[SOLVE_RATE]:.1%}, {number(solver[TIME_PER_SOLVE])} s"


def _ik_verdict(solvers: pd.DataFrame, tolerance: float | None, hard: tuple[int, int], findings: int) -> str:
    """An IK scene in one line: its best solver, its fastest reliable one, the solvers that solve nothing at the
    scene's tolerance, the hard targets solved and the findings."""
    best, fastest = summary.best_ik(solvers)
    reliable = f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}: " + ("the same" if fastest is not None and best is not None
                                                               and fastest.name == best.name
                                                               else _solver(fastest, tolerance))
    parts = [f"best {_solver(best, tolerance)}", reliable]
    none = [f"{r['engine']} {r['integrator']}" for _, r in solvers.iterrows() if r[SOLVE_RATE] == 0]
    if none:
        parts.append(f"{len(none)} solve none at the scene's tolerance ({_names(none, 2)})")
    if hard[1]:
        parts.append(f"hard targets: {hard[0]} of {hard[1]} solves succeeded")
    return "; ".join(parts + [f"{findings} finding{'s' if findings != 1 else ''}"])


def _scheme_row(engine: str, scheme: str, members: list[tuple[str, tuple[str, ...]]]) -> tuple[str, ...]:
    """One compact-table row for the variants of a scheme (core's orientation updates): each cell lists
    the variants' values in the order the integrator cell names them, or one value where they agree."""
    if len(members) == 1 and not members[0][0]:
        return (engine, scheme, *members[0][1])
    names = " / ".join(variant for variant, _ in members)
    cells = [cells for _, cells in members]
    return (engine, f"{scheme} ({names})",
            *(column[0] if len(set(column)) == 1 else " / ".join(column) for column in zip(*cells)))


_SWEEP_ROWS_DYNAMICS = Paragraph(
    "A sweep has one row, linked to its section: each engine × integrator × dt is ranked by its worst variant (its "
    "error the largest over the variants, its cost the median), and a case that is not ok in every variant is not "
    "ranked.")
_SWEEP_ROWS_IK = Paragraph(
    "A sweep has one row, linked to its section: each solver is ranked by its lowest solve rate over the variants and "
    "its median time per solve, and a solver not measured in every variant is not ranked.")


def _sweep_row(sweep: Sweep, by: str) -> tuple[str, ...]:
    """A sweep's row of the summary's table for its kind: its schemes judged by their worst variant."""
    link = (f"[{sweep_summary.label(sweep.base)}](#{sweep_sections.heading(sweep.base).anchor}) "
            f"({len(sweep.variants)} variants)")
    ranked = sweep.across[sweep.across["status"] == OK]
    if sweep.kind == "ik":
        best, fastest = summary.best_ik(ranked.rename(columns={"value": SOLVE_RATE, "cost": TIME_PER_SOLVE}))
        return link, _solver(best, None), _solver(fastest, None)
    name, unit = _HEADLINE_NAMES[sweep.metric]
    cases = ranked.rename(columns={"value": "error"})
    return ((link, f"{name.removesuffix(' error max')} [{unit}] vs `{sweep.reference}`")
            + tuple(engine_summary.overall(cases, b, by) for b in summary.ERROR_BUDGETS)
            + tuple(_scheme(summary.most_accurate_within(cases, b, by), unit) for b in summary.cost_budgets(by)))


NAMES_SHOWN = 4
"""Schemes or scenes a findings cell names before it counts the rest: a row stays one line."""

REASON_CHARS = 160
"""Characters of a reason in a findings table; the whole reason is the rows' ``detail`` in results.csv."""



_JOINT_DYNAMICS_ERRORS = (MASS_MATRIX_ERROR_MAX, BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX,
                          FORWARD_DYNAMICS_ERROR_MAX)
_JOINT_DYNAMICS_IDENTITIES = (GRAVITY_IDENTITY_RESIDUAL, MASS_COLUMN_RESIDUAL, ROUND_TRIP_RESIDUAL,
                              MASS_MATRIX_ASYMMETRY, KINETIC_ENERGY_RESIDUAL)


def _row_width(table: Table) -> int:
    """Characters of the table's widest markdown row ("| a | b |")."""
    return max(sum(len(str(cell)) + 3 for cell in row) + 1 for row in (table.head, *table.rows))


def _worst_cell(case: pd.DataFrame) -> str:
    """A joint-dynamics case in one cell: its worst error against the reference, then its worst identity residual
    ("id"); the case's status where nothing of either was measured; "—" where the case did not run."""
    if case.empty:
        return "—"
    ok = case[case["status"] == OK]
    parts = []
    for label, metrics in (("", _JOINT_DYNAMICS_ERRORS), ("id ", _JOINT_DYNAMICS_IDENTITIES)):
        values = ok[ok["metric"].isin(metrics)]["value"]
        parts.append(f"{label}{number(float(values.max()))}" if not values.empty else f"{label}n/a")
    if all(part.endswith("n/a") for part in parts):
        return str(case["status"].iloc[0]) if (case["status"] != OK).all() else "n/a"
    return " · ".join(parts)


def _names(names: list[str], shown: int = NAMES_SHOWN) -> str:
    """``a, b, c, d (+3 more)``: at most ``shown`` names, then the count of the rest."""
    return ", ".join(names[:shown]) + (f" (+{len(names) - shown} more)" if len(names) > shown else "")


def _per_engine(frame: pd.DataFrame, variants) -> str:
    """``core: rk4, midpoint (+3 more); mujoco: euler``: each engine's schemes (``integrator``) of ``frame``,
    ``variants(row, lead)`` adding how many of a sweep's variants a row stands for."""
    return "; ".join(f"{engine}: " + _names(list(dict.fromkeys(f"{r['integrator']}{variants(r, ' ')}"
                                                                for _, r in g.iterrows())))
                     for engine, g in frame.groupby("engine", sort=False))


_NUMBER = re.compile(r"[-+]?\d[\d.]*(?:e[-+]?\d+)?")


def _reason_kind(reason: str) -> str:
    """What a reason says, whatever its numbers and after its first clause (the engine's description): the key
    that groups "energy of rod rose by 1.05 x ..." with "energy of rod rose by 8.9 x ..."."""
    return _NUMBER.sub("#", reason.split("; ")[0])


def _dt_range(dts: list[float]) -> str:
    """``0.0025-0.01 (3)``: the range of time steps and how many; one step as itself; none as ""."""
    if not dts:
        return ""
    return f"{dts[0]:g}" if len(dts) == 1 else f"{min(dts):g}-{max(dts):g} ({len(dts)})"


def _clip(text: str, limit: int) -> str:
    """``text`` cut to ``limit`` characters with an ellipsis."""
    return text if len(text) <= limit else text[:limit - 1].rstrip() + "…"


def _solver(row: pd.Series | None, position_tolerance: float | None) -> str:
    """A ranked solver: its rate at the scene's ``position_tolerance`` [m] (None: not known), time per solve,
    and its rate at its own stopping rule where that rule is not the scene's."""
    if row is None:
        return "none"
    return f"{row['engine']} {row['integrator']}: {_rates(row, position_tolerance)}, {number(row[TIME_PER_SOLVE])} s"


def _rates(row: pd.Series, position_tolerance: float | None) -> str:
    """``97.0 %`` or ``0.0 % at 1e-06 m, 97.0 % at its own 0.0001 m``: the solve rate at the scene's tolerance
    [m], and at the solver's own stopping rule where it has one."""
    at = "" if position_tolerance is None else f" at {position_tolerance:g} m"
    text = f"{row[SOLVE_RATE]:.1%}{at}"
    if summary.own_rule_differs(row, position_tolerance):
        own = row[SOLVE_RATE_OWN_STOP]
        text += f", {'n/a' if pd.isna(own) else f'{own:.1%}'} at its own {row[OWN_STOP_POSITION_TOLERANCE]:g} m"
    return text


def _own_rules(solvers: pd.DataFrame, position_tolerance: float | None) -> list[Block]:
    """The solvers of an IK scene that stop by a rule of their own, each with both solve rates."""
    own = [f"{r['engine']} {r['integrator']}: {_rates(r, position_tolerance)}" for _, r in solvers.iterrows()
           if summary.own_rule_differs(r, position_tolerance) and pd.notna(r[SOLVE_RATE])]
    if not own:
        return []
    return [Paragraph("Solvers that stop by a rule of their own (a library's default threshold; the rule is in the "
                      f"`{SOLVE_RATE_OWN_STOP}` row's detail), at the scene's tolerance and at their own:"),
            Bullets(tuple(own))]


def build(table: pd.DataFrame, info: RunInfo, series: pd.DataFrame, verdict: ToleranceVerdict | None,
          run_dir: Path) -> tuple[list[Block], dict[str, str]]:
    """(the report's blocks, the SVG text of each figure by name); figures are written to
    ``run_dir/figures``, on one process per CPU. ``verdict``: the run held to tolerances, None if it was not."""
    with figures.FigureWriter() as writer:
        builder = _Builder(table, info, series, verdict, Path(run_dir) / FIGURES_DIR, writer,
                           sweep_summary.sweeps(table, info))
        blocks = _blocks(builder, table, info)
        svgs = {name: future.result() for name, future in builder.svgs.items()}
    return blocks, svgs


def _blocks(builder: _Builder, table: pd.DataFrame, info: RunInfo) -> list[Block]:
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
    blocks += builder.own_engines()
    blocks += builder.summary()
    blocks += _hard_cases(table, info, builder.groups)
    blocks += [Details("Definitions", (Paragraph(_DEFINITIONS), Paragraph(_IK_PROTOCOL)), markdown=False)]
    blocks += sweep_sections.sections(builder.sweeps, builder.figure, info.theoretical_orders, info.integrator_variants)
    kinds = {scene: _kind(rows) for scene, rows in table.groupby("scene", sort=False)}
    for scene, rows in table.groupby("scene", sort=False):
        own_section = kinds[scene] not in _TABULATED_KINDS and builder.listed(scene)
        blocks += builder.scene(scene, rows) if own_section else []
    for kind, section in (("joint_dynamics", builder.joint_dynamics), ("kinematics", builder.kinematics)):
        chosen = table[(table["scene"].map(kinds) == kind) & ~table["scene"].isin(builder.sweep_of)]
        blocks += section(chosen) if not chosen.empty else []
    return blocks


def _case_counts(table: pd.DataFrame) -> dict[str, int]:
    """:func:`case_counts` of the table's rows, each case's statuses gathered by pandas: a row at a time, a sweep of
    1,000 IK variants (429,000 rows) took 24 s."""
    cases = table.groupby(["scene", "engine", "integrator", "dt"], sort=False, dropna=False)["status"].unique()
    return case_counts({"scene": key, "engine": "", "integrator": "", "dt": 0.0, "status": status}
                       for key, statuses in cases.items() for status in statuses)


_TABULATED_KINDS = ("kinematics", "joint_dynamics")
"""Kinds of scene the report puts in one section of their own (a table with a row per scene), not one each."""
