"""report.md's rendering: no line over LINE_CHARS whatever the blocks say (text wraps between words, a long table
row has its longest cells shortened), wrapped text never turns into a list, heading or table, and what HTML-only
blocks hold stays out."""

import random

import pytest

from simparity.reports.blocks import Bullets, Details, Figure, Paragraph, Table
from simparity.reports.markdown import LINE_CHARS, to_markdown

SEEDS = range(20)
"""Random paragraphs, bullets and tables per test: enough to hit words at every position of a line."""

_WORDS = ("energy", "rose", "by", "1.05", "x", "-", "1.", "#", "|", ">", "`core:rk4`", "[scene](#scene-dynamics)",
          "+", "*", "2)", "orientation_error_max", "a" * 40)


def _text(rng: random.Random, words: int) -> str:
    return " ".join(rng.choice(_WORDS) for _ in range(words))


@pytest.mark.parametrize("seed", SEEDS)
def test_no_line_is_longer_than_the_limit_and_wrapping_opens_no_block(seed):
    rng = random.Random(seed)
    paragraph = "Text " + _text(rng, rng.randint(1, 400))
    bullets = tuple(_text(rng, rng.randint(1, 120)) for _ in range(3))
    table = Table(("a", "b", "c"), tuple(tuple(_text(rng, rng.randint(1, 80)) for _ in range(3)) for _ in range(4)))
    text = to_markdown([Paragraph(paragraph), Bullets(bullets), table])
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= LINE_CHARS
    paragraph_lines = lines[:lines.index("")]
    assert " ".join(paragraph_lines) == paragraph            # soft breaks only: the text is unchanged
    assert not any(line.startswith(("- ", "# ", "> ", "| ", "+ ", "* ")) for line in paragraph_lines[1:])
    bullet_lines = [line for line in lines[len(paragraph_lines) + 1:] if line and not line.startswith("|")]
    assert sum(line.startswith("- ") for line in bullet_lines) == 3     # one item each, continuation indented
    assert all(line.startswith(("- ", "  ")) for line in bullet_lines)
    rows = [line for line in lines if line.startswith("|")]
    assert len(rows) == 6 and all(row.count(" | ") == 2 for row in rows if not row.startswith("|---"))


def test_a_long_row_shortens_its_longest_cell_and_keeps_the_short_ones():
    row = ("core", "rk4", "x" * 500, "0.01")
    line = to_markdown([Table(("engine", "integrator", "reason", "dt"), (row,))]).splitlines()[2]
    assert len(line) == LINE_CHARS and line.startswith("| core | rk4 | xxx") and line.endswith("… | 0.01 |")


def test_a_long_row_keeps_its_links_whole():
    link = "[point-force-torque](#point-force-torque-dynamics)"
    row = (link, "y" * 120, "z" * 200)
    line = to_markdown([Table(("scene", "a", "b"), (row,))]).splitlines()[2]
    assert len(line) == LINE_CHARS and line.startswith(f"| {link} | ")


def test_figures_share_a_line_with_short_alt_texts_and_html_only_blocks_stay_out():
    blocks = [Figure("s-work-precision", "A long caption " * 30), Figure("s-drift", "Drift."),
              Details("every value", (Paragraph("only in the HTML"),), markdown=False, open=True)]
    text = to_markdown(blocks)
    assert text == "![s-work-precision](figures/s-work-precision.svg) ![s-drift](figures/s-drift.svg)\n"


def test_a_table_trimmed_last_may_give_up_every_row_and_the_report_keeps_its_budget():
    """A suite whose every shortenable table is at its minimum still outgrew report.md's budget (28 scenes: 414 lines);
    a table that may give up every row (``keep_at_least=0``) is shortened last, down to one line saying how many rows
    report.html has (no header left), and never below another table's minimum."""
    from simparity.reports.blocks import Paragraph, Table
    from simparity.reports.markdown import MAX_LINES, MIN_TRIMMED_ROWS, to_markdown
    findings = Table(("finding",), tuple((f"f{i}",) for i in range(40)), trim_order=1)
    per_scene = Table(("scene",), tuple((f"s{i}",) for i in range(40)), trim_order=4, keep_at_least=0)
    filler = [Paragraph(f"line {i}") for i in range((MAX_LINES - 12) // 2)]  # 2 lines each, the last 1: 387 of 400
    lines = to_markdown([findings, per_scene, *filler]).splitlines()
    assert len(lines) <= MAX_LINES
    assert "| f4 |" in lines and "| f5 |" not in lines  # the first table at its minimum
    assert "| s0 |" not in lines and "| scene |" not in lines  # the last one gave up every row, its header too
    assert "Its table (scene: 40 rows): report.html." in lines
