"""The report's sweep sections (reports/sweep_sections.py): per swept scene, every engine x integrator over all its
variants, the headline metric against the swept values, and sections for its first, last and hardest variants
only, read from a stored run; a run without a sweep has no such section."""

import math

import numpy as np
import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes.loading.scene_file import parse_scenes
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.reports.store import RunWriter
from simparity.core.model.files import tomllib
from simparity.core.model.results import REPORT_FILE, SERIES_COLUMNS, ResultRow
from simparity.reports.blocks import Details, Figure, Heading, Paragraph, Table
from simparity.reports.content import build
from simparity.reports.blocks import number
from simparity.reports.markdown import LINE_CHARS, MAX_LINES, to_markdown
from simparity.reports.sweep_compact import COMPACT_SWEEP_VARIANTS, QUANTILE_LABELS, WORST_VARIANTS, worst_variants
from simparity.reports.store import read_run
from simparity.reports.sweep_sections import SWEEP_PANELS, TABLE_ROWS, _figure_cases, sections, sweep_cases
from simparity.reports.sweep_summary import sweeps
from tests.comparisons.scenes.test_loader import VALID_DYNAMICS, VALID_KINEMATICS
from tests.reports.undrawn import undrawn_figures

GRAVITY_SWEEP = VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1.0, 2.0]\n"world.gravity_world[2]" = [-9.81, -1.62]\n'
"""Four variants, mass x gravity, each at one time step (0.01 s)."""
LADDER_SWEEP = VALID_DYNAMICS.replace("dt = [0.01]", "dt = [0.01, 0.02]") + '[sweep]\n"body[ball].mass" = [1.0, 2.0]\n'
"""Two variants, each at two time steps: dt becomes an axis of the table."""
MASS_SWEEP = VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1.0, 2.0, 3.0, 4.0, 5.0]\n'
"""Five variants of one key at one time step."""
IK_SWEEP = (VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"').replace("[chain]", "[targets]\nseed = 0\n[chain]")
            + '[sweep]\n"targets.seed" = [4, 7]\n')
NO_SERIES = pd.DataFrame(columns=list(SERIES_COLUMNS))


def _rows(scene, engine, integrator, value, status="ok", dt=0.01, metric="position_error_max"):
    return ResultRow(scene, engine, integrator, dt, metric, value if status == "ok" else math.nan, "m",
                     "analytic:exact", status, "" if status == "ok" else "why")


def _case(scene, engine, integrator, error, seconds_per_step, status="ok", dt=0.01):
    """The headline error and the time per step of one case."""
    return [_rows(scene, engine, integrator, error, status, dt),
            _rows(scene, engine, integrator, seconds_per_step, status, dt, metric="time_per_step")]


def _stored(tmp_path, scenes, rows):
    writer = RunWriter(tmp_path, describe_run([], "simparity run", scenes))
    writer.append(rows)
    return read_run(tmp_path)


def _recorded(drawn):
    def figure(fig, name, caption):
        drawn.append((fig, name))
        return [Figure(name, caption)] if fig is not None else []
    return figure


def _report(tmp_path, table, info) -> str:
    """The report.md of a stored run, its figures made but not saved (no test here reads a figure's file)."""
    with undrawn_figures():
        blocks, _ = build(table, info, NO_SERIES, None, tmp_path)
    return to_markdown(blocks)


