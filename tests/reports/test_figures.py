"""The report's figures (reports/figures.py), drawn from hand-made cases: laid out once with no layout engine left
(a save draws once), log ticks without mathtext, and the sweep's figures."""

import os
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from matplotlib.ticker import LogFormatterSciNotation

from simparity.core.model.metric_catalogue import (
    ORIENTATION_ERROR_MAX,
    OWN_STOP_POSITION_TOLERANCE,
    SOLVE_RATE,
    SOLVE_RATE_OWN_STOP,
    TIME_PER_SOLVE,
)
from simparity.reports import figure_writer, figures
from simparity.reports.figure_layout import finish, power_of_ten
from simparity.reports.summary import ERROR_BUDGETS

REFERENCE = "analytic:exact"

OVERLAP_PIXELS = 1.0
"""[px at 100 dpi] How far two texts' boxes may run into each other, in each direction, and a text past the figure's
edge: matplotlib snaps a text to the pixel grid, so boxes that just touch can share a pixel; any more is two texts
printed over each other (on a log axis, "2×10⁻⁴3×10⁻⁴")."""


def _texts(fig) -> list:
    """Every text drawn in ``fig``: tick labels of the ticks drawn, axis labels, titles, texts placed in the axes,
    legend entries and titles, the figure's own texts."""
    texts = list(fig.texts)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            texts += [label for tick in axis._update_ticks() for label in (tick.label1, tick.label2)]
            texts += [axis.label, axis.get_offset_text()]
        texts += [ax.title, ax._left_title, ax._right_title, *ax.texts]
        if ax.get_legend() is not None:
            texts += [*ax.get_legend().get_texts(), ax.get_legend().get_title()]
    return [t for t in texts if t.get_visible() and t.get_text().strip()]


