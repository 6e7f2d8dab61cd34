"""The report's figures, drawn with matplotlib (headless ``Agg``) from a stored run's rows and series.

Each ``*_figure`` function returns a matplotlib Figure, laid out by :mod:`reports.figure_layout`, or None when the
run holds nothing to draw; :func:`save` writes it as SVG and PNG. Every axis names its quantity and unit, every
title the reference the errors are measured against.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping

import numpy as np
import pandas as pd

from simparity.core.model.results import SWEEP_PREFIX
from simparity.reports.figure_layout import finish, legend, power_of_ten, title, wrap
from simparity.reports.figure_writer import plt  # pyplot, headless, its SVG text reproducible
from simparity.reports.summary import AGREE_RELATIVE, ERROR_BUDGETS, EVALUATIONS
from simparity.core.model.metric_catalogue import (
    JOINT_ANGLE_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX, SOLVE_RATE, TIME_PER_SOLVE,
)

_ENGINE_MARKERS = {"core": "o", "mujoco": "s", "pybullet": "^", "pinocchio": "D"}
"""The marker of a scheme without variants: its engine's."""
_VARIANT_MARKERS = ("P", "X", "*", "v", "<", ">")
"""The markers of the variants of a scheme (core's orientation updates), in the order the run names the variants;
none is an engine's marker, so a marker says either the engine or the variant."""
_KEY_COLOR = "0.35"
"""The grey of the legend's marker key and of the theoretical slopes: no scheme's colour."""
SLOPE_OFFSET = 4.0
"""[factor] A theoretical slope is drawn this far below the lowest line of its order (0.6 decade): beside the data,
not over it."""
_HEADLINE_LABELS = {POSITION_ERROR_MAX: "position error max [m]",
                    ORIENTATION_ERROR_MAX: "orientation error max [rad]",
                    JOINT_ANGLE_ERROR_MAX: "joint angle error max [rad]"}
_DRIFT_PANELS = [("energy_change", "|E(t) - E(0)| / |E(0)|"), ("angular_momentum_change", "|L(t) - L(0)| / |L(0)|"),
                 ("position_error", "position error [m]"), ("orientation_error", "orientation error [rad]")]
_COLORS = (tuple(plt.get_cmap("tab10").colors) + tuple(plt.get_cmap("tab20").colors[1::2])  # type: ignore[attr-defined]  # ListedColormap
           + tuple(plt.get_cmap("tab20b").colors))  # type: ignore[attr-defined]
"""40 colours, the 10 most distinct first (tab10, then its light shades): a scene's schemes (13 engine x scheme in
the default suite, core's orientation updates sharing one) each get their own."""
_WIDTH = 10.0
"""[in] Figure width: report.html scales every figure to its 1200 px column (10 pt text at ~17 px, the legend's
7 pt at ~12 px); report.md's PNG is 1000 px wide at 100 dpi."""
_PANEL_GAP = 0.12
"""[in] Between panels stacked on one time or swept axis: their x tick labels show on the lowest one only."""
_SIDE_BY_SIDE_GAP = 0.95
"""[in] Between panels side by side: room for the right one's y tick labels and y label."""
_MATRIX_MARGINS = {"left": 1.4, "right": 1.0, "top": 0.3}
"""[in] The FK matrix: engine names on the left, the colour bar with its ticks and label on the right."""


def _style(index: int, engine: str) -> dict:
    colors = _COLORS
    return {"color": colors[index % len(colors)], "marker": _ENGINE_MARKERS.get(engine, "x"), "markersize": 4,
            "linewidth": 1.2}


def _positive(values) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    return np.where(values > 0, values, np.nan)


def _scheme_and_variant(engine: str, integrator: str, variants: Mapping | None) -> tuple[str, str]:
    """(scheme, variant) of ``integrator`` by ``variants`` (run.json's ``integrator_variants``: {engine: {integrator:
    [scheme, variant]}}; an integrator it does not name has no variant: ""); without it, by the name
    ``<scheme>+<variant>`` (the plain ``<scheme>`` then is its variant "")."""
    if variants is not None:
        scheme, variant = variants.get(engine, {}).get(integrator, (integrator, ""))
        return str(scheme), str(variant)
    scheme, plus, variant = integrator.partition("+")
    return (scheme, variant) if plus else (integrator, "")