def test_headline_against_two_swept_keys_per_engine_and_integrator(tmp_path):
    scenes = parse_scenes(tomllib.loads(GRAVITY_SWEEP))
    names = [s.name for s in scenes]   # mass 1 (g -9.81, -1.62), mass 2 (g -9.81, -1.62)
    values = {"core": [1e-6, 2e-6, 3e-6, None], "mujoco": [0.5, 0.25, 0.125, 0.0625]}
    rows = [_rows(name, "analytic", "exact", 0.0) for name in names]                        # ground truth: left out
    rows += [_rows(name, "pinocchio", "euler", math.nan, "n/a") for name in names]          # n/a throughout: left out
    rows += [_rows(name, "core", "rk4", v, "ok" if v else "diverged") for name, v in zip(names, values["core"])]
    rows += [_rows(name, "mujoco", "euler", v) for name, v in zip(names, values["mujoco"])]
    rows += [_rows(name, "core", "rk4", 1.0, metric="time_per_step") for name in names]    # another metric
    table, info = _stored(tmp_path, scenes, rows[::-1])                                     # stored in any order
    drawn = []
    blocks = sections(sweeps(table, info), _recorded(drawn), {})
    assert blocks[0] == Heading(2, "Sweeps") and blocks[2] == Heading(3, "Sweep of drop")
    assert blocks[3].text.startswith("4 variants of `<scene>`: `body[ball].mass` 1, 2; `world.gravity_world[2]` "
                                     "-9.81, -1.62. Position error max [m] against `analytic:exact`. Shown with a "
                                     "section of their own: [variant 1](#drop_mass-10_gravity_world2--981-dynamics) "
                                     "(the first)")
    grid = next(b for b in blocks if isinstance(b, Table) and "world.gravity_world[2] = -9.81" in b.head)
    assert grid.head == ("engine", "integrator", "body[ball].mass", "world.gravity_world[2] = -9.81",
                         "world.gravity_world[2] = -1.62")
    assert set(grid.rows) == {("mujoco", "euler", "1", "0.5", "0.25"), ("mujoco", "euler", "2", "0.125", "0.0625"),
                              ("core", "rk4", "1", "1e-06", "2e-06"), ("core", "rk4", "2", "3e-06", "diverged")}
    assert [name for _, name in drawn] == ["drop-sweep-work-precision", "drop-sweep"]
    assert len(drawn[1][0].axes) == 2   # a panel per mass


@pytest.mark.slow
def test_a_scheme_is_judged_by_its_worst_variant(tmp_path):
    """The summary's row and the table over the variants take each scheme at its worst variant (and median cost);
    a scheme that diverged in one variant is not ranked, however cheap."""
    scenes = parse_scenes(tomllib.loads(GRAVITY_SWEEP))
    names = [s.name for s in scenes]
    rows = [r for name, error, step in zip(names, (1e-6, 4e-6, 2e-6, 3e-6), (1e-4, 3e-4, 2e-4, 9e-3))
            for r in _case(name, "core", "rk4", error, step)]
    rows += [r for k, name in enumerate(names)
             for r in _case(name, "mujoco", "rk4", 1e-9, 1e-7, "diverged" if k == 2 else "ok")]
    table, info = _stored(tmp_path, scenes, rows)
    (sweep,) = sweeps(table, info)
    across = next(b for b in sections([sweep], _recorded([]), {"core": {"rk4": 4}}) if isinstance(b, Table))
    assert across.head[:5] == ("engine", "integrator", "best dt [s]", "worst position error max [m]",
                               "worst variant (`body[ball].mass`, `world.gravity_world[2]`)")
    assert across.rows == (("core", "rk4", "0.01", "4e-06", "1, -1.62", "2.5e-06", "0.025", "— (4)", "ok 4"),
                           ("mujoco", "rk4", "—", "—", "—", "—", "—", "—", "ok 3, diverged 1"))
    report = _report(tmp_path, table, info)
    row = next(line for line in report.splitlines() if line.startswith("| [sweep of drop](#sweep-of-drop)"))
    cells = [cell.strip() for cell in row.split("|")[1:-1]]
    assert cells[0] == "[sweep of drop](#sweep-of-drop) (4 variants)"
    # within 1e-3, not 1e-6; ranked by wall time (0.025 s per simulated second): these rows count no force evaluations
    assert cells[2] == "core rk4 @ 0.01 (25 ms)" and cells[3] == "none"


