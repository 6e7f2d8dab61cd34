"""What every section of the report reads (:class:`ReportContext`): the stored run (its rows, run info and series),
the gate's verdict, the sweeps and their variants, each dynamics scene's cases and the cost the summary ranks by,
the figures submitted so far; and what a scene's rows say it is (:func:`scene_kind`, its headline metric).
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pandas as pd

from simparity.core.model.metric_catalogue import (
    JOINT_ANGLE_ERROR_MAX, MASS_MATRIX_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX, REST_WEIGHT_ERROR,
    SOLVE_RATE,
)
from simparity.core.model.run_info import RunInfo
from simparity.reports import engine_summary, figure_writer, figures, summary, sweep_sections, sweep_summary
from simparity.reports.blocks import Block, Figure
from simparity.reports.sweep_summary import Sweep, merge_variants
from simparity.reports.tolerance_verdict import ToleranceVerdict

HEADLINE_NAMES = {POSITION_ERROR_MAX: ("position error max", "m"),
                  ORIENTATION_ERROR_MAX: ("orientation error max", "rad"),
                  JOINT_ANGLE_ERROR_MAX: ("joint angle error max", "rad")}
"""(name, unit) of each headline metric a dynamics scene can be ranked by."""

TABULATED_KINDS = ("kinematics", "joint_dynamics")
"""Kinds of scene the report puts in one section of their own (a table with a row per scene), not one each."""


def scene_kind(rows: pd.DataFrame) -> str:
    """The kind of scene ``rows`` (one scene's, or one sweep's) are of: ``ik``, ``joint_dynamics``, ``dynamics`` or
    ``kinematics``."""
    if (rows["metric"] == SOLVE_RATE).any():
        return "ik"
    if (rows["metric"] == MASS_MATRIX_ERROR_MAX).any():
        return "joint_dynamics"
    return "dynamics" if rows["dt"].notna().any() else "kinematics"


def headline(about: dict) -> str:
    """The metric a dynamics scene is ranked by (``about``: its entry in run.json's scenes)."""
    return about.get("headline_metric", POSITION_ERROR_MAX)


def heading_kind(about: dict, kind: str) -> str:
    """The kind a scene's heading (and so its anchor) names."""
    return summary.heading_kind(kind, about.get("headline_metric", ""))


class ReportContext:
    """One report in the making: the run the sections read and what they share. The summary's flagged findings
    count each scene's findings (``findings_per_scene``) before the scenes' sections say them."""

    def __init__(self, table: pd.DataFrame, info: RunInfo, series: pd.DataFrame, verdict: ToleranceVerdict | None,
                 figure_dir: Path, writer: figure_writer.FigureWriter, sweeps: list[Sweep]) -> None:
        self.table, self.info, self.series, self.verdict = table, info, series, verdict
        self.figure_dir, self.writer = figure_dir, writer
        self.svgs: dict[str, figure_writer.WrittenFigure] = {}
        self.sweeps = sweeps
        self.sweep_of = {name: sweep for sweep in sweeps for name in sweep.variants}
        self.groups = sweep_summary.groups(sweeps)
        self.counts = sweep_summary.counts(sweeps)
        self.cases = {scene: summary.dynamics_cases(rows, headline(self.about(scene)))
                      for scene, rows in table.groupby("scene", sort=False)
                      if scene_kind(rows) == "dynamics" and scene not in self.sweep_of}
        self.joint_dynamics_scenes = [scene for scene, rows in table.groupby("scene", sort=False)
                                      if scene_kind(rows) == "joint_dynamics"]
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

    def merged(self, frame: pd.DataFrame, keys: list[str], **aggregations) -> pd.DataFrame:
        """``frame`` with each sweep's variants merged (:func:`reports.sweep_summary.merge_variants`); as it is in a
        run without a sweep."""
        return merge_variants(frame, self.groups, keys, **aggregations) if self.groups else frame

    def in_variants(self, row: pd.Series, lead: str = " ") -> str:
        """"in K of N variants" after ``lead`` for a row standing for a sweep's variants; nothing for a scene of its
        own."""
        count = self.counts.get(row["scene"])
        return f"{lead}in {row['variants']} of {count} variants" if count else ""

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
                + ("Reference: none (a scene with contact: each engine against truths that need no engine)."
                   if rows["metric"].eq(REST_WEIGHT_ERROR).any() else f"Reference: `{rows['reference'].iloc[0]}`.")
                + (f" Scene file: `{Path(about['source']).name}`." if about.get("source") else ""))
