"""The kinematics section: every kinematics scene in one table (a row per scene), not a section each."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.metric_catalogue import POSITION_ERROR_MAX
from simparity.core.model.results import OK
from simparity.reports import tables
from simparity.reports.blocks import Block, Bullets, Details, Heading, Paragraph, Table, number
from simparity.reports.sections.context import ReportContext
from simparity.reports.sections.shared import engine_notes


def section(ctx: ReportContext, rows: pd.DataFrame) -> list[Block]:
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
                           Bullets(tuple(f"**{scene}**: {ctx.introduction(scene, rows[rows['scene'] == scene])}"
                                         for scene in scenes)),
                           Paragraph("Frame position error max [m] against each scene's reference; orientation and "
                                     "Jacobian errors, times and the reasons for n/a: the HTML report."),
                           Table(("scene", *engines), tuple(compact)),
                           Details("Every kinematics metric", (full,), markdown=False, open=True)]
    return blocks + engine_notes(rows)