def overlaps(fig) -> list[str]:
    """Pairs of texts of ``fig`` (drawn with Agg) whose boxes intersect by more than :data:`OVERLAP_PIXELS` in
    both directions, and texts that reach past the figure's edge by more; [] for a figure where every text can be
    read."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = _texts(fig)
    boxes = [t.get_window_extent(renderer) for t in texts]
    found = [f"{a.get_text()!r} past the figure's edge" for a, box in zip(texts, boxes)
             if box.x0 < -OVERLAP_PIXELS or box.y0 < -OVERLAP_PIXELS
             or box.x1 > fig.bbox.width + OVERLAP_PIXELS or box.y1 > fig.bbox.height + OVERLAP_PIXELS]
    for i, (a, box_a) in enumerate(zip(texts, boxes)):
        for b, box_b in zip(texts[i + 1:], boxes[i + 1:]):
            wide = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0)
            high = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0)
            if wide > OVERLAP_PIXELS and high > OVERLAP_PIXELS:
                found.append(f"{a.get_text()!r} over {b.get_text()!r} ({wide:.0f} x {high:.0f} px)")
    return found


def _cases():
    """Two schemes at three time steps (summary.dynamics_cases' columns)."""
    return pd.DataFrame([{"scene": "s", "engine": engine, "integrator": "rk4", "dt": dt, "status": "ok",
                          "error": scale * dt ** 4, "time_per_step": 1e-5, "cost": 1e-5 / dt}
                         for engine, scale in (("core", 1.0), ("mujoco", 2.0)) for dt in (0.01, 0.02, 0.04)])


def _drawn_labels(fig) -> list[str]:
    fig.canvas.draw()
    return [t.get_text() for ax in fig.axes for t in ax.get_xticklabels() + ax.get_yticklabels() if t.get_text()]


@pytest.mark.slow
def test_dynamics_figures_leave_no_layout_engine_and_label_log_ticks_in_unicode():
    for fig in (figures.work_precision_figure("s", _cases(), "position_error_max", REFERENCE),
                figures.convergence_figure("s", _cases(), "position_error_max", REFERENCE, {}, {"core": {"rk4": 4}})):
        assert fig.get_layout_engine() is None
        labels = _drawn_labels(fig)
        assert any("10⁻" in label for label in labels) and not any("$" in label for label in labels)
        figures.plt.close(fig)


def _across(statuses=("ok", "ok")):
    """One scheme over a sweep's variants at two time steps (sweep_summary.across' columns)."""
    return pd.DataFrame({"engine": "core", "integrator": "rk4", "dt": [0.01, 0.02], "status": list(statuses),
                         "value": [1e-6, 1e-5], "best": [1e-8, 0.0], "median": [1e-7, 1e-6], "cost": [1e-3, 5e-4]})


# Representative inputs, shaped after a stored quick run of the default suite (q-default): its engines, integrators
# (core's orientation updates as variants), theoretical orders, three time steps, IK solvers' names and times.
DTS = (0.0025, 0.005, 0.01)
SCHEMES = {"core": {"explicit_euler": 1, "average_velocity": 2, "midpoint": 2, "rk4": 4, "semi_implicit_euler": 1},
           "mujoco": {"euler": 1, "rk4": 4, "implicit": 1, "implicitfast": 1}, "pybullet": {"euler": 1},
           "pinocchio": {"euler": 1, "rk4": 4}}
ORIENTATION_UPDATES = {"quaternion": 1.0, "matrix": 1.02, "expmap": 0.95}
"""core's variants (run.json's names) and how much each one's error differs from the quaternion update's."""
VARIANTS = {"core": {scheme + ("" if update == "quaternion" else f"+{update}"): [scheme, update]
                     for scheme in SCHEMES["core"] for update in ORIENTATION_UPDATES}}
THEORY = {engine: {integrator: SCHEMES[engine][VARIANTS.get(engine, {}).get(integrator, [integrator])[0]]
                   for integrator in VARIANTS.get(engine, SCHEMES[engine])} for engine in SCHEMES}
SAME_RK4 = 1e-12
"""The relative difference of core's, MuJoCo's and Pinocchio's rk4 errors in the quick run: the same method."""
NO_FIT = ("mujoco", "implicit")
NO_FIT_REASON = ("not in the asymptotic range: local slopes 3.83, 0.749 (finest first) differ by more than 0.3; finer "
                 "time steps are needed")
IK_SOLVERS = {"core": ("pseudo_inverse", "transpose", "damped_least_squares", "damped_least_squares+nullspace",
                       "damped_least_squares+restarts"), "mujoco": ("dls",),
              "pybullet": ("calculateInverseKinematics", "calculateInverseKinematics-tuned",
                           "calculateInverseKinematics-tuned-nullspace"), "pinocchio": ("clik", "clik-documented")}
IK_TIMES = (2.1e-4, 3.2e-3)
"""[s] Times per solve spanning a decade and a bit, across 10⁻³: matplotlib labels 2, 3, 4 and 6 ×10ⁿ on such an axis,
which ran into each other on iiwa-ik and ur5-ik."""


STAGES = {1: 1, 2: 2, 4: 4}
"""Force evaluations per step of a scheme of each order here: Euler 1, midpoint 2, RK4 4."""


def _representative_cases() -> pd.DataFrame:
    """Every dynamics scheme of a quick run at three time steps (summary.dynamics_cases' columns)."""
    rows = []
    for engine, integrators in THEORY.items():
        for k, (integrator, p) in enumerate(integrators.items()):
            scheme, update = VARIANTS.get(engine, {}).get(integrator, [integrator, "quaternion"])
            place = list(SCHEMES[engine]).index(scheme)  # a scheme's variants: close to its quaternion update
            scale = (1.0 if scheme == "rk4" else 10.0 ** (place % 4) * (1 + place / 10)) * ORIENTATION_UPDATES[update]
            scale *= 1 + SAME_RK4 * (engine == "mujoco")
            for dt in DTS:
                cost = {"core": 1e-4, "pinocchio": 3e-5}.get(engine, 2e-6) * (1 + k / 10) / dt
                rows.append({"scene": "s", "engine": engine, "integrator": integrator, "dt": dt, "status": "ok",
                             "error": scale * dt ** p, "time_per_step": cost * dt, "cost": cost,
                             "evaluations": STAGES[p] / dt})
    return pd.DataFrame(rows)


def _observed() -> dict:
    return {(engine, integrator): p + 0.01 for engine, integrators in THEORY.items()
            for integrator, p in integrators.items() if (engine, integrator) != NO_FIT}


def _series(quantities: dict[str, float]) -> pd.DataFrame:
    """A series per dynamics scheme and quantity over 2 s at the coarsest dt (values: scale × (1 + t))."""
    times = [0.1 * i for i in range(21)]
    return pd.DataFrame([{"scene": "s", "engine": engine, "integrator": integrator, "dt": DTS[-1], "quantity": quantity,
                          "unit": "", "x": t, "value": scale * (k + 1) * (1 + t)}
                         for engine, integrators in THEORY.items() for k, integrator in enumerate(integrators)
                         for quantity, scale in quantities.items() for t in times])


def _solvers() -> pd.DataFrame:
    """Every IK solver of a quick run, times per solve spread over :data:`IK_TIMES` (summary.ik_solvers' columns)."""
    pairs = [(engine, solver) for engine, solvers in IK_SOLVERS.items() for solver in solvers]
    times = np.geomspace(*IK_TIMES, len(pairs))
    return pd.DataFrame({"engine": [e for e, _ in pairs], "integrator": [s for _, s in pairs],
                         SOLVE_RATE: np.linspace(0.0, 1.0, len(pairs)), TIME_PER_SOLVE: times,
                         SOLVE_RATE_OWN_STOP: np.nan, OWN_STOP_POSITION_TOLERANCE: np.nan})


def _ik_series() -> pd.DataFrame:
    """Residual and iteration distributions per solver, and the FK agreement of every two engines."""
    fractions = np.linspace(0.0, 1.0, 11)
    rows = [{"scene": "s", "engine": engine, "integrator": solver, "dt": np.nan, "quantity": quantity, "unit": "",
             "x": x, "value": scale * (1 + 10 * x)}
            for engine, solvers in IK_SOLVERS.items() for solver in solvers
            for quantity, scale in (("position_residual", 1e-9), ("iterations", 3.0)) for x in fractions]
    rows += [{"scene": "s", "engine": a, "integrator": b, "dt": np.nan, "quantity": "fk_disagreement_max", "unit": "m",
              "x": 0.0, "value": 1e-16 if "pybullet" not in (a, b) else 1e-7} for a in IK_SOLVERS for b in IK_SOLVERS
             if a != b]
    return pd.DataFrame(rows)


def _sweep_cases() -> pd.DataFrame:
    """Every dynamics scheme against a swept key at two other values (sweep_sections.sweep_cases' columns)."""
    return pd.DataFrame([{"engine": engine, "integrator": integrator, "status": "ok", "value": (k + 1) * x * 1e-6,
                          "sweep:speed": x, "sweep:mass": m, "dt": DTS[0]}
                         for engine, integrators in THEORY.items() for k, integrator in enumerate(integrators)
                         for x in (1.0, 3.0, 10.0) for m in (1.0, 2.0)])


def _every_figure() -> dict:
    """Every figure function of reports/figures.py on the representative inputs, by name."""
    cases = _representative_cases()
    across = cases.rename(columns={"error": "value"}).assign(best=lambda f: f["value"] / 10)
    return {
        "work precision": figures.work_precision_figure("s", cases, ORIENTATION_ERROR_MAX, REFERENCE, VARIANTS),
        "convergence": figures.convergence_figure("s", cases, ORIENTATION_ERROR_MAX, REFERENCE, _observed(), THEORY,
                                                  {NO_FIT: NO_FIT_REASON}),
        "drift": figures.drift_figure("s", _series({"energy_change": 1e-9, "angular_momentum_change": 1e-12,
                                                    "position_error": 1e-6, "orientation_error": 1e-4}), REFERENCE),
        "contact height": figures.contact_height_figure("s", _series({"support_height": 1e-4}), REFERENCE),
        "IK solve rate": figures.ik_rate_figure("s", _solvers(), "core:fk (targets); cross-evaluated by core, mujoco, "
                                                "pybullet, pinocchio"),
        "IK distributions": figures.ik_distribution_figure("s", _ik_series(), 1e-6),
        "FK matrix": figures.fk_matrix_figure("s", _ik_series()),
        "sweep work precision": figures.sweep_work_precision_figure("b", across, "orientation error max [rad]",
                                                                    REFERENCE, 100, VARIANTS),
        "sweep": figures.sweep_figure("b", _sweep_cases(), "sweep:speed", ["sweep:mass", "dt"],
                                      "orientation error max [rad]", REFERENCE),
        "sweep parameter": figures.sweep_parameter_figure("b", [("position error max [m]", _sweep_cases()),
                                                                ("orientation error max [rad]", _sweep_cases())],
                                                          "sweep:speed", REFERENCE),
    }


@pytest.mark.slow  # ~6 s of CPU: every figure drawn
def test_no_text_of_any_figure_overlaps_another():
    """Tick labels, axis labels, titles, texts in the axes and legend entries of every figure, drawn with Agg on
    a quick run's schemes, each readable: no two boxes meet by more than OVERLAP_PIXELS, none leaves the figure."""
    drawn = _every_figure()
    try:
        assert all(fig is not None for fig in drawn.values()), [name for name, fig in drawn.items() if fig is None]
        problems = {name: found for name, fig in drawn.items() if (found := overlaps(fig))}
        assert problems == {}
    finally:
        figures.plt.close("all")


def test_the_overlap_check_sees_tick_labels_printed_over_each_other():
    """The check itself, on the IK times' axis 3 in long: matplotlib's choice of labels (2, 3, 4 and 6 ×10ⁿ) runs
    together; the layout's formatter labels fewer."""
    fig, ax = figures.plt.subplots(figsize=(4.0, 2.5))
    ax.plot(IK_TIMES, [0, 1])
    ax.set_xscale("log")
    finish(fig)
    try:
        assert overlaps(fig) == []
        ax.xaxis.set_minor_formatter(LogFormatterSciNotation(labelOnlyBase=False))   # matplotlib's own
        assert any("times10" in problem for problem in overlaps(fig))
    finally:
        figures.plt.close(fig)


def test_the_variants_of_a_scheme_share_a_colour_with_a_marker_each():
    fig = figures.work_precision_figure("s", _representative_cases(), ORIENTATION_ERROR_MAX, REFERENCE, VARIANTS)
    ax = fig.axes[0]
    drawn = {line.get_label().removeprefix("_"): line for line in ax.get_lines() if len(line.get_xdata())}
    updates = [drawn[f"core {name}"] for name in ("rk4", "rk4+matrix", "rk4+expmap")]
    assert len({line.get_color() for line in updates}) == 1
    assert len({line.get_marker() for line in updates}) == 3
    assert drawn["mujoco rk4"].get_color() != updates[0].get_color()
    entries = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "core rk4 (quaternion, matrix, expmap)" in entries and "marker: variant matrix" in entries
    assert not any(entry.startswith("core rk4+") for entry in entries)
    assert [t.get_text() for t in ax.texts] == [f"error budget {power_of_ten(b)}" for b in ERROR_BUDGETS]
    figures.plt.close(fig)


def test_work_precision_puts_the_same_points_against_force_evaluations_where_counted():
    """Issue #26: beside wall time, the hardware-neutral cost: a second panel of force evaluations per simulated
    second, the same errors on x; a run that counted none draws the wall-time panel alone."""
    cases = _representative_cases()
    fig = figures.work_precision_figure("s", cases, ORIENTATION_ERROR_MAX, REFERENCE, VARIANTS)
    wall, work = fig.axes
    assert "wall time" in wall.get_ylabel() and "force evaluations" in work.get_ylabel()
    rk4 = next(line for line in work.get_lines() if line.get_label().removeprefix("_") == "mujoco rk4")
    assert list(rk4.get_ydata()) == [4 / dt for dt in sorted(DTS)]   # 4 stages a step, per simulated second
    figures.plt.close(fig)
    fig = figures.work_precision_figure("s", cases.drop(columns=["evaluations"]), ORIENTATION_ERROR_MAX, REFERENCE)
    assert len(fig.axes) == 1
    figures.plt.close(fig)


def test_convergence_draws_agreeing_schemes_as_one_line_names_failed_fits_and_shows_the_slopes():
    fig = figures.convergence_figure("s", _representative_cases(), ORIENTATION_ERROR_MAX, REFERENCE, _observed(),
                                     THEORY, {NO_FIT: NO_FIT_REASON})
    (ax,) = fig.axes
    entries = [t.get_text().replace("\n  ", " ") for t in ax.get_legend().get_texts()]
    assert "core rk4 = mujoco rk4 = pinocchio rk4: observed 4.01, theory 4" in entries
    assert "mujoco implicit: no fit: not in the asymptotic range, theory 1" in entries
    assert sorted(t.get_text() for t in ax.texts) == ["slope 1", "slope 2", "slope 4"]
    figures.plt.close(fig)
    apart = _representative_cases()
    apart.loc[apart["engine"] == "mujoco", "error"] *= 1 + 10 * figures.AGREE_RELATIVE
    fig = figures.convergence_figure("s", apart, ORIENTATION_ERROR_MAX, REFERENCE, _observed(), THEORY)
    entries = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert "core rk4 = pinocchio rk4: observed 4.01, theory 4" in entries
    assert "mujoco implicit: no fit: no order in the run (see the order table), theory 1" in [
        e.replace("\n  ", " ") for e in entries]
    figures.plt.close(fig)


def test_the_sweeps_work_precision_figure_draws_the_worst_variant_and_a_band_to_the_best():
    fig = figures.sweep_work_precision_figure("b", _across(), "position error max [m]", REFERENCE, 100)
    (ax,) = fig.axes
    line = ax.get_lines()[0]
    assert list(line.get_xdata()) == [1e-6, 1e-5] and list(line.get_ydata()) == [1e-3, 5e-4]
    assert "over 100 variants" in ax.get_title(loc="left")
    figures.plt.close(fig)
    assert figures.sweep_work_precision_figure("b", _across(("diverged", "n/a")), "e", REFERENCE, 2) is None


def test_the_sweep_parameter_figure_draws_the_median_over_the_other_keys_and_their_range():
    """Issue #29: per engine x integrator, at each value of the key, the median over the variants sharing it and a
    band from their least to their largest; a panel per metric given values, none drawn without any."""
    cases = pd.DataFrame({"engine": "core", "integrator": "rk4", "value": [1.0, 3.0, 2.0, 8.0, 4.0, 6.0],
                          "sweep:x": [0.1, 0.1, 0.2, 0.2, 0.2, 0.2]})
    fig = figures.sweep_parameter_figure("b", [("error [m]", cases), ("other", cases.iloc[:0])], "sweep:x", REFERENCE)
    (ax,) = fig.axes
    line = ax.get_lines()[0]
    assert list(line.get_xdata()) == [0.1, 0.2] and list(line.get_ydata()) == [2.0, 5.0]
    band = ax.collections[0].get_paths()[0].vertices[:, 1]
    assert band.min() == 1.0 and band.max() == 8.0 and ax.get_xlabel() == "x"
    figures.plt.close(fig)
    assert figures.sweep_parameter_figure("b", [("error [m]", cases.iloc[:0])], "sweep:x", REFERENCE) is None


def test_the_sweep_figure_draws_a_panel_per_combination_it_is_given():
    cases = pd.DataFrame({"engine": "core", "integrator": "rk4", "status": "ok", "value": [1.0, 2.0, 3.0, 4.0],
                          "x": [0.1, 0.2, 0.1, 0.2], "y": [1.0, 1.0, 2.0, 2.0]})
    fig = figures.sweep_figure("b", cases, "x", ["y"], "error [m]", REFERENCE)
    assert len(fig.axes) == 2 and fig.get_layout_engine() is None
    figures.plt.close(fig)
    assert figures.sweep_figure("b", cases.assign(status="n/a"), "x", ["y"], "error [m]", REFERENCE) is None


ORPHAN_SECONDS = 10.0
"""How long the figure processes of a killed report may take to go: the kernel signals them at once."""

KILLED_WRITER = """
import os, signal, sys
from pathlib import Path
import matplotlib.pyplot as plt
from simparity.reports.figure_writer import FigureWriter
with FigureWriter(2, in_process_max=0) as writer:  # the pool at once
    writer.submit(plt.figure(), Path(sys.argv[1]), "first").result()  # the pool's processes are up
    print(" ".join(str(pid) for pid in writer._pool._processes), flush=True)
    os.kill(os.getpid(), signal.SIGKILL)
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status", encoding="utf-8") as f:
            return not any(line.startswith("State:") and "Z" in line for line in f)
    except FileNotFoundError:
        return False


@pytest.mark.slow
def test_the_figure_processes_of_a_killed_report_do_not_outlive_it(tmp_path):
    """SIGKILL while figures are written (a CI job cancelled): the pool's processes end with their parent."""
    done = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(tmp_path)], capture_output=True, text=True,
                          timeout=120)
    pids = [int(p) for p in done.stdout.split()]
    assert done.returncode == -9 and len(pids) >= 1, done.stderr
    deadline = time.monotonic() + ORPHAN_SECONDS
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in pids)
    assert os.path.exists(tmp_path / "first.svg")


