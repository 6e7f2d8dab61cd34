"""Pieces several sections say alike: a list of names cut to a few, a text cut to a length, and what each engine was
given on a scene."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.metric_catalogue import TIME_PER_FK, TIME_PER_SOLVE, TIME_PER_STEP
from simparity.core.model.results import OK
from simparity.reports.blocks import Block, Bullets, Details

NAMES_SHOWN = 4
"""Schemes or scenes a findings cell names before it counts the rest: a row stays one line."""

_TIMING_METRICS = (TIME_PER_STEP, TIME_PER_FK, TIME_PER_SOLVE)


def names(shown_names: list[str], shown: int = NAMES_SHOWN) -> str:
    """``a, b, c, d (+3 more)``: at most ``shown`` names, then the count of the rest."""
    return ", ".join(shown_names[:shown]) + (f" (+{len(shown_names) - shown} more)" if len(shown_names) > shown else "")


def clip(text: str, limit: int) -> str:
    """``text`` cut to ``limit`` characters with an ellipsis."""
    return text if len(text) <= limit else text[:limit - 1].rstrip() + "…"


def engine_notes(scene_rows: pd.DataFrame) -> list[Block]:
    """What each engine was given on a scene (its timing rows' detail), folded; nothing where no time was
    measured."""
    timed = scene_rows["metric"].isin(_TIMING_METRICS)
    ok = scene_rows[timed & (scene_rows["status"] == OK)].drop_duplicates(["engine", "integrator"])
    items = tuple(f"**{' '.join(filter(None, (r['engine'], r['integrator'])))}**: {r['detail']}" for _, r in ok.iterrows())
    return [Details("What each engine was given", (Bullets(items),), markdown=False)] if items else []