def _plot_grouped(ax, lines: dict[tuple[str, str], pd.DataFrame], x: str, y: str, variants: Mapping | None) -> dict:
    """Draw ``lines`` (a frame per (engine, integrator), sorted by dt) as ``x`` against ``y``, the variants of a
    scheme grouped: one colour per engine x scheme, one marker per variant (:data:`_VARIANT_MARKERS`), one legend
    entry per scheme naming its variants and, after them, a grey marker key of the variants; a scheme without
    variants keeps its engine's marker. Returns each line's style by (engine, integrator)."""
    named = {pair: _scheme_and_variant(*pair, variants) for pair in lines}
    schemes = list(dict.fromkeys((engine, named[engine, integrator][0]) for engine, integrator in lines))
    members = {scheme: [pair for pair in lines if (pair[0], named[pair][0]) == scheme] for scheme in schemes}
    kinds = list(dict.fromkeys(named[pair][1] or "default" for group in members.values() if len(group) > 1
                               for pair in group))
    styles = {}
    for i, (engine, scheme) in enumerate(schemes):
        group = members[engine, scheme]
        for pair in group:
            style = _style(i, engine)
            label = f"{engine} {pair[1]}"
            if len(group) > 1:
                kind = named[pair][1] or "default"
                style |= {"marker": _VARIANT_MARKERS[kinds.index(kind) % len(_VARIANT_MARKERS)], "markersize": 5}
                label = "_" + label  # the scheme's entry below stands for it
            ax.plot(lines[pair][x], lines[pair][y], label=label, **style)
            styles[pair] = style
        if len(group) > 1:
            names = ", ".join(named[pair][1] or "default" for pair in group)
            ax.plot([], [], color=_style(i, engine)["color"], linewidth=1.2, label=wrap(f"{engine} {scheme} ({names})"))
    for k, kind in enumerate(kinds):
        ax.plot([], [], linestyle="none", marker=_VARIANT_MARKERS[k % len(_VARIANT_MARKERS)], color=_KEY_COLOR,
                markersize=5, label=f"marker: variant {kind}")
    return styles


def _error_budgets(ax) -> None:
    """The summary's error budgets as dotted vertical lines, each labelled inside the axes' top."""
    for budget in ERROR_BUDGETS:
        ax.axvline(budget, color="0.6", linestyle=":", linewidth=0.8)
        ax.text(budget, 0.98, f"error budget {power_of_ten(budget)}", transform=ax.get_xaxis_transform(),
                rotation=90, ha="right", va="top", fontsize=7, color=_KEY_COLOR,
                bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8, "pad": 1})  # readable over a line


def work_precision_figure(scene: str, cases: pd.DataFrame, headline: str, reference: str,
                          variants: Mapping | None = None):
    """Error (x, log) against cost per simulated second (y, log): one line per engine x integrator, one point per
    dt, the variants of a scheme in its colour with a marker each (``variants``: run.json's
    ``integrator_variants``; see :func:`_scheme_and_variant`), the error budgets of the summary dotted and labelled.
    Where the cases counted their force evaluations, a second panel below puts the same points against force
    evaluations per simulated second: the hardware-neutral cost, on which engines compare without their per-call
    overhead.

    ``cases``: :func:`reports.summary.dynamics_cases`."""
    measured = cases[(cases["status"] == "ok") & (cases["error"] > 0) & (cases["cost"] > 0)]
    if measured.empty:
        return None
    counted = EVALUATIONS in measured and bool((measured[EVALUATIONS] > 0).any())
    costs = [("cost", "wall time per simulated second [s/s]")] + (
        [(EVALUATIONS, "force evaluations per simulated second [1/s]")] if counted else [])
    fig, axes = plt.subplots(len(costs), 1, figsize=(_WIDTH, 4.8 + 3.2 * (len(costs) - 1)), sharex=True,
                             squeeze=False)
    for ax, (column, label) in zip(axes[:, 0], costs):
        shown = measured[measured[column] > 0]
        lines = {pair: g.sort_values("dt") for pair, g in shown.groupby(["engine", "integrator"], sort=False)}
        _plot_grouped(ax, lines, "error", column, variants)
        _error_budgets(ax)
        ax.set(xscale="log", yscale="log", ylabel=label)
        ax.grid(True, which="major", alpha=0.3)
    axes[-1, 0].set_xlabel(_HEADLINE_LABELS[headline])
    title(axes[0, 0], f"{scene}: work against precision (one point per dt; error against {reference})")
    legend(axes[0, 0])
    return finish(fig, row_gap=_PANEL_GAP)


