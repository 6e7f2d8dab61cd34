"""The robot files in one table (issue #45): each joint-dynamics scene whose engines report what they compiled from a
robot file (the model-parity rows), one row per robot and a cell per engine: whether the engine loads the file, whether
its compiled model agrees with the reference's (mass, centre of mass, inertia, axes, origins, joint types and limits)
and whether its dynamics do (M, h, tau, qddot, the identities, the derivatives), the first disagreement named; the
reasons an engine gives no number are numbered notes under the table, each said once."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.metric_catalogue import (
    MODEL_AXIS_ERROR_MAX, MODEL_COM_ERROR_MAX, MODEL_INERTIA_ERROR_MAX, MODEL_JOINT_TYPE_MISMATCHES,
    MODEL_LIMIT_MISMATCHES, MODEL_MASS_ERROR_MAX, MODEL_ORIGIN_ERROR_MAX,
)
from simparity.core.model.results import FAILED, NOT_AVAILABLE, OK
from simparity.reports.blocks import Block, Bullets, Heading, Paragraph, Table, number
from simparity.reports.markdown import LINE_CHARS
from simparity.reports.sections.context import ReportContext
from simparity.reports.sections.joint_dynamics import DYNAMICS_ERRORS, DYNAMICS_IDENTITIES
from simparity.reports.sections.shared import clip

MODEL_ERRORS = (MODEL_MASS_ERROR_MAX, MODEL_COM_ERROR_MAX, MODEL_INERTIA_ERROR_MAX, MODEL_AXIS_ERROR_MAX,
                MODEL_ORIGIN_ERROR_MAX)
"""The compiled fields' errors against the reference's (relative, or radians for the axes)."""
MODEL_COUNTS = (MODEL_JOINT_TYPE_MISMATCHES, MODEL_LIMIT_MISMATCHES)
"""The compiled joints that differ from the reference's, counted."""
MODEL_METRICS = MODEL_ERRORS + MODEL_COUNTS
DYNAMICS = DYNAMICS_ERRORS + DYNAMICS_IDENTITIES
"""What a 'dyn' cell gives the largest of: M, h, tau and qddot against the reference, and the identities of the
engine's own outputs (derivatives are judged by their own rows: a differenced partial's truncation is no importer's)."""
NOTE_CHARS = LINE_CHARS - 20
"""A note's reason is cut to fit its line with the engine and its number."""


def robot_scenes(table: pd.DataFrame, joint_dynamics_scenes: list[str]) -> list[str]:
    """The joint-dynamics scenes of a robot file: those where some engine reported its compiled model (a chain written in
    the scene file has model rows too, n/a in every engine)."""
    with_model = set(table.loc[table["metric"].isin(MODEL_ERRORS) & (table["status"] == OK), "scene"])
    return [scene for scene in joint_dynamics_scenes if scene in with_model]


class _Notes:
    """The numbered reasons of the table's n/a and failed cells, each text once."""

    def __init__(self) -> None:
        self.texts: dict[str, int] = {}

    def number_of(self, text: str) -> int:
        return self.texts.setdefault(text, len(self.texts) + 1)

    def blocks(self) -> list[Block]:
        if not self.texts:
            return []
        return [Bullets(tuple(f"[{k}] {clip(text, NOTE_CHARS)}" for text, k in self.texts.items()))]


def _first_disagreement(violations: list[str], metrics: tuple[str, ...]) -> str:
    """The first of ``violations`` (metric names, the gate's order) among ``metrics``; "" when none is."""
    return next((metric for metric in violations if metric in metrics), "")


def _cell(case: pd.DataFrame, violations: list[str], notes: _Notes) -> str:
    """One engine on one robot: "—" where it did not run; the reason (a note) where it gave no number; else the
    worst compiled-field error and the worst dynamics error, each with its first violation where the gate held one."""
    if case.empty:
        return "—"
    engine = str(case["engine"].iloc[0])
    statuses = case["status"]
    unmeasured = FAILED if (statuses == FAILED).any() else NOT_AVAILABLE if (statuses == NOT_AVAILABLE).all() else None
    if unmeasured is not None:
        detail = str(case.loc[statuses == unmeasured, "detail"].iloc[0])
        return f"{unmeasured} [{notes.number_of(f'{engine}: {detail}')}]"
    ok = case[case["status"] == OK]
    model = ok[ok["metric"].isin(MODEL_ERRORS)]["value"]
    counts = ok[ok["metric"].isin(MODEL_COUNTS)]["value"]
    dynamics = ok[ok["metric"].isin(DYNAMICS)]["value"]
    parts = []
    for label, values, metrics in (("model", model, MODEL_METRICS), ("dyn", dynamics, DYNAMICS)):
        text = f"{label} {number(float(values.max()))}" if not values.empty else f"{label} n/a"
        if label == "model" and not counts.empty and float(counts.max()) > 0:
            text += f" ({int(counts.sum())} joint(s) read otherwise)"
        first = _first_disagreement(violations, metrics)
        parts.append(text + (f" ✗ {first}" if first else ""))
    return " · ".join(parts)


def section(ctx: ReportContext, scenes: list[str]) -> list[Block]:
    """The table of robot files x engines (the module docstring), the reference's column saying it is."""
    rows = ctx.table[ctx.table["scene"].isin(scenes)]
    # every engine with model rows: one that declines every file here (core on non-physical tensors) keeps its column
    engines = [e for e in dict.fromkeys(rows["engine"]) if e in set(rows.loc[rows["metric"].isin(MODEL_ERRORS), "engine"])]
    verdict = ctx.verdict
    against: dict[tuple[str, str], list[str]] = {}
    if verdict is not None:
        for engine, (scene, metric) in zip(verdict.engines, verdict.cases):
            against.setdefault((scene, engine), []).append(metric)
    notes = _Notes()
    body = []
    for scene in scenes:
        scene_rows = rows[rows["scene"] == scene]
        reference = str(scene_rows["reference"].iloc[0])
        cells = []
        for engine in engines:
            case = scene_rows[scene_rows["engine"] == engine]
            cell = "reference" if engine == reference and (case["status"] != OK).all() else \
                _cell(case, against.get((scene, engine), []), notes)
            cells.append(cell)
        body.append((scene, *cells))
    held = "held to the shipped tolerances" if verdict is not None else "not checked (run with --check)"
    return [Heading(2, "Robot files × engines"),
            Paragraph(f"{len(scenes)} robot files, each read by every engine's own importer ({held}). A cell: 'model' "
                      "the largest error of what the engine compiled (mass, centre of mass, inertia, axis, origin, "
                      "against the reference's), 'dyn' of its dynamics (M, h, tau, qddot, identities), each relative; "
                      "✗ names the first metric outside its bound; n/a and failed cells give their reason as a note. "
                      "docs/robots.md lists each importer difference with the file that shows it."),
            Table(("robot", *engines), tuple(body)), *notes.blocks()]
