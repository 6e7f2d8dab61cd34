"""The report's sweep sections (reports/sweep_sections.py): per swept scene, every engine x integrator over all its
variants, the headline metric against the swept values, and sections for its first, last and hardest variants
only, read from a stored run; a run without a sweep has no such section."""

import math

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes.loader import parse_scenes
from simparity.comparisons.execute.store import RunWriter
from simparity.core.model.files import tomllib
from simparity.core.model.results import REPORT_FILE, SERIES_COLUMNS, ResultRow
from simparity.reports.blocks import Details, Figure, Heading, Paragraph, Table
from simparity.reports.content import build
from simparity.reports.markdown import to_markdown
from simparity.reports.store import read_run
from simparity.reports.sweep_sections import SWEEP_PANELS, TABLE_ROWS, _figure_cases, sections, sweep_cases
from simparity.reports.sweep_summary import sweeps
from tests.test_scene_loader import VALID_DYNAMICS, VALID_KINEMATICS

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
    writer = RunWriter(tmp_path, [], "simparity run", scenes)
    writer.append(rows)
    return read_run(tmp_path)


def _recorded(drawn):
    def figure(fig, name, caption):
        drawn.append((fig, name))
        return [Figure(name, caption)] if fig is not None else []
    return figure


def _report(tmp_path, table, info) -> str:
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
    # within 1e-3, not 1e-6; ranked by wall time: these rows count no force evaluations
    assert cells[2] == "core rk4 @ 0.01 (0.025 s/s)" and cells[3] == "none"


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


@pytest.mark.slow
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


@pytest.mark.slow
def test_a_sweep_file_runs_end_to_end(tmp_path):
    """`simparity run FILE` runs every variant; results.csv has the sweep columns and the report the section."""
    path = tmp_path / "drop.toml"
    path.write_text(LADDER_SWEEP.replace("dt = [0.01, 0.02]", 'dt = [0.01, 0.02]\nintegrators = ["rk4", "exact"]'),
                    encoding="utf-8")
    out = tmp_path / "run"
    assert main(["run", str(path), "--engines", "core,analytic", "--repeats", "0", "--jobs", "1", "--out", str(out)]) == 0
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
    for name in ("drop-sweep", "drop-sweep-work-precision", "drop_mass-1.0-work-precision"):
        assert (out / "figures" / f"{name}.svg").is_file()