def _agree(a: pd.DataFrame, b: pd.DataFrame) -> bool:
    """Whether two lines (sorted by dt) have the same time steps and errors within :data:`AGREE_RELATIVE`."""
    return (len(a) == len(b) and bool(np.array_equal(a["dt"].to_numpy(), b["dt"].to_numpy()))
            and bool(np.allclose(a["error"], b["error"], rtol=AGREE_RELATIVE, atol=0.0)))


def _fit_text(pair: tuple[str, str], g: pd.DataFrame, observed: Mapping, unfitted: Mapping | None) -> str:
    """"observed 4.00", or "no fit: <reason>": the order row's reason up to its first colon (``unfitted``: {(engine,
    integrator): the n/a order row's detail}), else what the figure's own points say."""
    fitted = observed.get(pair, math.nan)
    if math.isfinite(fitted):
        return f"observed {fitted:.2f}"
    reason = (unfitted or {}).get(pair, "")
    if not reason:
        reason = f"only {len(g)} time steps measured" if len(g) < 3 else "no order in the run (see the order table)"
    return f"no fit: {reason.split(':')[0]}"


def convergence_figure(scene: str, cases: pd.DataFrame, headline: str, reference: str,
                       observed: dict[tuple[str, str], float], theory: dict[str, dict[str, int]],
                       unfitted: Mapping | None = None):
    """Error (log) against dt (log) per engine x integrator, the observed order in the legend ("no fit: <reason>",
    dotted, where none was fitted; ``unfitted``: :func:`_fit_text`), schemes whose errors agree
    (:data:`AGREE_RELATIVE`) as one line naming them all, and per theoretical order p a grey dashed line of slope p
    (:data:`SLOPE_OFFSET` under the lowest line of that order), labelled."""
    measured = cases[(cases["status"] == "ok") & (cases["error"] > 0)]
    if measured["dt"].nunique() < 2:
        return None
    fig, ax = plt.subplots(figsize=(_WIDTH, 4.8))
    groups: list[tuple[list[tuple[str, str]], pd.DataFrame]] = []
    for (engine, integrator), g in measured.groupby(["engine", "integrator"], sort=False):
        g = g.sort_values("dt")
        p = theory.get(engine, {}).get(integrator)
        same = next((members for members, first in groups if _agree(first, g)
                     and theory.get(members[0][0], {}).get(members[0][1]) == p), None)
        if same is None:
            groups.append(([(engine, integrator)], g))
        else:
            same.append((engine, integrator))
    lowest: dict[int, pd.DataFrame] = {}
    for i, (members, g) in enumerate(groups):
        p = theory.get(members[0][0], {}).get(members[0][1])
        fits = " / ".join(dict.fromkeys(_fit_text(pair, g, observed, unfitted) for pair in members))
        label = " = ".join(f"{engine} {integrator}" for engine, integrator in members) + f": {fits}"
        ax.plot(g["dt"], g["error"], label=wrap(label + (f", theory {p}" if p else "")),
                **_style(i, members[0][0]) | ({"linestyle": ":"} if "no fit" in fits else {}))
        if p and len(g) > 1 and (p not in lowest or g["error"].iloc[0] < lowest[p]["error"].iloc[0]):
            lowest[p] = g
    for p, g in sorted(lowest.items()):
        dts = np.geomspace(g["dt"].iloc[0], g["dt"].iloc[-1], 3)
        errors = g["error"].iloc[0] / SLOPE_OFFSET * (dts / dts[0]) ** p
        ax.plot(dts, errors, linestyle="--", linewidth=0.9, color=_KEY_COLOR)
        ax.text(dts[1], errors[1], f"slope {p}", ha="left", va="top", fontsize=7, color=_KEY_COLOR)
    ax.set(xscale="log", yscale="log", xlabel="time step dt [s]", ylabel=_HEADLINE_LABELS[headline])
    title(ax, f"{scene}: convergence against {reference} (grey dashed: theoretical slope p)")
    ax.grid(True, which="major", alpha=0.3)
    legend(ax)
    return finish(fig)


