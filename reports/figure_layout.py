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

import functools
import math
import re
import textwrap

import matplotlib
from matplotlib.axis import Axis, XAxis
from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.font_manager import FontProperties
from matplotlib.ticker import LogFormatterSciNotation

MARGINS = {"left": 0.85, "right": 0.15, "bottom": 0.5, "top": 0.35}
"""[in] Room around the axes: left for y tick labels up to ~8 characters and the y label, bottom for the x tick
labels and x label, top for a one-line title, right for nothing but the frame (a legend adds its own width)."""

LEGEND_GAP = 0.15
"""[in] Between the axes' right edge and a legend placed at 1.01 axes widths, plus the legend's own padding."""

LEGEND_FONT_SIZE = 7
"""[pt] Legend text: up to ~25 schemes must fit beside a 4.8 in high axes."""

MIN_PANEL_WIDTH = 2.5
"""[in] The narrowest a panel may be: a figure whose legend leaves less (a run with many engines and schemes) is
widened to keep it, never laid out with its axes crushed (or left of its own left edge)."""

MAX_LEGEND_COLUMNS = 3
"""A legend too tall for its figure takes up to this many columns (each ~2 in of the width of the axes)."""

TITLE_FONT_SIZE = 10
"""[pt] Titles, a size above the tick labels'."""

TITLE_LINE = 0.2
"""[in] What each line of a wrapped title adds to the top margin: 10 pt text at matplotlib's 1.2 line spacing."""

TICK_LABEL_GAP = 6.0
"""[px] Least room between two neighbouring tick labels of a log axis (at the figure's dpi): about half a
character of 10 pt text, so that two labels never read as one ("2×10⁻⁴3×10⁻⁴")."""

LEGEND_LABEL_CHARS = 52
"""[characters] A legend entry longer than this is wrapped onto more lines (a reason a fit failed, the schemes whose
results agree), so that the legend does not take the axes' width."""

SUBLABELS = ((1, 2, 3, 4, 5, 6, 7, 8, 9), (1, 2, 3, 4, 6), (1, 2, 5), (1, 3), (1,))
"""The coefficients k of k×10ⁿ that a log axis spanning less than a decade or two may label, densest first
(matplotlib's own two choices, then sparser ones): the densest whose labels keep :data:`TICK_LABEL_GAP` apart."""

_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_POWER = re.compile(r"\^\{(-?[0-9]+)\}")
_MATHTEXT = re.compile(r"^\$\\mathdefault\{(.*)\}\$$")


class UnicodeLogFormatter(LogFormatterSciNotation):
    """matplotlib's log-axis tick labels (the same ticks labelled, ``10^{k}`` and ``2\\times10^{k}``) as plain
    text with Unicode superscripts, so a label is laid out from the font without parsing TeX."""

    _sublabels: set | None   # matplotlib's: the coefficients k of k×10ⁿ to label (None: every one)

    def __call__(self, x, pos=None) -> str:
        return plain(super().__call__(x, pos))

    def set_locs(self, locs=None) -> None:
        """matplotlib's choice of the coefficients to label (every one on an axis spanning less than ~0.4 decade,
        1, 2, 3, 4, 6 on one under two decades, decades alone otherwise), thinned to the densest of
        :data:`SUBLABELS` whose labels, with the decades', do not come closer than :data:`TICK_LABEL_GAP` on this
        axis: at 2×10⁻⁴ to 3×10⁻³ on a 5 in axis matplotlib's labels touch."""
        super().set_locs(locs)
        axis = self.axis
        if self._sublabels is None or self._sublabels == {1} or not isinstance(axis, Axis):
            return
        vmin, vmax = sorted(axis.get_view_interval())
        horizontal = isinstance(axis, XAxis)
        box = axis.axes.bbox
        length = box.width if horizontal else box.height
        if not (0 < vmin < vmax and length > 0):
            return
        lo, hi = math.log10(vmin), math.log10(vmax)
        size = _tick_label_size(axis, horizontal, max(abs(math.floor(lo)), abs(math.floor(hi))))
        for coefficients in (c for c in SUBLABELS if len(c) <= len(self._sublabels)):
            labelled = [math.log10(k) + n for n in range(math.floor(lo), math.ceil(hi) + 1) for k in coefficients
                        if lo <= math.log10(k) + n <= hi]
            gaps = [(b - a) / (hi - lo) * length for a, b in zip(labelled, labelled[1:])]
            if all(gap >= size + TICK_LABEL_GAP for gap in gaps):
                self._sublabels = set(coefficients)
                return
        self._sublabels = {1}


@functools.lru_cache(maxsize=4)
def _measuring(dpi: float) -> RendererAgg:
    """An Agg renderer at ``dpi`` to measure text with, whatever canvas is drawing (saving as SVG swaps the canvas
    for one that has no renderer to ask, and draws at 72 dpi)."""
    return RendererAgg(1, 1, dpi)


def _tick_label_size(axis, horizontal: bool, exponent: int) -> float:
    """[px] The extent along ``axis`` (horizontal: an x axis) of its widest k×10⁻ⁿ label (``exponent``: the largest |n|) when horizontal,
    of one line of its labels when vertical."""
    font = FontProperties(size=matplotlib.rcParams["xtick.labelsize" if horizontal else "ytick.labelsize"])
    text = "8×10\N{MINUS SIGN}" + str(exponent).translate(_SUPERSCRIPT)
    width, height, _ = _measuring(axis.figure.dpi).get_text_width_height_descent(text, font, ismath=False)
    return width if horizontal else height


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
    """The legend outside the axes, on their right, top-aligned; in as many columns as it needs to end above the
    figure's bottom edge (22 schemes beside a 3.2 in high figure take two)."""
    fig = ax.figure
    room = (fig.get_size_inches()[1] - MARGINS["top"]) * fig.dpi
    renderer = fig.canvas.get_renderer()
    columns = 1
    while True:
        made = ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=LEGEND_FONT_SIZE, frameon=False,
                         ncols=columns)
        if columns == MAX_LEGEND_COLUMNS or made.get_window_extent(renderer).height <= room:
            return
        columns += 1


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
    narrowest = margins["left"] + margins["right"] + columns * MIN_PANEL_WIDTH + column_gap * (columns - 1)
    if width < narrowest:
        width = narrowest
        fig.set_size_inches(width, height)
    inner_width = width - margins["left"] - margins["right"]
    inner_height = height - margins["top"] - margins["bottom"]
    fig.subplots_adjust(left=margins["left"] / width, right=1 - margins["right"] / width,
                        bottom=margins["bottom"] / height, top=1 - margins["top"] / height,
                        wspace=column_gap * columns / max(inner_width - column_gap * (columns - 1), 1e-3),
                        hspace=row_gap * rows / max(inner_height - row_gap * (rows - 1), 1e-3))
    fig.set_layout_engine(None)
    return fig


def power_of_ten(value: float) -> str:
    """``value``, a power of ten, as a tick label sets it (``10⁻⁶``)."""
    exponent = round(math.log10(value))
    return "10" + str(exponent).translate(_SUPERSCRIPT).replace("-", "\N{MINUS SIGN}")


def wrap(label: str) -> str:
    """A legend entry on lines of at most :data:`LEGEND_LABEL_CHARS` characters, later lines indented."""
    return textwrap.fill(label, LEGEND_LABEL_CHARS, subsequent_indent="  ", break_on_hyphens=False)
