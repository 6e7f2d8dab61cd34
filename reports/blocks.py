"""The report as typed blocks, built once and rendered twice: to Markdown (``report.md``) and to HTML
(``report.html``). A block says what it is; the renderers decide how it looks."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Heading:
    level: int
    text: str

    @property
    def anchor(self) -> str:
        """The id GitHub gives this heading in rendered Markdown (lower case, punctuation dropped, spaces
        to hyphens), so a ``[...](#anchor)`` link works in report.md on GitHub and in report.html alike."""
        return re.sub(r"[^\w\- ]", "", self.text.lower()).replace(" ", "-")


@dataclass(frozen=True)
class Paragraph:
    """Text with Markdown's inline marks only: `code`, **bold**, [links](url)."""

    text: str


@dataclass(frozen=True)
class Bullets:
    items: tuple[str, ...]


SCENE_TABLE_TRIM_ORDER = 5
"""Where a scene section's tables of its engines stand among the tables report.md may shorten: last of all, down to no
row ("… N more rows: report.html"), since the section's verdict line above them names each engine's best and its
findings; a default suite past ~30 scenes (issue #42 added six) outgrew 400 lines with every section whole, and the
contact suite past 25 scenes did with its robots' momentum and contact tables whole (403 lines)."""


@dataclass(frozen=True)
class Table:
    """``trim_order``: for a table that report.md may shorten to keep within its line budget
    (:data:`reports.markdown.MAX_LINES`), saying how many rows the HTML has beyond it: the lowest is shortened first
    (1 the cases without a result, 2 the flagged findings, 3 a user's engine's table, 4 the summary's row per scene,
    :data:`SCENE_TABLE_TRIM_ORDER` a scene section's row per engine); 0 (the default) never."""

    head: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    trim_order: int = 0
    keep_at_least: int | None = None
    """Rows a trimmed table keeps at least (None: :data:`reports.markdown.MIN_TRIMMED_ROWS`)."""


@dataclass(frozen=True)
class Figure:
    """A figure written by :func:`reports.figure_writer.save` as ``figures/<name>.svg`` (and .png). ``caption`` is under
    it in the HTML; report.md links it with its short ``alt`` (the figure's name when empty): docs/report.md says how
    to read each figure."""

    name: str
    caption: str
    alt: str = ""


@dataclass(frozen=True)
class Details:
    """Folded content: collapsed in HTML (unfolded when ``open``); in Markdown a ``<details>`` block, or left out
    when ``markdown`` is False (it is in ``results.csv`` and the HTML)."""

    summary: str
    blocks: tuple = field(default_factory=tuple)
    markdown: bool = True
    open: bool = False


Block = Heading | Paragraph | Bullets | Table | Figure | Details


def number(value: float) -> str:
    """A number in a cell or a sentence: three significant digits; an em dash for no value."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    return "0" if value == 0 else f"{value:.3g}"


def scene_heading(scene: str, kind: str) -> Heading:
    """A scene section's heading; the summary and the sweep sections link to its anchor."""
    return Heading(2, f"{scene} ({kind})")