def drift_figure(scene: str, series: pd.DataFrame, reference: str):
    """Drift of the conserved quantities and error against time, at the scene's coarsest time step with
    series (where drift shows most), one line per engine x integrator. Magnitudes on a log axis."""
    timed = series[series["quantity"].isin([q for q, _ in _DRIFT_PANELS])]
    if timed.empty or not timed["quantity"].isin(["energy_change", "angular_momentum_change"]).any():
        return None
    dt = timed["dt"].max()
    at_dt = timed[timed["dt"] == dt]
    # A panel whose values are all zero (a body that does not move) has nothing to show on a log axis.
    panels = [(q, label) for q, label in _DRIFT_PANELS if (at_dt.loc[at_dt["quantity"] == q, "value"] != 0).any()]
    fig, axes = plt.subplots(len(panels), 1, figsize=(_WIDTH, 2.3 * len(panels)), sharex=True, squeeze=False)
    schemes = list(dict.fromkeys(zip(at_dt["engine"], at_dt["integrator"])))
    for ax, (quantity, label) in zip(axes[:, 0], panels):
        for i, (engine, integrator) in enumerate(schemes):
            g = at_dt[(at_dt["quantity"] == quantity) & (at_dt["engine"] == engine) & (at_dt["integrator"] == integrator)]
            if not g.empty:
                ax.plot(g["x"], _positive(np.abs(g["value"])), label=f"{engine} {integrator}",
                        **(_style(i, engine) | {"marker": None}))
        ax.set(yscale="log", ylabel=label)
        ax.grid(True, which="major", alpha=0.3)
    title(axes[0, 0], f"{scene}: drift and error against time at dt = {dt:g} s (errors against {reference})")
    axes[-1, 0].set_xlabel("time [s]")
    legend(axes[0, 0])
    return finish(fig, row_gap=_PANEL_GAP)


def contact_height_figure(scene: str, series: pd.DataFrame, reference: str):
    """Height of the first body's lowest point above its nearest plane against time, at the scene's coarsest
    time step, one line per engine x integrator and the reference's (envelope of the samples: apexes and
    penetrations kept)."""
    heights = series[series["quantity"] == "support_height"]
    if heights.empty:
        return None
    dt = heights["dt"].max()
    at_dt = heights[heights["dt"] == dt]
    fig, ax = plt.subplots(figsize=(_WIDTH, 3.2))
    for i, ((engine, integrator), g) in enumerate(at_dt.groupby(["engine", "integrator"], sort=False)):
        ax.plot(g["x"], g["value"], label=f"{engine} {integrator}", **(_style(i, engine) | {"marker": None}))
    ax.axhline(0.0, color="black", linewidth=0.8)
    ax.set(xlabel="time [s]", ylabel="lowest point height [m]")
    ax.grid(True, which="major", alpha=0.3)
    title(ax, f"{scene}: height of the lowest point at dt = {dt:g} s (reference {reference})")
    legend(ax)
    return finish(fig)


def ik_rate_figure(scene: str, solvers: pd.DataFrame, reference: str):
    """Solve rate against time per solve (log), one point per engine x solver."""
    rated = solvers.dropna(subset=[SOLVE_RATE, TIME_PER_SOLVE])
    if rated.empty:
        return None
    fig, ax = plt.subplots(figsize=(_WIDTH, 4.0))
    for i, (_, r) in enumerate(rated.iterrows()):
        ax.plot([r[TIME_PER_SOLVE]], [r[SOLVE_RATE]], linestyle="none",
                label=f"{r['engine']} {r['integrator']}", **_style(i, r["engine"]) | {"markersize": 7})
    ax.set(xscale="log", xlabel="time per solve [s]", ylabel="solve rate", ylim=(-0.03, 1.03))
    title(ax, f"{scene}: solve rate against time per solve (targets from {reference})")
    ax.grid(True, alpha=0.3)
    legend(ax)
    return finish(fig)


