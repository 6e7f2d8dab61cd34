"""Laying out the report's figures (reports/figure_layout.py): log-axis tick labels as Unicode text, not mathtext,
and fixed margins with room for the legend, leaving no layout engine behind."""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from simparity.reports.figure_layout import (  # noqa: E402
    MARGINS,
    MIN_PANEL_WIDTH,
    TITLE_LINE,
    UnicodeLogFormatter,
    finish,
    legend,
    plain,
    title,
)

PIXEL = 1.0
"""[px] Positions read back from a laid-out figure are exact to the pixel grid at its dpi, no better."""


@pytest.mark.parametrize("label, text", [
    (r"$\mathdefault{10^{-6}}$", "10⁻⁶"),
    (r"$\mathdefault{10^{12}}$", "10¹²"),
    (r"$\mathdefault{2\times10^{-3}}$", "2×10⁻³"),
    (r"$\mathdefault{-10^{2}}$", "\N{MINUS SIGN}10²"),
    (r"$\mathdefault{0.5}$", "0.5"),
    ("", ""),
    ("0.25", "0.25"),
])
def test_plain_turns_matplotlibs_tick_labels_into_unicode(label, text):
    assert plain(label) == text


def test_log_axes_label_the_same_ticks_without_mathtext():
    fig, ax = plt.subplots()
    ax.plot([1e-3, 3e-3], [1e-12, 1e-2])
    ax.set(xscale="log", yscale="log")
    finish(fig)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_yticklabels() + ax.get_xticklabels(minor=True) if t.get_text()]
    assert "10⁻⁶" in labels and "2×10⁻³" in labels and not any("$" in label for label in labels)
    assert isinstance(ax.yaxis.get_major_formatter(), UnicodeLogFormatter)
    plt.close(fig)


def test_fixed_margins_and_room_for_the_legend():
    fig, ax = plt.subplots(figsize=(9.0, 4.0))
    ax.plot([0, 1], [0, 1], label="a scheme with a rather long name, observed 4.01, theory 4")
    legend(ax)
    finish(fig)
    assert fig.get_layout_engine() is None   # a save draws the figure once
    box = ax.get_position()
    assert math.isclose(box.x0 * 9.0, MARGINS["left"]) and math.isclose((1 - box.y1) * 4.0, MARGINS["top"])
    fig.canvas.draw()
    assert ax.get_legend().get_window_extent().x1 <= fig.bbox.width + PIXEL   # the legend is inside the figure
    plt.close(fig)


@pytest.mark.slow  # ~1.5 s of CPU: figures drawn
def test_a_legend_wider_than_the_figure_widens_it_instead_of_crushing_the_axes():
    """Found by a run of core beside three copies of it: dozens of schemes gave a three-column legend wider than the
    figure, and laying it out raised (left >= right) and lost the report."""
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    for i in range(60):
        ax.plot([0, 1], [0, i], label=f"mutant-copy-{i:02d} semi_implicit_euler: observed 1.00, theory 1, a long label")
    legend(ax)
    finish(fig)
    fig.canvas.draw()
    assert ax.get_position().width * fig.get_size_inches()[0] >= MIN_PANEL_WIDTH - 1e-9
    assert ax.get_legend().get_window_extent().x1 <= fig.bbox.width + PIXEL
    plt.close(fig)


def test_gaps_between_panels_are_in_inches():
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.0))
    finish(fig, column_gap=1.0)
    left, right = (ax.get_position() for ax in axes)
    assert math.isclose((right.x0 - left.x1) * 9.0, 1.0)
    plt.close(fig)


def test_a_title_too_long_for_the_figure_wraps_and_the_axes_make_room():
    short = plt.subplots(figsize=(9.0, 4.0))[1]
    title(short, "a scene: convergence")
    assert "\n" not in short.get_title(loc="left")
    fig, ax = plt.subplots(figsize=(9.0, 4.0))
    title(ax, "a_scene_with_a_long_variant_name.0-6.0_gravity_world.2--10.0: work against precision (one point per "
              "dt; error against analytic:exact)")
    assert ax.get_title(loc="left").count("\n") == 1
    finish(fig)
    assert math.isclose((1 - ax.get_position().y1) * 4.0, MARGINS["top"] + TITLE_LINE)
    fig.canvas.draw()
    box = ax.get_tightbbox()   # the axes with their labels and titles
    assert box.x1 <= fig.bbox.width + PIXEL and box.y1 <= fig.bbox.height + PIXEL
    plt.close("all")
