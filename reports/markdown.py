"""``report.md``: the report's blocks as Markdown, figures linked from ``figures/``."""

from __future__ import annotations

import itertools

from simparity.reports.blocks import Block, Bullets, Details, Figure, Heading, Paragraph, Table


def _cell(text: str) -> str:
    return text.replace("|", "/").replace("\n", " ")


def _lines(block: Block, figure_dir: str) -> list[str]:
    if isinstance(block, Heading):  # a heading ends at its line: no blank line needed after it
        return [f"{'#' * block.level} {block.text}"]
    if isinstance(block, Paragraph):
        return [block.text, ""]
    if isinstance(block, Bullets):
        return [f"- {item}" for item in block.items] + [""] if block.items else []
    if isinstance(block, Table):
        return (["| " + " | ".join(_cell(h) for h in block.head) + " |", "|" + "---|" * len(block.head)]
                + ["| " + " | ".join(_cell(c) for c in row) + " |" for row in block.rows] + [""])
    if isinstance(block, Details):
        if not block.markdown:
            return []
        inner = [line for b in block.blocks for line in _lines(b, figure_dir)]
        return [f"<details><summary>{block.summary}</summary>", ""] + inner + ["</details>", ""]
    raise TypeError(f"unknown block {block!r:.80}")


def to_markdown(blocks: list[Block], figure_dir: str = "figures") -> str:
    """Markdown text of the blocks; folded blocks marked markdown=False are left out (they are in the HTML)."""
    lines: list[str] = []
    for is_figure, run in itertools.groupby(blocks, key=lambda b: isinstance(b, Figure)):
        if is_figure:  # consecutive figures on one line: side by side where there is room
            lines += [" ".join(f"![{f.caption}]({figure_dir}/{f.name}.svg)" for f in run if isinstance(f, Figure)), ""]
        else:
            lines += [line for block in run for line in _lines(block, figure_dir)]
    while lines and not lines[-1]:
        lines.pop()
    return "\n".join(lines) + "\n"