def ik_distribution_figure(scene: str, series: pd.DataFrame, position_tolerance: float | None):
    """Cumulative distributions of the position residual and the iterations per engine x solver."""
    panels = [(q, label) for q, label in (("position_residual", "position residual [m]"),
                                          ("iterations", "iterations")) if (series["quantity"] == q).any()]
    if not panels:
        return None
    fig, axes = plt.subplots(1, len(panels), figsize=(_WIDTH, 3.8), squeeze=False)
    for ax, (quantity, label) in zip(axes[0], panels):
        rows = series[series["quantity"] == quantity]
        for i, ((engine, solver), g) in enumerate(rows.groupby(["engine", "integrator"], sort=False)):
            ax.plot(_positive(g["value"]), g["x"], label=f"{engine} {solver}", **(_style(i, engine) | {"marker": None}))
        if quantity == "position_residual" and position_tolerance:
            ax.axvline(position_tolerance, color="0.3", linestyle=":", linewidth=0.9, label="scene tolerance")
        ax.set(xscale="log", xlabel=label, ylabel="fraction of targets at or below", ylim=(0, 1.02))
        ax.grid(True, alpha=0.3)
    title(axes[0, 0], f"{scene}: distributions over the random targets")
    legend(axes[0, -1])
    return finish(fig, column_gap=_SIDE_BY_SIDE_GAP)


def fk_matrix_figure(scene: str, series: pd.DataFrame):
    """Largest end-effector distance [m] between every two engines' FK over all IK solutions."""
    rows = series[series["quantity"] == "fk_disagreement_max"]
    if rows.empty:
        return None
    names = list(dict.fromkeys(rows["engine"]))
    matrix = np.full((len(names), len(names)), np.nan)
    for _, r in rows.iterrows():
        matrix[names.index(r["engine"]), names.index(r["integrator"])] = r["value"]
    fig, ax = plt.subplots(figsize=(_WIDTH, 0.5 * len(names) + 1.2))
    shown = np.log10(np.maximum(matrix, 1e-17))
    image = ax.imshow(shown, cmap="viridis", aspect="auto")  # cells as wide as the page allows
    for i in range(len(names)):
        for j in range(len(names)):
            text = "—" if i == j else f"{matrix[i, j]:.1e}"
            light = i != j and sum(image.cmap(image.norm(shown[i, j]))[:3]) > 1.5  # a light cell: dark text
            ax.text(j, i, text, ha="center", va="center", fontsize=8,
                    color="0.5" if i == j else "black" if light else "white")
    ax.set_xticks(range(len(names)), names)
    ax.set_yticks(range(len(names)), names)
    fig.colorbar(image, ax=ax, label="log10 distance [m]")
    ax.set_title(f"{scene}: FK agreement, largest distance [m]", fontsize=9)
    return finish(fig, margins=_MATRIX_MARGINS)


def sweep_work_precision_figure(base: str, across: pd.DataFrame, label: str, reference: str, variants: int,
                                integrator_variants: Mapping | None = None):
    """Work against precision over a sweep's ``variants``: per engine x integrator one point per dt at its worst
    variant's error (x, log) and its median cost over the variants (y, log), a band from there to its best
    variant's error, the variants of a scheme grouped as in :func:`work_precision_figure` (``integrator_variants``),
    the error budgets of the summary dotted and labelled; None when no scheme was ok in every variant.

    ``across``: :func:`reports.sweep_summary.across` of a dynamics sweep's cases (value: the error)."""
    measured = across[(across["status"] == "ok") & (across["value"] > 0) & (across["cost"] > 0)]
    if measured.empty:
        return None
    fig, ax = plt.subplots(figsize=(_WIDTH, 4.8))
    lines = {pair: g.sort_values("dt") for pair, g in measured.groupby(["engine", "integrator"], sort=False)}
    styles = _plot_grouped(ax, lines, "value", "cost", integrator_variants)
    for pair, g in lines.items():
        ax.hlines(g["cost"], _positive(g["best"]), g["value"], color=styles[pair]["color"], linewidth=4, alpha=0.3)
    _error_budgets(ax)
    ax.set(xscale="log", yscale="log", xlabel=label, ylabel="compute per simulated second, median [s/s]")
    title(ax, f"{base}: work against precision over {variants} variants (worst variant; band to the best; error "
              f"against {reference})")
    ax.grid(True, which="major", alpha=0.3)
    legend(ax)
    return finish(fig)


