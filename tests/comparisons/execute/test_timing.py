"""Timing and resource figures (comparisons/execute/timing.py)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.execute.timing import PeakMemory, peak_memory, record_peak_memory, resource_line
from simparity.comparisons.common.processes import status_bytes
from simparity.core.model.results import RUN_INFO_FILE
from simparity.core.model.run_info import RunInfo

PARENT_BYTES = 300 * 2**20
"""Resident memory the test process takes before starting a child."""
HIGH_WATER_DRIFT = 0.01
"""Relative growth of this process's high-water mark allowed between recording it and reading it again (reading
run.json allocates a few KiB; the test process holds tens of MiB)."""


@pytest.mark.slow  # ~1.5 s of CPU: subprocesses
@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux's /proc (VmHWM)")
def test_a_process_started_by_a_large_one_reports_its_own_peak():
    """Held-out finding (issue #11): ru_maxrss survives exec, so `simparity run` started by a 3.8 GiB benchmark
    reported 3.8 GiB; the peak now comes from VmHWM, which starts afresh."""
    ballast = np.ones(PARENT_BYTES // 8)
    assert peak_memory().this_process_bytes >= PARENT_BYTES
    script = "from simparity.comparisons.execute.timing import peak_memory; print(peak_memory().this_process_bytes)"
    child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert int(child.stdout) < PARENT_BYTES / 2 and ballast.sum() > 0


def test_the_resource_line_names_wall_time_and_peak_memory():
    assert resource_line(12.345).startswith("wall time 12.3 s; peak memory ")


def test_a_process_memory_field_is_read_in_bytes_or_none():
    assert status_bytes("VmRSS") > 10 * 1024 ** 2  # this Python with NumPy holds more than 10 MiB
    assert status_bytes("VmRSS", pid=2 ** 31) is None  # no such process


def test_a_run_s_peak_memory_is_recorded_in_its_run_json_and_read_back(tmp_path):
    """The bench reads the peak by its field names from run.json, never by the first number of a printed line; a run
    that recorded none (older, or stopped before the end) reads as None."""
    RunInfo(command="simparity run").write(tmp_path / RUN_INFO_FILE)
    assert PeakMemory.of_run(tmp_path) is None
    recorded = record_peak_memory(tmp_path)
    assert PeakMemory.of_run(tmp_path) == recorded and RunInfo.read(tmp_path / RUN_INFO_FILE).command == "simparity run"
    assert recorded.this_process_bytes == pytest.approx(status_bytes("VmHWM"), rel=HIGH_WATER_DRIFT)