def _line_figure(slope: float):
    fig, ax = figures.plt.subplots()
    ax.plot([0.0, 1.0], [0.0, slope])
    return fig


@pytest.mark.slow  # starts a pool of two figure processes (~3 CPU-s)
def test_a_few_figures_are_written_here_and_more_on_the_pool_the_same_svg_either_way(tmp_path):
    """Up to ``in_process_max`` figures wait and are written in this process (no pool started: a small report does not
    pay two interpreters' start-up); the next one starts the pool, which writes the waiting ones too. The SVG text
    and the files are the same whichever process wrote them."""
    with figure_writer.FigureWriter(2, in_process_max=2) as small:
        few = [small.submit(_line_figure(k), tmp_path / "few", f"f{k}") for k in (1, 2)]
        assert small._pool is None
    with figure_writer.FigureWriter(2, in_process_max=2) as large:
        many = [large.submit(_line_figure(k), tmp_path / "many", f"f{k}") for k in (1, 2, 3)]
        assert large._pool is not None
    for k, (here, pooled) in enumerate(zip(few, many), start=1):
        assert here.result() == pooled.result() == (tmp_path / "many" / f"f{k}.svg").read_text(encoding="utf-8")
        assert (tmp_path / "few" / f"f{k}.png").read_bytes() == (tmp_path / "many" / f"f{k}.png").read_bytes()
    assert (tmp_path / "many" / "f3.svg").is_file()


