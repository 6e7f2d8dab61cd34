"""Issue #41, "waiting that shows": a run whose output is a pipe (a CI log) says each scene as it finishes, not every
scene at the end; a gate-only run (--no-report) draws no report, says how to draw it later, and 'simparity report'
does; the run ends with where its wall time went."""

import re
import subprocess
import sys

import pytest

from simparity.comparisons.cli.main import EXIT_OK
from simparity.core.model.results import RESULTS_FILE, RUN_INFO_FILE
from tests.comparisons.cli.test_cli import _run

TWO_SCENES = ["lecture-planar-arm", "oblique-arm-dynamics"]
"""A cheap scene first in the suite's order (and by name), a costlier one second: the costliest runs first, so it
finishes first. Both cost little (the arm's configurations; the oblique arm's joint dynamics, ~0.1 s of CPU): what
is tested is the order the run says them in, which neither the command line's nor the names' order gives."""


@pytest.mark.slow  # a simparity process of its own: ~3 s of CPU
def test_a_piped_run_says_each_scene_as_it_finishes(tmp_path):
    command = [sys.executable, "-m", "simparity.comparisons.cli", "run", *TWO_SCENES, "--quick", "--engines", "core",
               "--jobs", "1", "--no-report", "--out", str(tmp_path / "run"), "--history", str(tmp_path / "h.sqlite")]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    scene_lines, running_at_first = [], None
    assert process.stdout is not None
    for line in process.stdout:  # as they come
        if re.match(r"[\w-]+: \d+ cases \(", line):
            if running_at_first is None:
                running_at_first = process.poll() is None
            scene_lines.append(line.split(":")[0])
    assert process.wait() == EXIT_OK
    # the costlier scene, run first, is said when it is done: before the cheap scene's case has run, not at the end
    assert scene_lines == ["oblique-arm-dynamics", "lecture-planar-arm"] and running_at_first


@pytest.mark.slow  # a run and a report: ~6 s of CPU
def test_a_gate_only_run_draws_no_report_and_simparity_report_draws_it_later(tmp_path):
    run, junit, summary = tmp_path / "run", tmp_path / "junit.xml", tmp_path / "summary.md"
    code, text = _run(["run", "lecture-planar-arm", "--engines", "core,analytic", "--repeats", "0", "--no-report",
                       "--jobs", "1", "--out", str(run), "--history", str(tmp_path / "h.sqlite"), "--check",
                       "--junit", str(junit), "--summary", str(summary)])
    assert code == EXIT_OK and "check passed" in text
    assert (run / RESULTS_FILE).is_file() and (run / RUN_INFO_FILE).is_file() and junit.is_file() and summary.is_file()
    assert not (run / "report.md").exists() and not (run / "report.html").exists()
    assert f"report:  not drawn (asked for none); 'simparity report {run}' draws {run / 'report.md'}" in text
    lines = text.strip().splitlines()
    assert re.fullmatch(r"wall time by part: cases \d+\.\d s, storing \d+\.\d s, report 0\.0 s, the rest \d+\.\d s "
                        r"\(.*\)", lines[-2]) and lines[-1].startswith("wall time ")
    code, _ = _run(["history", "lecture-planar-arm", "--history", str(tmp_path / "h.sqlite")])
    assert code == EXIT_OK  # recorded as any run is
    code, text = _run(["report", str(run)])
    assert code == EXIT_OK and (run / "report.html").is_file()
    assert "lecture-planar-arm" in (run / "report.md").read_text(encoding="utf-8")