@pytest.mark.slow
def test_only_the_first_last_and_hardest_variants_have_sections(tmp_path):
    scenes = parse_scenes(tomllib.loads(MASS_SWEEP))
    names = [s.name for s in scenes]
    errors = (1e-6, 2e-6, 9e-6, 3e-6, 1e-6)   # the third variant's errors are the largest
    rows = [r for name, error in zip(names, errors) for engine in ("core", "mujoco")
            for r in _case(name, engine, "rk4", error, 1e-4)]
    table, info = _stored(tmp_path, scenes, rows)
    report = _report(tmp_path, table, info)
    headings = [line for line in report.splitlines() if line.startswith("## drop_")]
    assert headings == [f"## {names[k]} (dynamics)" for k in (0, 2, 4)]
    assert f"(#{names[2].replace('.', '')}-dynamics) (the hardest: its errors rank worst" in report
    assert "Variant 3 of 5 of the [sweep of drop](#sweep-of-drop) (the hardest: its errors rank worst" in report
    assert "Variant 5 of 5 of the [sweep of drop](#sweep-of-drop) (the last):" in report
    summary = report.split("### Which integrator", 1)[1].split("###", 1)[0]
    assert names[1] not in summary and "(5 variants)" in summary   # one row for the sweep


def test_dt_is_an_axis_when_the_variants_run_a_ladder(tmp_path):
    scenes = parse_scenes(tomllib.loads(LADDER_SWEEP))
    rows = [_rows(s.name, "core", "rk4", 1e-4 * (k + 1) * dt / 0.01, dt=dt) for k, s in enumerate(scenes)
            for dt in (0.01, 0.02)]
    table, info = _stored(tmp_path, scenes, rows)
    grid = next(b for b in sections(sweeps(table, info), _recorded([]), {})
                if isinstance(b, Table) and "dt [s]" in b.head)
    assert grid.head == ("engine", "integrator", "dt [s]", "body[ball].mass = 1", "body[ball].mass = 2")
    assert grid.rows == (("core", "rk4", "0.01", "0.0001", "0.0002"), ("core", "rk4", "0.02", "0.0002", "0.0004"))


def test_an_ik_sweep_shows_the_solve_rate(tmp_path):
    scenes = parse_scenes(tomllib.loads(IK_SWEEP))
    rows = [_rows(s.name, "core", "pseudo_inverse", rate, dt=math.nan, metric="solve_rate")
            for s, rate in zip(scenes, (0.98, 1.0))]
    table, info = _stored(tmp_path, scenes, rows)
    blocks = sections(sweeps(table, info), _recorded([]), {})
    assert "Solve rate against `analytic:exact`" in next(b.text for b in blocks[3:] if isinstance(b, Paragraph))
    across, grid = [b for b in blocks if isinstance(b, Table)]
    assert across.rows == (("core", "pseudo_inverse", "0.98", "4", "0.99", "—", "ok 2"),)   # worst: seed 4
    assert grid.rows == (("core", "pseudo_inverse", "0.98", "1"),)


def test_a_run_without_a_sweep_has_no_sweep_section(tmp_path):
    table, info = _stored(tmp_path, [], [_rows("s", "core", "rk4", 1e-6)])
    assert sweeps(table, info) == [] and sections([], _recorded([]), {}) == []
    assert "Sweep" not in _report(tmp_path, table, info)