@pytest.mark.slow  # starts a pool of two figure processes (~2 CPU-s)
def test_a_figure_process_imports_matplotlib_and_not_the_drawing_nor_pandas(tmp_path):
    """A pool's process is a fresh interpreter: what it imports before its first figure is paid per process. It writes
    pickled figures, so it needs matplotlib and the writer, not pandas nor the drawing code (~0.5 CPU-s each)."""
    imported = "sorted({m for m in __import__('sys').modules if m.split('.')[0] in ('pandas', 'simparity', 'matplotlib')})"
    with figure_writer.FigureWriter(2, in_process_max=0) as writer:
        writer.submit(_line_figure(1.0), tmp_path, "f")  # starts the pool
        modules = writer._pool.submit(eval, imported).result()  # eval: a builtin, so the process imports nothing more
    assert "matplotlib.pyplot" in modules and "simparity.reports.figure_writer" in modules
    assert not [m for m in modules if m.startswith("pandas") or m == "simparity.reports.figures"], modules


def test_a_failed_report_writes_none_of_its_waiting_figures(tmp_path):
    with pytest.raises(RuntimeError), figure_writer.FigureWriter(2) as writer:
        writer.submit(_line_figure(1.0), tmp_path, "unwritten")
        raise RuntimeError("the report failed")
    assert not list(tmp_path.iterdir())