def sweep_figure(base: str, cases: pd.DataFrame, x: str, panels: list[str], label: str, reference: str):
    """A metric (y) against the last swept key (x), one line per engine x integrator, one panel per combination
    of ``panels`` (the other swept keys, and dt) in the order they come; None when nothing was measured.

    ``cases``: :func:`reports.sweep_sections.sweep_cases` (columns engine, integrator, the keys, status, value)."""
    measured = cases[(cases["status"] == "ok") & cases["value"].notna()]
    if measured.empty:
        return None
    groups = list(measured.groupby(panels, sort=False)) if panels else [((), measured)]
    xs = measured[x].astype(float)
    log_x = bool((xs > 0).all() and xs.max() >= 10 * xs.min())
    log_y = bool((measured["value"] > 0).all())
    schemes = list(dict.fromkeys(zip(measured["engine"], measured["integrator"])))
    fig, axes = plt.subplots(len(groups), 1, figsize=(_WIDTH, 2.4 * len(groups) + 0.8), sharex=True, squeeze=False)
    for ax, (key, g) in zip(axes[:, 0], groups):
        for i, (engine, integrator) in enumerate(schemes):
            line = g[(g["engine"] == engine) & (g["integrator"] == integrator)].sort_values(x)
            if not line.empty:
                ax.plot(line[x].astype(float), line["value"], label=f"{engine} {integrator}", **_style(i, engine))
        at = ", ".join(f"{name.removeprefix(SWEEP_PREFIX)} = {float(v):g}" + (" s" if name == "dt" else "")
                       for name, v in zip(panels, key if isinstance(key, tuple) else (key,)))
        if at:
            ax.text(0.99, 0.96, at, transform=ax.transAxes, ha="right", va="top", fontsize=8,
                    bbox={"facecolor": "white", "edgecolor": "0.8", "pad": 2})
        ax.set(yscale="log" if log_y else "linear", ylabel=label)
        ax.grid(True, which="major", alpha=0.3)
    title(axes[0, 0], f"{base}: {label} against {x.removeprefix(SWEEP_PREFIX)} (against {reference})")
    axes[-1, 0].set(xlabel=x.removeprefix(SWEEP_PREFIX), xscale="log" if log_x else "linear")
    legend(axes[0, 0])
    return finish(fig, row_gap=_PANEL_GAP)


def sweep_parameter_figure(base: str, panels: list[tuple[str, pd.DataFrame]], key: str, reference: str):
    """Headline metrics (one panel each) against one swept ``key`` (x) over a sweep of many variants: per engine x
    integrator the median over the variants sharing each value of ``key`` (the other swept keys varying), a pale band
    from their least to their largest; None when no panel holds a value.

    ``panels``: (the metric's label, its values: columns engine, integrator, value and the sweep's key columns;
    :func:`reports.sweep_compact.parameter_cases`)."""
    panels = [(label, cases) for label, cases in panels if not cases.empty]
    if not panels:
        return None
    xs = pd.concat([cases[key] for _, cases in panels]).astype(float)
    log_x = bool((xs > 0).all() and xs.max() >= 10 * xs.min())
    fig, axes = plt.subplots(len(panels), 1, figsize=(_WIDTH, 2.6 * len(panels) + 0.8), sharex=True, squeeze=False)
    for ax, (label, cases) in zip(axes[:, 0], panels):
        schemes = list(dict.fromkeys(zip(cases["engine"], cases["integrator"])))
        for i, (engine, integrator) in enumerate(schemes):
            mine = cases[(cases["engine"] == engine) & (cases["integrator"] == integrator)]
            spread = mine.groupby(mine[key].astype(float))["value"].agg(["min", "median", "max"]).sort_index()
            style = _style(i, engine)
            ax.fill_between(spread.index, spread["min"], spread["max"], color=style["color"], alpha=0.15, linewidth=0)
            ax.plot(spread.index, spread["median"], label=f"{engine} {integrator}", **style)
        log_y = bool((cases["value"] > 0).all())
        ax.set(yscale="log" if log_y else "linear", ylabel=label)
        ax.grid(True, which="major", alpha=0.3)
    name = key.removeprefix(SWEEP_PREFIX)
    title(axes[0, 0], f"{base}: against {name}, median and range over the other swept values (against {reference})")
    axes[-1, 0].set(xlabel=name, xscale="log" if log_x else "linear")
    legend(axes[0, 0])
    return finish(fig, row_gap=_PANEL_GAP)


