"""Timing and resource figures (comparisons/execute/timing.py)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.execute.timing import peak_memory_bytes, resource_line, status_bytes

PARENT_BYTES = 300 * 2**20
"""Resident memory the test process takes before starting a child."""


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux's /proc (VmHWM)")
def test_a_process_started_by_a_large_one_reports_its_own_peak():
    """Held-out finding (issue #11): ru_maxrss survives exec, so `simparity run` started by a 3.8 GiB benchmark
    reported 3.8 GiB; the peak now comes from VmHWM, which starts afresh."""
    ballast = np.ones(PARENT_BYTES // 8)
    assert peak_memory_bytes()[0] >= PARENT_BYTES
    child = subprocess.run([sys.executable, "-c", "from simparity.comparisons.execute.timing import peak_memory_bytes; "
                            "print(peak_memory_bytes()[0])"], capture_output=True, text=True, check=True)
    assert int(child.stdout) < PARENT_BYTES / 2 and ballast.sum() > 0


def test_the_resource_line_names_wall_time_and_peak_memory():
    assert resource_line(12.345).startswith("wall time 12.3 s; peak memory ")


def test_a_process_memory_field_is_read_in_bytes_or_none():
    assert status_bytes("VmRSS") > 10 * 1024 ** 2  # this Python with NumPy holds more than 10 MiB
    assert status_bytes("VmRSS", pid=2 ** 31) is None  # no such process
