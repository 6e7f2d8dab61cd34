"""Issue #12: every case runs in a worker process with a time and a memory limit; a case that segfaults, hangs
or allocates without bound becomes failed rows naming the cause, and every other case of the run completes."""

from __future__ import annotations

import pandas as pd
import pytest

from simparity.comparisons.cli import main
from simparity.comparisons.isolation import death_cause
from tests.helpers import THROWN_BALL

HOSTILE = {
    "segfaulting": ("tests.hostile_engines:SegfaultingEngine", "killed by signal 11 (SIGSEGV)"),
    "hanging": ("tests.hostile_engines:HangingEngine", "hung: no result within the per-case time limit of 4 s"),
    "hogging": ("tests.hostile_engines:HoggingEngine", "out of memory"),
}

CASE_SECONDS = 4
"""The hanging engine's limit: long enough for any honest case of the tiny scene below (milliseconds) and a
worker's start (~1 s of imports), short enough for a quick test."""

CASE_GIB = 1.0
"""The hogging engine's limit: ~4x what a worker running the tiny scene holds (~250 MiB)."""


def test_a_segfault_a_hang_and_a_memory_blow_up_each_fail_alone(tmp_path, capsys):
    scene = tmp_path / "drop.toml"
    scene.write_text(THROWN_BALL, encoding="utf-8")
    engines = ",".join(["core"] + [spec for spec, _ in HOSTILE.values()] + ["mujoco"])
    code = main(["run", str(scene), "--engines", engines, "--repeats", "0", "--jobs", "2", "--case-timeout",
                 str(CASE_SECONDS), "--case-memory", str(CASE_GIB), "--out", str(tmp_path / "run")])
    assert code == 1, capsys.readouterr()  # failed cases: exit 1, not a crash of the run
    assert "cases did not finish (crashed, hung or out of memory)" in capsys.readouterr().out
    assert (tmp_path / "run" / "cases").is_dir()  # kept for --resume, which tries those cases again
    table = pd.read_csv(tmp_path / "run" / "results.csv")
    cases = table[table.dt.notna()].groupby(["engine", "dt"])
    assert len(cases) == 5 * 2  # every engine at both time steps: nothing lost
    for name, (_, cause) in HOSTILE.items():
        rows = table[(table.engine == name) & table.dt.notna()]
        assert set(rows.status) == {"failed"} and rows.detail.str.contains(cause, regex=False).all(), name
    for honest in ("core", "mujoco"):
        rows = table[(table.engine == honest) & (table.metric == "position_error_max")]
        assert list(rows.status) == ["ok", "ok"], honest


def test_the_cause_of_a_death_names_the_signal_and_where():
    stderr = 'Fatal Python error: Segmentation fault\n\nCurrent thread 0x1 (most recent call first):\n  File "/x/eng.py", line 7 in run\n'
    assert death_cause(-11, stderr) == 'crashed: the worker was killed by signal 11 (SIGSEGV), in File "/x/eng.py", line 7 in run'
    assert "out-of-memory killer" in death_cause(-9, "")
    assert death_cause(1, "Traceback ...\nValueError: bad\n") == "crashed: the worker exited with code 1: ValueError: bad"


@pytest.mark.parametrize("option, value", [("--case-timeout", "0"), ("--case-timeout", "nan"), ("--case-memory", "-1"),
                                           ("--case-memory", "inf")])
def test_limits_out_of_range_are_one_line_errors(option, value, capsys, tmp_path):
    assert main(["run", "lecture-projectile", option, value, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and option in err and "allowed" in err
