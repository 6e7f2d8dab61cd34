"""Laying out the report's figures cheaply: margins fixed in inches instead of ``tight_layout``, the right one
sized to the legend alone, and log-axis tick labels as Unicode text (10⁻⁶, 2×10⁻³) instead of mathtext.

Why: ``tight_layout`` measures every text of a figure with a renderer of its own (the saved SVG and PNG measure
them again) and leaves a placeholder layout engine behind, which makes every save draw the figure twice; matplotlib's
log-axis labels are TeX strings, ~4 ms each to parse against 0.2 ms to lay out as plain text. In a 100-variant
sweep's report (300 figures, 113 s) cProfile put 77 s in ``tight_layout`` and ~40 s in parsing mathtext. The
labels here say the same (matplotlib's formatter still decides which ticks get one), the margins are constant, and
a legend is measured once.
"""

from __future__ import annotations

import re
import textwrap

from matplotlib.font_manager import FontProperties
from matplotlib.ticker import LogFormatterSciNotation

MARGINS = {"left": 0.85, "right": 0.15, "bottom": 0.5, "top": 0.35}
"""[in] Room around the axes: left for y tick labels up to ~8 characters and the y label, bottom for the x tick
labels and x label, top for a one-line title, right for nothing but the frame (a legend adds its own width)."""

LEGEND_GAP = 0.15
"""[in] Between the axes' right edge and a legend placed at 1.01 axes widths, plus the legend's own padding."""

LEGEND_FONT_SIZE = 7
"""[pt] Legend text: up to ~25 schemes must fit beside a 4.8 in high axes."""

TITLE_FONT_SIZE = 10
"""[pt] Titles, a size above the tick labels'."""

TITLE_LINE = 0.2
"""[in] What each line of a wrapped title adds to the top margin: 10 pt text at matplotlib's 1.2 line spacing."""

_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_POWER = re.compile(r"\^\{(-?[0-9]+)\}")
_MATHTEXT = re.compile(r"^\$\\mathdefault\{(.*)\}\$$")


class UnicodeLogFormatter(LogFormatterSciNotation):
    """matplotlib's log-axis tick labels (the same ticks labelled, ``10^{k}`` and ``2\\times10^{k}``) as plain
    text with Unicode superscripts, so a label is laid out from the font without parsing TeX."""

    def __call__(self, x, pos=None) -> str:
        return plain(super().__call__(x, pos))


def plain(label: str) -> str:
    """A mathtext tick label (``$\\mathdefault{2\\times10^{-3}}$``) as Unicode text (``2×10⁻³``); other text as
    it is. The sign is a minus sign (U+2212), as mathtext sets it."""
    match = _MATHTEXT.match(label)
    if match is None:
        return label
    text = _POWER.sub(lambda power: power.group(1).translate(_SUPERSCRIPT), match.group(1))
    return text.replace(r"\times", "×").replace("-", "\N{MINUS SIGN}")


def title(ax, text: str) -> None:
    """``text`` as the title of ``ax``, from its left edge; wrapped onto more lines where it would run past the
    figure's right margin (:func:`finish` makes room above the axes)."""
    fig = ax.figure
    room = (fig.get_size_inches()[0] - MARGINS["left"] - MARGINS["right"]) * fig.dpi
    width = fig.canvas.get_renderer().get_text_width_height_descent(text, FontProperties(size=TITLE_FONT_SIZE),
                                                                     ismath=False)[0]
    if width > room:
        text = textwrap.fill(text, int(len(text) * room / width))
    ax.set_title(text, loc="left", fontsize=TITLE_FONT_SIZE)


def legend(ax) -> None:
    """The legend outside the axes, on their right, top-aligned."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=LEGEND_FONT_SIZE, frameon=False)


def finish(fig, column_gap: float = 0.0, row_gap: float = 0.0, margins: dict[str, float] | None = None):
    """Lay ``fig`` out with fixed margins (:data:`MARGINS`, or ``margins`` [in]) and gaps between panels [in]:
    the top margin grows by a line per wrapped line of a :func:`title`, the right one by the widest legend. Log
    axes get :class:`UnicodeLogFormatter`. Returns ``fig``, which has no layout engine left, so saving draws it
    once."""
    for ax in fig.axes:
        for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
            if scale == "log":
                axis.set_major_formatter(UnicodeLogFormatter())
                axis.set_minor_formatter(UnicodeLogFormatter(labelOnlyBase=False))
    margins = dict(MARGINS, **(margins or {}))
    margins["top"] += TITLE_LINE * max(ax.get_title(loc="left").count("\n") for ax in fig.axes)
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    if legends:
        renderer = fig.canvas.get_renderer()
        widest = max(item.get_window_extent(renderer).width for item in legends) / fig.dpi
        margins["right"] += widest + LEGEND_GAP
    width, height = fig.get_size_inches()
    rows, columns = fig.axes[0].get_subplotspec().get_gridspec().get_geometry()
    inner_width = width - margins["left"] - margins["right"]
    inner_height = height - margins["top"] - margins["bottom"]
    fig.subplots_adjust(left=margins["left"] / width, right=1 - margins["right"] / width,
                        bottom=margins["bottom"] / height, top=1 - margins["top"] / height,
                        wspace=column_gap * columns / max(inner_width - column_gap * (columns - 1), 1e-3),
                        hspace=row_gap * rows / max(inner_height - row_gap * (rows - 1), 1e-3))
    fig.set_layout_engine(None)
    return fig
