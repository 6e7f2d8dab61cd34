"""Issue #12: ``simparity run --resume DIR``. A run killed halfway and resumed writes the same results.csv as
an uninterrupted run; finished cases are kept, cases that did not finish are tried again."""

from __future__ import annotations

import dataclasses
import math
import os
import pickle
import shutil
import sys

import pandas as pd
import pytest

from simparity.comparisons.execute.cases import CaseKey, CaseOutcome
from simparity.comparisons.cli.main import main
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.execution import count_cases, run_scenes
from simparity.comparisons.execute.journal import CASES_FOLDER, Journal, run_lock
from simparity.comparisons.scenes.profiles import apply_profile
from simparity.core.model.results import RESULTS_FILE, ResultRow
from simparity.comparisons.scenes import library
from tests.helpers import THROWN_BALL, InProcess, killed_and_resumed

SCENES = ("ball-bounce-k05", "lecture-2link-ik", "ur5-kinematics")
KILL_WAIT_SECONDS = 240
"""How long the test waits for half the cases to finish before it gives up (they take ~2 s on 2 cores)."""

TRIMMED = {
    "ball-bounce-k05": (("duration = 2.0", "duration = 0.6"), ("dt = [0.001, 0.0025, 0.005, 0.01]", "dt = [0.005, 0.01]")),
    "lecture-2link-ik": (("count = 500", "count = 10\nmax_iterations = 20"),),
}
"""What the killed-and-resumed run trims from a built-in scene's file (the text it replaces, and by what): the
ball still meets the floor (at 0.45 s) and leaves it before the end, at two time steps; every IK solver still
iterates to its cap on the hard targets. 15 cases of three kinds, ~1 CPU-s in all instead of ~8: some kept before
the kill, some computed after it, what resuming is about; it compares the rows of a resumed and a whole run, not
their accuracy."""


ENGINES = ("core", "analytic")
"""Enough engines for cases of every kind in both processes (the journal keys a case by engine, not by what it
computes): core, and the reference of the ball and the arm; MuJoCo's, PyBullet's and Pinocchio's cases would add a
case process per group and run (~2 CPU-s for MuJoCo's alone) and test nothing more of resuming."""


NO_REPORT = "--no-report"
"""Every run here draws no report: the tests read results.csv and the kept cases (a report is ~5 CPU-s a run)."""


def _trimmed_scenes(folder) -> list[str]:
    """:data:`SCENES` as the killed-and-resumed run gives them: a file in ``folder`` for each one :data:`TRIMMED`
    trims, the others by name."""
    scenes = []
    for name in SCENES:
        if name not in TRIMMED:
            scenes.append(name)
            continue
        text = library.builtin_paths()[name].read_text(encoding="utf-8")
        for old, new in TRIMMED[name]:
            assert text.count(old) == 1, (name, old)  # the built-in file changed: trim it anew
            text = text.replace(old, new)
        path = folder / f"{name}.toml"
        path.write_text(text, encoding="utf-8")
        scenes.append(str(path))
    return scenes


def _run_args(scenes: list[str], out, jobs: int) -> list[str]:
    return ["run", *scenes, "--quick", "--jobs", str(jobs), "--engines", ",".join(ENGINES), NO_REPORT, "--out", str(out)]


def _table(run_dir) -> pd.DataFrame:
    """results.csv as text, the wall times blanked (they differ between any two runs)."""
    table = pd.read_csv(run_dir / RESULTS_FILE, dtype=str, keep_default_na=False)
    table.loc[table.metric.str.startswith("time_"), "value"] = "timing"
    return table


@pytest.mark.slow
def test_a_run_killed_halfway_and_resumed_writes_the_same_results(tmp_path):
    scenes = _trimmed_scenes(tmp_path)
    total = sum(count_cases(apply_profile(library.load(scenes), "quick"), [make_engine(n) for n in ENGINES],
                            make_engine))
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    # The uninterrupted run in this process by one worker: a reference only (the results do not depend on the number of
    # workers); the killed run is a process of its own with two workers, both keeping cases when it is killed; the
    # resumed run computes what is left by one worker (a worker start less).
    assert main(_run_args(scenes, whole, 1)) == 0
    killed_and_resumed([sys.executable, "-m", "simparity.comparisons.cli", *_run_args(scenes, killed, 2)], killed,
                       total, KILL_WAIT_SECONDS, (NO_REPORT, "--jobs", "1"))
    pd.testing.assert_frame_equal(_table(killed), _table(whole))