_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]")


def figure_stem(name: str) -> str:
    """A figure's file name (without suffix) from a name built of a scene's: every character but letters, digits and
    ``_ . -`` made ``_`` and no leading dot, so no name (``../x``, ``/abs``, ``a/b``) leads out of the folder."""
    return _UNSAFE.sub("_", name).lstrip(".") or "figure"


_DIFFERENCE_QUANTITIES = (("forward_difference_error", "-"), ("central_difference_error", "--"))
"""The step sweep's series (comparisons.execute.derivative_runner) and their line styles: forward solid, centred
dashed."""


def difference_step_figure(series: pd.DataFrame):
    """The error of dtau/dq by finite differences of each engine's own inverse dynamics against the step, one panel
    per joint-dynamics scene (stacked on one step axis), one colour per engine x method, forward differences solid
    and centred dashed, each line's best step marked: the V of truncation against rounding."""
    swept = series[series["quantity"].isin([q for q, _ in _DIFFERENCE_QUANTITIES])]
    if swept.empty:
        return None
    scenes = list(dict.fromkeys(swept["scene"]))
    fig, axes = plt.subplots(len(scenes), 1, figsize=(_WIDTH, 1.9 * len(scenes) + 0.6), sharex=True, squeeze=False)
    schemes = list(dict.fromkeys(zip(swept["engine"], swept["integrator"])))
    for ax, scene in zip(axes[:, 0], scenes):
        for i, (engine, method) in enumerate(schemes):
            for quantity, line in _DIFFERENCE_QUANTITIES:
                g = swept[(swept["scene"] == scene) & (swept["engine"] == engine) & (swept["integrator"] == method)
                          & (swept["quantity"] == quantity)].dropna(subset=["value"])
                if g.empty:
                    continue
                style = _style(i, engine) | {"marker": None, "linestyle": line}
                label = f"{engine} {method}" if line == "-" else None
                ax.plot(g["x"], _positive(g["value"]), label=label, **style)
                best = g.loc[g["value"].idxmin()]
                ax.plot([best["x"]], [max(best["value"], 1e-17)], linestyle="none",
                        **(_style(i, engine) | {"markersize": 5}))
        ax.set(xscale="log", yscale="log", ylabel="dtau/dq error")
        ax.text(0.01, 0.04, scene, transform=ax.transAxes, fontsize=8, ha="left", va="bottom")
        ax.grid(True, which="major", alpha=0.3)
    shown = set(axes[0, 0].get_legend_handles_labels()[1])
    for i, (engine, method) in enumerate(schemes):  # the legend (on the top panel) names every panel's lines
        if f"{engine} {method}" not in shown:
            axes[0, 0].plot([], [], label=f"{engine} {method}", **(_style(i, engine) | {"marker": None}))
    axes[-1, 0].set_xlabel("finite-difference step h [rad or m]")
    axes[-1, 0].invert_xaxis()
    title(axes[0, 0], "dtau/dq by finite differences of each engine's inverse dynamics against the complex-step "
                      "truth (solid: forward, dashed: centred; marker: the best step)")
    legend(axes[0, 0])
    return finish(fig, row_gap=_PANEL_GAP)
