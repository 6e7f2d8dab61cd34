"""Held-out review of #39: what a stored run or a user names never leads a write out of its folder (a scene named
``../../x`` in results.csv wrote figures beside the run), and a history database a run cannot record in is said
before the run, exit 2, no folder made."""

from pathlib import Path

import pytest

from simparity.comparisons.cli.main import EXIT_USAGE, main
from simparity.reports.figures import figure_stem


@pytest.mark.parametrize("name", ["../../escape-drift", "/tmp/abs/x-convergence", "a/b", "..", ".hidden", "c:\\d", ""])
def test_a_figure_name_stays_in_its_folder(tmp_path, name):
    stem = figure_stem(name)
    folder = tmp_path / "figures"
    assert stem and "/" not in stem and "\\" not in stem and not stem.startswith(".")
    assert (folder / f"{stem}.svg").resolve().parent == folder.resolve()


def test_a_builtin_scene_names_its_figures_as_before():
    assert figure_stem("restitution-sweep_restitution-0.7-work-precision") == \
        "restitution-sweep_restitution-0.7-work-precision"


def test_a_history_that_is_no_database_is_refused_before_the_run(tmp_path, capsys):
    history = tmp_path / "history.sqlite"
    history.write_text("not a database", encoding="utf-8")
    out = tmp_path / "run"
    code = main(["run", "lecture-projectile", "--quick", "--engines", "core", "--out", str(out), "--history",
                 str(history)])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE and str(history) in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
