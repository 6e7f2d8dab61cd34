"""The console script: Ctrl-C at any moment (imports, start-up, cases, the report) is one line and exit 130."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from simparity.comparisons.cli.console import EXIT_INTERRUPTED

SCRIPT = Path(sys.executable).with_name("simparity")
"""The installed console script, beside this interpreter (the README installs both into one environment)."""

INTERRUPT_AFTER = (0.4, 1.0, 2.0, 3.5, 6.0)
"""When [s] Ctrl-C is sent: during the imports, the scene loading, the workers' start, the cases and (on a
loaded machine) the report; a run that finished first exits 0 and is also fine."""


@pytest.mark.slow  # each runs the console script; under a loaded CI one run went on to its end (35 s, exit 0: allowed)
@pytest.mark.parametrize("seconds", INTERRUPT_AFTER)
def test_ctrl_c_at_any_moment_is_one_line_and_exit_130(seconds, tmp_path):
    # one worker (--jobs 1), the quick profile: the same phases, at a fraction of the CPU of the full profile on two
    # workers, and a run the signal reaches only after it ended (a loaded machine) costs seconds, not a full run's ~35
    process = subprocess.Popen([str(SCRIPT), "run", "lecture-projectile", "lecture-2link-ik", "--repeats", "0",
                                "--quick", "--jobs", "1", "--out", str(tmp_path / "run")], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    time.sleep(seconds)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=120)
    assert process.returncode in (EXIT_INTERRUPTED, 0), (process.returncode, err)
    assert "Traceback" not in err and "Traceback" not in out, err
    if process.returncode == EXIT_INTERRUPTED:
        assert "interrupted" in err + out