def test_many_panels_keep_the_finest_dt_then_evenly_spaced_ones():
    """10 values of the other key at two time steps: the figure keeps dt 0.01 and 6 of the 10 values, both ends."""
    cases = pd.DataFrame([{"engine": "core", "integrator": "rk4", "status": "ok", "value": 1.0, "x": x, "y": y,
                           "dt": dt} for y in range(10) for x in (0.1, 0.2) for dt in (0.01, 0.02)])
    drawn, panels, note = _figure_cases(cases, ["y", "dt"])
    assert panels == ["y"] and set(drawn["dt"]) == {0.01}
    kept = list(dict.fromkeys(drawn["y"]))
    assert len(kept) == SWEEP_PANELS and kept[0] == 0 and kept[-1] == 9
    assert note == (" At the finest time step, dt = 0.01 s. 6 of the 10 panels, evenly spaced with both ends; the "
                    "table has every one.")
    few = cases[cases["y"] < 3]
    assert _figure_cases(few, ["y", "dt"])[1:] == (["y", "dt"], "")   # 6 panels: all kept


@pytest.mark.slow
def test_a_large_table_is_folded_into_the_html(tmp_path):
    scenes = parse_scenes(tomllib.loads(MASS_SWEEP))
    rows = [_rows(s.name, "core", f"scheme{k}", 1e-6) for s in scenes for k in range(TABLE_ROWS + 1)]
    table, info = _stored(tmp_path, scenes, rows)
    blocks = sections(sweeps(table, info), _recorded([]), {})
    folded = [b for b in blocks if isinstance(b, Details)]
    assert [d.markdown for d in folded] == [False, False]   # the table of every value, every metric of every variant
    assert folded[0].summary == (f"drop: position error max [m] of every engine × integrator × variant "
                                 f"({TABLE_ROWS + 1} rows)")
    assert "scheme0 | 1e-06" not in to_markdown(blocks)


def test_variants_share_a_line_in_findings_and_cases_without_a_result(tmp_path):
    hard = GRAVITY_SWEEP.replace('kind = "dynamics"', 'kind = "dynamics"\nsuites = ["hard"]')
    scenes = parse_scenes(tomllib.loads(hard))
    names = [s.name for s in scenes]
    rows = [r for name in names for r in _case(name, "core", "rk4", 1e-6, 1e-4)]
    rows += [_rows(name, "pinocchio", "euler", math.nan, "n/a") for name in names]
    rows += [_rows(name, "mujoco", "euler", math.nan, "diverged") for name in names[:2]]
    table, info = _stored(tmp_path, scenes, rows)
    report = _report(tmp_path, table, info)
    assert "| n/a (run) | sweep of drop | pinocchio: euler in 4 of 4 variants | 4 | 0.01 |" in report
    assert "| diverged | sweep of drop | mujoco: euler in 2 of 4 variants | 2 | 0.01 | why |" in report
    assert "- **sweep of drop**: ok 4, n/a 4, diverged 2; diverged: mujoco euler" in report   # hard cases: one line
    assert names[1] not in report.split("## Sweeps", 1)[0]


def test_sweep_cases_leave_out_ground_truths_and_the_reference_scheme(tmp_path):
    scenes = parse_scenes(tomllib.loads(LADDER_SWEEP))
    rows = [ResultRow(s.name, engine, integrator, 0.01, "position_error_max", 1.0, "m", "core:backup", "ok")
            for s in scenes for engine, integrator in (("core", "backup"), ("tight", "dop853"), ("core", "act_after"))]
    table, _ = _stored(tmp_path, scenes, rows)
    cases = sweep_cases(table, ["sweep:body[ball].mass"], "position_error_max", "dynamics")
    assert set(cases["integrator"]) == {"act_after"}


END_TO_END_FIGURES = ("drop-sweep", "drop-sweep-work-precision", "drop_mass-1.0-work-precision")
"""The figures test_a_sweep_file_runs_end_to_end looks for: its report saves these alone (the other five it makes,
each variant's convergence and drift and the last one's work-precision, are made by their figure functions all the same;
saving them, SVG and PNG, is what reports/figures.py's tests and test_report.py's run look at)."""


