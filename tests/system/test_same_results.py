"""The bit-identity check of a redesign (tests/same_results.py) finds a moved number and ignores wall time."""

import pandas as pd

from simparity.core.model.results import RESULTS_FILE, SERIES_FILE
from tests.same_results import differences, series_differences


def _run(folder, values, detail="x"):
    folder.mkdir()
    pd.DataFrame({"scene": ["s", "s"], "engine": ["core", "core"], "integrator": ["rk4", "rk4"], "dt": ["0.1", "0.1"],
                  "metric": ["position_error_max", "time_per_step"], "value": values, "detail": ["", detail]}
                 ).to_csv(folder / RESULTS_FILE, index=False)
    return folder


def test_timing_aside_two_runs_are_the_same(tmp_path):
    assert differences(_run(tmp_path / "a", ["1e-3", "2e-6"]), _run(tmp_path / "b", ["1e-3", "3e-6"], "y")) == []


def test_a_number_that_moved_in_its_last_digit_is_found(tmp_path):
    found = differences(_run(tmp_path / "a", ["0.0010000000000000002", "2e-6"]), _run(tmp_path / "b", ["0.001", "2e-6"]))
    assert len(found) == 1 and "position_error_max) value" in found[0]


def test_where_an_environment_installed_a_package_is_not_a_difference(tmp_path):
    before = _run(tmp_path / "a", ["1e-3", "2e-6"])
    after = _run(tmp_path / "b", ["1e-3", "2e-6"])
    for folder, prefix in ((before, "/venv-a"), (after, "/home/u/.venv")):
        table = pd.read_csv(folder / RESULTS_FILE, dtype=str, keep_default_na=False)
        table.loc[0, "detail"] = f"loadURDF of {prefix}/lib/python3.11/site-packages/pybullet_data/kuka_iiwa/model.urdf"
        table.to_csv(folder / RESULTS_FILE, index=False)
    assert differences(before, after) == []


def test_where_a_checkout_of_simparity_lives_is_not_a_difference_but_another_file_is(tmp_path):
    """Two checkouts (a worktree beside main) read a built-in scene's URDF from two places; another file is a change."""
    def with_detail(name, path):
        folder = _run(tmp_path / name, ["1e-3", "2e-6"])
        table = pd.read_csv(folder / RESULTS_FILE, dtype=str, keep_default_na=False)
        table.loc[0, "detail"] = f"read {path}, 7 joints"
        table.to_csv(folder / RESULTS_FILE, index=False)
        return folder

    main = with_detail("a", "/work/main/comparisons/scenes/urdf/arm.urdf")
    worktree = with_detail("b", "/w/tree/.typecheck/simparity/comparisons/scenes/urdf/arm.urdf")
    other = with_detail("c", "/w/tree/.typecheck/simparity/comparisons/scenes/urdf/other.urdf")
    assert differences(main, worktree) == []
    assert len(differences(main, other)) == 1


def test_a_sampled_series_that_moved_is_found(tmp_path):
    """The series are compared too (a redesign of how runs are read must keep the envelopes the report draws)."""
    before, after = _run(tmp_path / "a", ["1e-3", "2e-6"]), _run(tmp_path / "b", ["1e-3", "2e-6"])
    for folder, value in ((before, "0.25"), (after, "0.2500000000000001")):
        pd.DataFrame({"scene": ["s"], "engine": ["core"], "integrator": ["rk4"], "dt": ["0.1"], "quantity": ["x"],
                      "value": [value]}).to_csv(folder / SERIES_FILE, index=False)
    found = series_differences(before, after)
    assert len(found) == 1 and "value: '0.25' -> '0.2500000000000001'" in found[0]
    assert series_differences(before, before) == []
