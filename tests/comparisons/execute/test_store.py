"""Stored runs: written incrementally, read back exactly, bad folders rejected clearly."""

import json
import math
import sys

import pandas as pd
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.loading.scene_file import parse_scenes
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.core.model.errors import ResultsError
from simparity.core.model.files import tomllib
from simparity.core.model.results import COLUMNS, RESULTS_FILE, ResultRow
from simparity.reports import store
from simparity.reports.store import RunWriter, read_run
from tests.helpers import builtin
from tests.comparisons.scenes.test_loader import VALID_DYNAMICS, VALID_KINEMATICS


def test_rows_round_trip_with_full_precision(tmp_path):
    """Appended rows read back with the same values (17 digits), NaN kept as NaN, metadata present."""
    core = make_engine("core")
    writer = RunWriter(tmp_path, describe_run([core], "simparity run", [builtin("lecture-projectile")]))
    value = 0.1 + 0.2
    writer.append([ResultRow("s", "core", "rk4", 1 / 30, "m", value, "m", "analytic:exact", "ok", "a, b")])
    writer.append([ResultRow("s", "core", "", math.nan, "m", math.nan, "m", "analytic:exact", "n/a", "why")])
    table, info = read_run(tmp_path)
    assert table["value"].iloc[0] == value and table["dt"].iloc[0] == 1 / 30
    assert math.isnan(table["value"].iloc[1]) and table["detail"].iloc[0] == "a, b"
    assert info.engine_versions == {"core": core.version()} and "lecture-projectile" in info.scenes
    assert info.theoretical_orders["core"]["rk4"] == 4 and "taylor2" not in info.theoretical_orders["core"]
    assert info.scenes["lecture-projectile"]["bodies"] == 1
    variants = info.integrator_variants["core"]
    assert variants["rk4+matrix"] == ["rk4", "matrix"] and variants["rk4"] == ["rk4", "quaternion"]
    assert "engine_euler" not in variants and "taylor2" not in variants   # one orientation update; a particle rule
    assert {"platform", "cpu_count", "python"} <= set(info.machine) and info.git_commit


def test_bad_run_folders_raise_results_error(tmp_path):
    """A folder without results, or with a future schema, is a ResultsError saying what is wrong."""
    with pytest.raises(ResultsError, match="missing"):
        read_run(tmp_path)
    RunWriter(tmp_path, describe_run([], "x", []))
    info = json.loads((tmp_path / "run.json").read_text())
    info["schema_version"] = 99
    (tmp_path / "run.json").write_text(json.dumps(info))
    with pytest.raises(ResultsError, match="schema_version 99"):
        read_run(tmp_path)


def _row(scene: str) -> ResultRow:
    return ResultRow(scene, "core", "rk4", 0.01, "position_error_max", 1e-3, "m", "analytic:exact", "ok")