def test_resume_refuses_a_folder_without_a_run_and_options_that_change_it(tmp_path, capsys):
    assert main(["run", "--resume", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "resume.json" in err
    assert main(["run", "lecture-projectile", "--resume", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "SCENE" in err and "allowed with --resume" in err
    (tmp_path / "resume.json").write_text("{not json", encoding="utf-8")
    assert main(["run", "--resume", str(tmp_path)]) == 2
    assert "resume.json: not JSON" in capsys.readouterr().err


def test_unfinished_and_unreadable_cases_are_computed_again(tmp_path):
    journal = Journal(tmp_path)
    key = CaseKey("hash", "core", "1.0", "rk4", 0.01, "dynamics")
    journal.save(key, CaseOutcome([], harness_failure=True))
    assert journal.load(key) is None and len(journal) == 0
    journal.save(key, CaseOutcome([]))
    assert journal.load(key) == CaseOutcome([])
    (tmp_path / CASES_FOLDER / f"{key.digest()}.pickle").write_bytes(b"truncated")
    assert journal.load(key) is None and journal.unreadable == 1
    other = CaseKey("hash", "core", "1.1", "rk4", 0.01, "dynamics")
    assert other.digest() != key.digest()


def test_a_case_without_a_time_step_is_read_back(tmp_path):
    """Issue #39: an IK, kinematics or joint-dynamics case is kept under a key whose dt is NaN, and NaN != NaN: it was
    never read back, so --resume computed every such case again (a sweep of 1,000 IK variants from its start)."""
    journal = Journal(tmp_path)
    for kind, method in (("ik", "damped_least_squares"), ("kinematics", ""), ("joint_dynamics", "recursive")):
        key = CaseKey("hash", "core", "1.0", method, math.nan, kind)
        journal.save(key, CaseOutcome([]))
        assert journal.load(key) == CaseOutcome([]), kind
    assert journal.unreadable == 0


def test_a_case_kept_before_its_types_moved_is_read_by_their_names(tmp_path):
    """A journal names its types by module path; kept by a simparity whose modules were elsewhere (before the
    folders per job: simparity.comparisons.execute.cases, simparity.core.results), it is still read, not computed again."""
    journal = Journal(tmp_path)
    key = CaseKey("hash", "core", "1.0", "rk4", 0.01, "dynamics")
    row = ResultRow("s", "core", "rk4", 0.01, "position_error_max", 1e-6, "m", "analytic:exact", "ok")
    kept = pickle.dumps((key, CaseOutcome([row])), protocol=2)  # protocol 2 names each type as "module\nname"
    for new, old in ((b"simparity.comparisons.execute.cases", b"simparity.comparisons.cases"),
                     (b"simparity.core.model.results", b"simparity.core.results")):
        assert new in kept
        kept = kept.replace(new, old)
    (tmp_path / CASES_FOLDER / f"{key.digest()}.pickle").write_bytes(kept)
    assert journal.load(key) == CaseOutcome([row]) and journal.unreadable == 0


class _Planted:
    """What a tampered case file holds: unpickling it would call ``os.system`` (or a simparity function)."""

    def __init__(self, call, *args) -> None:
        self.call, self.args = call, args

    def __reduce__(self):
        return self.call, self.args


@pytest.mark.parametrize("call", [os.system, main])
def test_a_case_file_that_names_code_is_computed_again_and_never_runs_it(tmp_path, call):
    """--resume reads only simparity's data types and NumPy arrays: a file naming os.system or simparity's own CLI
    is refused (the case is computed again) and the planted command never runs."""
    journal = Journal(tmp_path)
    key = CaseKey("hash", "core", "1.0", "rk4", 0.01, "dynamics")
    witness = tmp_path / "ran"
    payload = f"touch {witness}" if call is os.system else ["list", "--out", str(witness)]
    (tmp_path / CASES_FOLDER / f"{key.digest()}.pickle").write_bytes(pickle.dumps((key, _Planted(call, payload))))
    assert journal.load(key) is None
    assert not witness.exists()


@pytest.mark.parametrize("dt", [0.01, float("nan")])
def test_a_key_digest_is_a_file_name(dt):
    digest = CaseKey("h", "a/b", "v", "rk4", dt, "dynamics").digest()
    assert len(digest) == 64 and all(c in "0123456789abcdef" for c in digest)


def _thrown_ball(folder) -> str:
    """A scene file of milliseconds per case (:data:`tests.helpers.THROWN_BALL`) in ``folder``; its path."""
    path = folder / "throw.toml"
    path.write_text(THROWN_BALL, encoding="utf-8")
    return str(path)


def _interrupted(run_dir, scene_file: str) -> int:
    """Leave in ``run_dir`` the kept cases an interrupted quick run of ``scene_file`` on core leaves, each claiming
    a detail no engine writes; returns how many there are."""
    scenes = apply_profile(library.load([scene_file]), "quick")
    list(run_scenes(scenes, [make_engine("core")], make_engine, 0, InProcess(), Journal(run_dir)))
    journal, planted = Journal(run_dir), 0
    for path in (run_dir / CASES_FOLDER).glob("*.pickle"):
        key, outcome = pd.read_pickle(path)
        outcome.rows = [dataclasses.replace(r, detail="planted") for r in outcome.rows]
        journal.save(key, outcome)
        planted += 1
    return planted


def _argv(scene: str, out) -> list[str]:
    """A quick run of ``scene`` on core by one worker into ``out``."""
    return ["run", scene, "--quick", "--engines", "core", "--jobs", "1", NO_REPORT, "--out", str(out)]


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    """The folder of a finished quick run of the thrown ball on core (and its scene file), shared by the tests that
    resume or overwrite it (each on a copy of its own, or refused before anything is written)."""
    folder = tmp_path_factory.mktemp("finished")
    scene, out = _thrown_ball(folder), folder / "run"
    assert main(_argv(scene, out)) == 0
    return scene, out


@pytest.mark.slow
def test_a_forced_new_run_reuses_nothing_a_run_left_and_a_finished_run_keeps_no_cases(tmp_path, finished_run):
    scene, finished = finished_run
    assert not (finished / CASES_FOLDER).exists()  # finished, every case done: they are in results.csv
    out = shutil.copytree(finished, tmp_path / "run")
    assert _interrupted(out, scene) > 0
    assert main(_argv(scene, out) + ["--force"]) == 0
    assert "planted" not in (out / RESULTS_FILE).read_text(encoding="utf-8")
    _interrupted(out, scene)
    assert main(["run", "--resume", str(out), NO_REPORT]) == 0  # a resumed run, by contrast, keeps what it finds
    assert "planted" in (out / RESULTS_FILE).read_text(encoding="utf-8")


def test_a_folder_being_written_by_another_run_is_refused(tmp_path, capsys):
    with run_lock(tmp_path):  # as another run would hold it
        assert main(["run", "lecture-projectile", "--out", str(tmp_path), "--force"]) == 2
    err = capsys.readouterr().err
    assert "another simparity run is writing this folder" in err and err.count("\n") == 1


@pytest.mark.slow
def test_a_finished_run_is_not_resumed(finished_run, capsys):
    assert main(["run", "--resume", str(finished_run[1])]) == 2
    err = capsys.readouterr().err
    assert "that run finished" in err and err.count("\n") == 1


@pytest.mark.parametrize("text, says", [
    ("[" * 100_000 + "]" * 100_000, "nested 100,000 levels deep"),
    ('{"scenes": ["a"], "max_steps": ' + "9" * 5001 + "}", "an integer of 5,001 digits"),
    ('{"scenes": [5]}', "scenes[0]: a number 5 (allowed: text)"),
    ('{"scenes": ["a"], "max_joints": "many"}', "max_joints: text 'many'"),
    ('{"scenes": ["a"], "max_steps": NaN}', "NaN, which is not JSON"),
    ('{"scenes": ["a"], "max_steps": 0}', "max_steps: a number 0 (allowed: a whole number > 0)"),
])
def test_a_damaged_request_is_refused_in_one_line(tmp_path, text, says):
    """Held-out review of #39: resume.json was read by json.loads alone (RecursionError, ValueError, TypeError)."""
    from simparity.comparisons.execute.journal import RESUME_FILE, read_request
    from simparity.core.model.errors import SimparityError

    (tmp_path / RESUME_FILE).write_text(text, encoding="utf-8")
    with pytest.raises(SimparityError) as refused:
        read_request(tmp_path)
    assert says in str(refused.value) and "\n" not in str(refused.value)
