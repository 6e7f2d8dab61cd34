"""``report.html``: the report's blocks as one self-contained page: figures inline as SVG, styles
inline, no script and no request to any host, so it opens from disk offline."""

from __future__ import annotations

import html
import re

from simparity.reports.blocks import Block, Bullets, Details, Figure, Heading, Paragraph, Table

_STYLE = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 1200px; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: .5em 0 1em; font-size: 12px; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
figure { margin: 1em 0; }
figure svg { display: block; width: 100%; height: auto; }
figcaption { font-size: 12px; color: #555; }
details { margin: .5em 0; }
summary { cursor: pointer; color: #035; }
code { background: #f5f5f5; padding: 0 2px; }
"""

_INLINE = [
    (re.compile(r"`([^`]+)`"), r"<code>\1</code>"),
    (re.compile(r"\*\*([^*]+)\*\*"), r"<strong>\1</strong>"),
    (re.compile(r"\[([^\]]+)\]\((#[A-Za-z0-9_-]+)\)"), r'<a href="\2">\1</a>'),
]


def _inline(text: str) -> str:
    """Escaped text with the Markdown inline marks the blocks use (code, bold, links within the page)."""
    out = html.escape(text, quote=False)
    for pattern, replacement in _INLINE:
        out = pattern.sub(replacement, out)
    return out


_SVG_SIZE = re.compile(r'\s(?:width|height)="[^"]*"')


def _svg_body(svg: str) -> str:
    """An SVG file's text without its XML prolog and DOCTYPE, to put inline, and without the root's ``width`` and
    ``height`` (matplotlib's, in pt: 10 in is 720 pt, 960 CSS px), so that the figure takes the column's width
    (``figure svg`` in the style) and its ``viewBox`` the height; ``max-width`` alone would keep it at 960 px."""
    body = svg[svg.index("<svg"):]
    end = body.index(">")
    return _SVG_SIZE.sub("", body[:end]) + body[end:]


def _html(block: Block, svgs: dict[str, str]) -> str:
    if isinstance(block, Heading):
        return f'<h{block.level} id="{html.escape(block.anchor)}">{_inline(block.text)}</h{block.level}>'
    if isinstance(block, Paragraph):
        return f"<p>{_inline(block.text)}</p>"
    if isinstance(block, Bullets):
        return "<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in block.items) + "</ul>"
    if isinstance(block, Table):
        head = "".join(f"<th>{_inline(h)}</th>" for h in block.head)
        rows = "".join("<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in row) + "</tr>" for row in block.rows)
        return f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>"
    if isinstance(block, Figure):
        return (f'<figure class="plot" data-name="{html.escape(block.name)}">{_svg_body(svgs[block.name])}'
                f"<figcaption>{_inline(block.caption)}</figcaption></figure>")
    if isinstance(block, Details):
        inner = "".join(_html(b, svgs) for b in block.blocks)
        return f"<details{' open' if block.open else ''}><summary>{_inline(block.summary)}</summary>{inner}</details>"
    raise TypeError(f"unknown block {block!r:.80}")


def to_html(blocks: list[Block], svgs: dict[str, str], title: str = "simparity report") -> str:
    """One HTML page of the blocks, every figure inline (``svgs``: SVG text by figure name)."""
    body = "\n".join(_html(b, svgs) for b in blocks)
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{_STYLE}</style></head><body>\n{body}\n</body></html>\n")