@pytest.mark.slow
def test_a_sweep_file_runs_end_to_end(tmp_path):
    """`simparity run FILE` runs every variant; results.csv has the sweep columns and the report the section."""
    path = tmp_path / "drop.toml"
    path.write_text(LADDER_SWEEP.replace("dt = [0.01, 0.02]", 'dt = [0.01, 0.02]\nintegrators = ["rk4", "exact"]'),
                    encoding="utf-8")
    out = tmp_path / "run"
    with undrawn_figures(frozenset(END_TO_END_FIGURES)):
        assert main(["run", str(path), "--engines", "core,analytic", "--repeats", "0", "--jobs", "1", "--out",
                     str(out)]) == 0
    table, info = read_run(out)
    assert list(dict.fromkeys(table["scene"])) == ["drop_mass-1.0", "drop_mass-2.0"]
    assert list(table.columns[-2:]) == ["sweep", "sweep:body[ball].mass"]
    assert set(table.loc[table["scene"] == "drop_mass-2.0", "sweep:body[ball].mass"]) == {2.0}
    report = (out / REPORT_FILE).read_text(encoding="utf-8")
    section = report.split("### Sweep of drop", 1)[1].split("\n## ", 1)[0]
    assert "| engine | integrator | dt [s] | body[ball].mass = 1 | body[ball].mass = 2 |" in section
    assert "| core | rk4 | 0.01 |" in section and "figures/drop-sweep.svg" in section
    assert "figures/drop-sweep-work-precision.svg" in section
    assert "Variant 2 of 2 of the [sweep of drop](#sweep-of-drop) (the last" in report
    for name in END_TO_END_FIGURES:
        assert (out / "figures" / f"{name}.svg").is_file()


