"""``report.md``: the report's blocks as Markdown, figures linked from ``figures/``. No line is longer than
:data:`LINE_CHARS`: text wraps between words (a paragraph's soft line breaks render as spaces), and a table row
that would be longer has its longest cells shortened (report.html and results.csv keep every cell whole)."""

from __future__ import annotations

import itertools
import math
import re
from typing import cast

from simparity.reports.blocks import Block, Bullets, Details, Figure, Heading, Paragraph, Table

LINE_CHARS = 300
"""Characters a line of report.md stays under (issue #26): a reader scanning the file in an editor or a diff, and
a table row a reviewer can read on one screen; what is longer is said compactly, wrapped or shortened."""

MAX_LINES = 400
"""Lines report.md stays within where it can (issue #26): a pull request's reviewer reads it on a few screens. Over it,
the tables that may be trimmed (:attr:`reports.blocks.Table.trim_order`: cases without a result, then the flagged
findings, a user's engine's table, the summary's row per scene) give up their last rows, in that order, down to
:data:`MIN_TRIMMED_ROWS` each (the summary's row per scene down to none), with a row saying how many more report.html
has; every other block stays whole."""

MIN_TRIMMED_ROWS = 5
"""Rows a trimmed table keeps at least: its first rows are its most important (each table is sorted so)."""

WRAP_CHARS = LINE_CHARS
"""Where text wraps: a line takes words while it stays within :data:`LINE_CHARS` (longer only for a single word
longer than that); a narrower wrap would spend lines of the report's 400-line budget on paragraphs."""

_OPENS_BLOCK = re.compile(r"^(?:[-+*#>|<]|\d+[.)]|=+|-+|`{3,}|~{3,})(?:\s|$)")
"""A word that would open a list item, heading, quote, table, HTML block or fence, or underline a heading, at the
start of a line: never wrapped onto one."""


def _tokens(text: str) -> list[str]:
    """``text``'s words, each word that would open a block (:data:`_OPENS_BLOCK`) glued to the word before it, so
    that no line can start with it."""
    tokens: list[str] = []
    for word in text.split(" "):
        if tokens and _OPENS_BLOCK.match(word):
            tokens[-1] += " " + word
        else:
            tokens.append(word)
    return tokens


def _wrap(text: str, indent: str = "") -> list[str]:
    """``text`` in lines of at most :data:`WRAP_CHARS` where words allow, broken only between words, never before
    one that Markdown would read as opening a block; continuation lines start with ``indent``."""
    lines: list[str] = []
    line = ""
    for token in _tokens(text):
        if line and len(line) + 1 + len(token) > WRAP_CHARS:
            lines.append(line)
            line = indent + token
        else:
            line = f"{line} {token}" if line else token
    return lines + [line]


def _cell(text: str) -> str:
    return text.replace("|", "/").replace("\n", " ")


def _row(cells: list[str]) -> str:
    """A table row within :data:`LINE_CHARS`: while it is longer, its longest cell is cut with an ellipsis (a cell
    holding a link only when no other is left to cut: a cut link leads nowhere)."""
    cells = [_cell(c) for c in cells]
    while len(line := "| " + " | ".join(cells) + " |") > LINE_CHARS:
        plain = [k for k, cell in enumerate(cells) if "](" not in cell and len(cell) > 2]
        longest = max(plain or range(len(cells)), key=lambda k: len(cells[k]))
        excess = len(line) - LINE_CHARS
        if len(cells[longest]) <= 2:
            break
        cells[longest] = cells[longest][:max(1, len(cells[longest]) - excess - 1)].rstrip() + "…"
    return line


def _lines(block: Block, figure_dir: str) -> list[str]:
    if isinstance(block, Heading):  # a heading ends at its line: no blank line needed after it
        return [f"{'#' * block.level} {block.text}"]
    if isinstance(block, Paragraph):
        return _wrap(block.text) + [""]
    if isinstance(block, Bullets):
        return [line for item in block.items for line in _wrap(f"- {item}", "  ")] + [""] if block.items else []
    if isinstance(block, Table):
        return ([_row(list(block.head)), "|" + "---|" * len(block.head)]
                + [_row(list(row)) for row in block.rows] + [""])
    if isinstance(block, Details):
        if not block.markdown:
            return []
        inner = [line for b in block.blocks for line in _lines(b, figure_dir)]
        return [f"<details><summary>{block.summary}</summary>", ""] + inner + ["</details>", ""]
    raise TypeError(f"unknown block {block!r:.80}")


def _figures(run: list[Figure], figure_dir: str) -> list[str]:
    """Consecutive figures on one line (side by side where there is room), each linked with its short alt."""
    links = [f"![{f.alt or f.name}]({figure_dir}/{f.name}.svg)" for f in run]
    return _wrap(" ".join(links)) + [""]


def _render(blocks: list[Block], figure_dir: str) -> list[str]:
    lines: list[str] = []
    for is_figure, run in itertools.groupby(blocks, key=lambda b: isinstance(b, Figure)):
        if is_figure:
            lines += _figures([f for f in run if isinstance(f, Figure)], figure_dir)
        else:
            lines += [line for block in run for line in _lines(block, figure_dir)]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def _trimmed(table: Table, keep: int) -> Table | Paragraph:
    """``table`` with its first ``keep`` rows and a last one saying how many more report.html has; none kept: one line
    saying where its rows are."""
    more = len(table.rows) - keep
    if keep == 0:
        return Paragraph(f"Its table ({table.head[0]}: {more} rows): report.html.")
    note = (f"… {more} more rows: report.html",) + ("",) * (len(table.head) - 1)
    return Table(table.head, table.rows[:keep] + (note,))


def _within_budget(blocks: list[Block], excess: int) -> list[Block]:
    """``blocks`` with the tables that may be trimmed shortened by ``excess`` lines in all where they can be: a row at
    a time, the first in :attr:`Table.trim_order` first, each kept to at least its :attr:`Table.keep_at_least` rows
    (:data:`MIN_TRIMMED_ROWS` unless it says) (a trimmed table gains a row saying so)."""
    full = {i: len(b.rows) for i, b in enumerate(blocks) if isinstance(b, Table) and b.trim_order}
    keep = dict(full)
    least = {i: MIN_TRIMMED_ROWS if b.keep_at_least is None else b.keep_at_least
             for i, b in enumerate(blocks) if i in full and isinstance(b, Table)}

    def saved() -> int:  # a table of r rows takes r + 3 lines; trimmed to k rows k + 4, to none 2 (a line and a blank)
        return sum(full[i] + 1 if keep[i] == 0 else full[i] - keep[i] - (keep[i] < full[i]) for i in keep)
    while saved() < excess:
        cuttable = [i for i in keep if keep[i] > least[i]]
        if not cuttable:
            break
        keep[min(cuttable, key=lambda i: (cast(Table, blocks[i]).trim_order, i))] -= 1
    return [_trimmed(b, keep[i]) if keep.get(i, math.inf) < full.get(i, 0) else b  # type: ignore[arg-type]
            for i, b in enumerate(blocks)]


def to_markdown(blocks: list[Block], figure_dir: str = "figures") -> str:
    """Markdown text of the blocks; folded blocks marked markdown=False are left out (they are in the HTML). Over
    :data:`MAX_LINES`, the tables that may be are shortened (:func:`_within_budget`)."""
    lines = _render(blocks, figure_dir)
    if len(lines) > MAX_LINES:
        lines = _render(_within_budget(list(blocks), len(lines) - MAX_LINES), figure_dir)
    return "\n".join(lines) + "\n"