def _swept_scenes() -> list:
    """Two dynamics variants (a float key), a scene without a sweep, two IK variants (a seed up to 2^63 - 1)."""
    dynamics = parse_scenes(tomllib.loads(VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1.0, 0.30000000000000004]\n'))
    ik = VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"').replace("[chain]", "[targets]\nseed = 0\n[chain]")
    ik = parse_scenes(tomllib.loads(ik + '[sweep]\n"targets.seed" = [3, 9223372036854775807]\n'))
    return dynamics + [builtin("lecture-projectile")] + ik


def test_a_run_of_swept_scenes_has_a_column_per_swept_key(tmp_path):
    """Issue #12: `sweep` (the base scene) and `sweep:KEY` per swept key after the fixed columns, read back exactly
    and typed (a seed stays a whole number), empty where a scene does not sweep the key; run.json has the sweep."""
    scenes = _swept_scenes()
    writer = RunWriter(tmp_path, describe_run([], "simparity run", scenes))
    writer.append([_row(s.name) for s in scenes[3:]])          # rows arrive in any order
    writer.append([_row(s.name) for s in scenes[:3]] + [_row("not-in-the-run")])
    table, info = read_run(tmp_path)
    assert list(table.columns) == list(COLUMNS) + ["sweep", "sweep:body[ball].mass", "sweep:targets.seed"]
    assert list(table["scene"]) == ["arm_seed-3", "arm_seed-9223372036854775807", "drop_mass-1.0",
                                    "drop_mass-0.30000000000000004", "lecture-projectile", "not-in-the-run"]
    assert list(table["sweep"]) == ["arm", "arm", "drop", "drop", "", ""]
    mass = table["sweep:body[ball].mass"]
    assert mass.dtype == float and list(mass[2:4]) == [1.0, 0.1 + 0.2] and mass.isna().sum() == 4
    seed = table["sweep:targets.seed"]
    assert str(seed.dtype) == "Int64" and list(seed[:2]) == [3, 2**63 - 1] and seed.isna().sum() == 4
    assert info.scenes["drop_mass-0.30000000000000004"]["sweep"] == {
        "base": "drop", "index": 1, "count": 2, "values": {"body[ball].mass": 0.1 + 0.2}}
    assert "sweep" not in info.scenes["lecture-projectile"]


def test_a_run_without_sweeps_keeps_exactly_the_fixed_columns(tmp_path):
    writer = RunWriter(tmp_path, describe_run([], "simparity run", [builtin("lecture-projectile")]))
    writer.append([_row("lecture-projectile")])
    assert (tmp_path / RESULTS_FILE).read_text(encoding="utf-8").splitlines()[0] == ",".join(COLUMNS)
    table, _ = read_run(tmp_path)
    assert tuple(table.columns) == COLUMNS


def test_a_damaged_sweep_column_is_a_results_error(tmp_path):
    writer = RunWriter(tmp_path, describe_run([], "simparity run", _swept_scenes()[:2]))
    writer.append([_row("drop_mass-1.0")])
    path = tmp_path / RESULTS_FILE
    path.write_text(path.read_text(encoding="utf-8").replace(",drop,1.0", ",drop,heavy"), encoding="utf-8")
    with pytest.raises(ResultsError, match=r"results.csv: row 1 \(line 2\): sweep:body\[ball\].mass .heavy. is not a number"):
        read_run(tmp_path)


def _finished_sweep(tmp_path) -> tuple[list, pd.DataFrame]:
    """A finished run of swept scenes (floats, whole numbers, NaN, n/a and empty cells) with its results.parquet: (its
    scenes, the table its writer handed back)."""
    scenes = _swept_scenes()
    writer = RunWriter(tmp_path, describe_run([], "simparity run", scenes))
    writer.append([_row(s.name) for s in scenes])
    writer.append([ResultRow(scenes[0].name, "mujoco", "", math.nan, "position_error_max", math.nan, "m",
                             "analytic:exact", "n/a", "no such integrator, \"quoted\"", "saturated", "rk4")])
    return scenes, writer.finish()


def test_the_writer_hands_back_the_table_it_wrote(tmp_path):
    """What a run's verdict, history and report are given without reading the folder again is what a reader of the
    folder gets, from the Parquet copy and from the CSV alike, type for type."""
    _, written = _finished_sweep(tmp_path)
    assert len(written) == len(_swept_scenes()) + 1
    pd.testing.assert_frame_equal(written, read_run(tmp_path)[0])
    (tmp_path / "results.parquet").unlink()
    pd.testing.assert_frame_equal(written, read_run(tmp_path)[0])


def test_results_parquet_holds_the_csv_table_typed(tmp_path):
    """Issue #29: results.parquet beside results.csv (pyarrow installed) gives read_run the same table as the CSV,
    value for value and type for type; its key columns are stored as categories, its numbers as numbers."""
    import pyarrow.parquet

    _finished_sweep(tmp_path)
    parquet = tmp_path / store.RESULTS_PARQUET_FILE
    assert parquet.is_file()
    from_parquet, _ = read_run(tmp_path)
    parquet.rename(tmp_path / "aside.parquet")
    from_csv, _ = read_run(tmp_path)
    pd.testing.assert_frame_equal(from_parquet, from_csv)
    schema = pyarrow.parquet.read_schema(tmp_path / "aside.parquet")
    assert all(str(schema.field(c).type).startswith("dictionary") for c in ("scene", "engine", "metric", "status"))
    assert str(schema.field("value").type) == "double" and str(schema.field("sweep:targets.seed").type) == "int64"


def test_without_pyarrow_runs_are_stored_and_read_as_csv(tmp_path, monkeypatch):
    """pyarrow is optional (simparity[parquet]): without it no results.parquet is written, and one already there is
    passed over for the CSV."""
    _finished_sweep(tmp_path / "both")
    csv = tmp_path / "both" / RESULTS_FILE
    csv.write_text(csv.read_text(encoding="utf-8").replace("no such integrator", "edited"), encoding="utf-8")
    with monkeypatch.context() as uninstalled:
        uninstalled.setitem(sys.modules, "pyarrow", None)  # import pyarrow raises ImportError
        assert not store.parquet_available()
    # pandas, imported with pyarrow here, keeps using it for its own strings: the check above is what stands for it
    monkeypatch.setattr(store, "parquet_available", lambda: False)
    _finished_sweep(tmp_path / "plain")
    assert not (tmp_path / "plain" / store.RESULTS_PARQUET_FILE).exists()
    assert (tmp_path / "both" / store.RESULTS_PARQUET_FILE).exists()
    table, _ = read_run(tmp_path / "both")
    assert table["detail"].str.startswith("edited").sum() == 1


def test_a_csv_edited_after_its_parquet_is_read_instead(tmp_path):
    """results.csv is the record: one changed by hand after the run (rows removed) is what read_run gives."""
    _finished_sweep(tmp_path)
    csv = tmp_path / RESULTS_FILE
    lines = csv.read_text(encoding="utf-8").splitlines(keepends=True)
    csv.write_text("".join(lines[:-1]), encoding="utf-8")
    assert (tmp_path / store.RESULTS_PARQUET_FILE).is_file() and len(read_run(tmp_path)[0]) == len(lines) - 2


def test_a_run_that_starts_writing_again_drops_its_parquet(tmp_path):
    """A new run or a resumed one in the folder rewrites results.csv from its first row: the parquet of the run before
    is removed at once, so read_run never reads rows the CSV no longer has."""
    scenes, _ = _finished_sweep(tmp_path)
    RunWriter(tmp_path, describe_run([], "simparity run --resume", scenes)).append([_row(scenes[0].name)])
    assert not (tmp_path / store.RESULTS_PARQUET_FILE).exists()
    assert len(read_run(tmp_path)[0]) == 1
