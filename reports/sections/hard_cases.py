"""The hard cases section: the verdict every engine earned on each scene of the ``hard`` suite in the run, one line
each (IK: the hard solves that succeeded; dynamics: the cases per status and which diverged), then each one's grid of
verdicts, folded."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.results import STATUSES, case_status
from simparity.core.model.run_info import RunInfo
from simparity.reports.blocks import Block, Bullets, Details, Heading, Paragraph, Table
from simparity.reports.sections import ik
from simparity.reports.sections.context import scene_kind
from simparity.reports.sections.shared import names


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
    return text + (f"; diverged: {names(diverged)}" if diverged else "")


def section(table: pd.DataFrame, info: RunInfo, groups: dict[str, str]) -> list[Block]:
    """The verdict every engine earned on each scene of the hard suite in the run; a sweep's variants (``groups``:
    {variant: its sweep's label}) share one line, with no grid of their own (the sweep's section has one)."""
    hard = [name for name, about in info.scenes.items() if "hard" in about.get("suites", ())]
    hard = [name for name in hard if (table["scene"] == name).any()]
    if not hard:
        return []
    table = table.assign(_group=table["scene"].map(lambda scene: groups.get(scene, scene)))
    scenes = list(dict.fromkeys(groups.get(name, name) for name in hard))
    swept = set(groups.values())
    blocks: list[Block] = [
        Heading(2, "Hard cases"),
        Paragraph("The `hard` suite's numerical-stability cases: `diverged` when a conserved quantity or a speed left "
                  "its bound, `ok` when it stayed bounded; the verdict each must earn is in the shipped tolerances.")]
    lines = []
    for name in scenes:
        rows = table[table["_group"] == name]
        if scene_kind(rows) == "ik":
            solved, total = ik.hard_solved(rows)
            lines.append(f"**{name}**: {solved} of {total} hard IK solves succeeded")
        else:
            lines.append(_verdict_line(name, rows))
    blocks.append(Bullets(tuple(lines)))
    for name in (name for name in scenes if name not in swept):
        rows = table[table["scene"] == name]
        grid = ik.hard_table(rows) if scene_kind(rows) == "ik" else [_dynamics_verdicts(rows)]
        blocks.append(Details(f"{name}: every verdict", tuple(grid), markdown=False))
    return blocks