MANY = 40
"""Variants of the compact sweep below: more than COMPACT_SWEEP_VARIANTS."""
MANY_SWEEP = (VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [' + ", ".join(f"{1.0 + k:.1f}" for k in range(MANY // 4))
              + ']\n"world.gravity_world[2]" = [-9.81, -5.0, -3.0, -1.62]\n')


def _many(tmp_path):
    """MANY variants, core rk4 with error k * 1e-9 in variant k (0-based; variant 0 is ok with error 0: rounding), and
    MuJoCo euler with 1e-3 except in the third variant, which diverged; a time per step beside."""
    scenes = parse_scenes(tomllib.loads(MANY_SWEEP))
    rows = []
    for k, scene in enumerate(scenes):
        rows += _case(scene.name, "core", "rk4", k * 1e-9, 1e-6)
        rows += _case(scene.name, "mujoco", "euler", 1e-3, 2e-6, "diverged" if k == 2 else "ok")
    return scenes, *_stored(tmp_path, scenes, rows)


def test_past_the_compact_limit_a_sweep_shows_its_distribution_not_a_row_per_variant(tmp_path):
    """Issue #29: a sweep of more than COMPACT_SWEEP_VARIANTS variants has, after its table over the variants, the
    quantiles of its headline metrics per engine x integrator, its worst variants and a figure per swept key; no
    grid of every variant and no table of every metric of every variant."""
    scenes, table, info = _many(tmp_path)
    assert MANY > COMPACT_SWEEP_VARIANTS
    drawn = []
    blocks = sections(sweeps(table, info), _recorded(drawn), {})
    tables_ = [b for b in blocks if isinstance(b, Table)]
    assert not any(any(" = " in h for h in t.head) for t in tables_)          # no grid of every value
    assert "`body[ball].mass` 10 values from 1 to 10; `world.gravity_world[2]` 4 values from -9.81 to -1.62" in (
        blocks[3].text)
    quantile = next(t for t in tables_ if t.head[-6:] == QUANTILE_LABELS + ("variants",))
    rows = {(r[0], r[1], r[2]): r[3:] for r in quantile.rows}
    core = rows[("position error max [m]", "core", "rk4")]
    assert core == ("0", number(np.quantile(np.arange(MANY) * 1e-9, 0.05)), number(19.5e-9), number(
        np.quantile(np.arange(MANY) * 1e-9, 0.95)), number(39e-9), str(MANY))
    assert rows[("position error max [m]", "mujoco", "euler")][-1] == str(MANY - 1)  # the diverged variant left out
    worst = next(t for t in tables_ if t.head[0] == "variant")
    assert len(worst.rows) == WORST_VARIANTS and worst.rows[0][:3] == ("40", "10", "-1.62")
    folded = [b for b in blocks if isinstance(b, Details)]
    assert [d.summary for d in folded] == [f"drop: every metric's quantiles over the {MANY} variants, at every time step"]
    every = folded[0].blocks[0]
    assert {r[0] for r in every.rows} == {"position error max [m]", "time per step [s]"}
    names = [name for _, name in drawn]
    assert names == ["drop-sweep-work-precision", "drop-sweep-body_ball_.mass", "drop-sweep-world.gravity_world_2_"]
    assert all(fig is not None for fig, _ in drawn)


@pytest.mark.slow  # ~1.4 s of CPU: the report of 40 variants
def test_a_compact_sweep_keeps_the_report_within_its_lines(tmp_path):
    _, table, info = _many(tmp_path)
    report = _report(tmp_path, table, info)
    lines = report.splitlines()
    assert len(lines) <= MAX_LINES and max(map(len, lines)) <= LINE_CHARS
    assert "| metric | engine | integrator | min | 5 % | median | 95 % | max | variants |" in report


def test_the_worst_variants_rank_by_the_sweeps_metric_within_each_case():
    """A variant worst in every case ranks 1; the worst value it had and where are named."""
    cases = pd.DataFrame({"scene": ["a", "b", "c"] * 2, "engine": ["core"] * 3 + ["mujoco"] * 3,
                          "integrator": ["rk4"] * 3 + ["euler"] * 3, "dt": [0.01] * 6, "status": ["ok"] * 6,
                          "value": [1.0, 3.0, 2.0, 10.0, 30.0, 20.0], "cost": [1.0] * 6})

    class Stub:
        kind, lower_is_better, variants = "dynamics", True, ["a", "b", "c"]

    Stub.cases = cases
    worst = worst_variants(Stub())
    assert list(worst["scene"]) == ["b", "c", "a"] and list(worst["rank"]) == [1.0, pytest.approx(2 / 3),
                                                                              pytest.approx(1 / 3)]
    assert worst.iloc[0]["value"] == 30.0 and worst.iloc[0]["where"] == "mujoco euler, dt = 0.01 s"


def test_a_compact_ik_sweep_ranks_its_worst_variants_by_the_lowest_solve_rate(tmp_path):
    """A higher solve rate is better: the worst variants are those that solve least, quantiles per solver."""
    text = IK_SWEEP.replace('"targets.seed" = [4, 7]', '"targets.seed" = {start = 0, stop = 29, num = 30}')
    scenes = parse_scenes(tomllib.loads(text))
    rates = [1.0 - (k % 7) / 100 for k in range(len(scenes))]
    rows = [_rows(s.name, "core", "pseudo_inverse", rate, dt=math.nan, metric="solve_rate")
            for s, rate in zip(scenes, rates)]
    table, info = _stored(tmp_path, scenes, rows)
    drawn = []
    blocks = sections(sweeps(table, info), _recorded(drawn), {})
    tables_ = [b for b in blocks if isinstance(b, Table)]
    quantile = next(t for t in tables_ if t.head[0] == "metric")
    assert quantile.rows == (("solve rate", "core", "pseudo_inverse", "0.94", "0.94", "0.97", "1", "1", "30"),)
    worst = next(t for t in tables_ if t.head[0] == "variant")
    assert [r[1] for r in worst.rows] == ["6", "13", "20", "27", "5"] and worst.rows[0][2:] == ("0.95", "0.94",
                                                                                              "core pseudo_inverse")
    assert [name for _, name in drawn] == ["arm-sweep-targets.seed"]
