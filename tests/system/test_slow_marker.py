"""The inner loop's guard (tests/conftest.py): an unmarked test over its CPU limit fails, naming the marker to add."""

import re
from pathlib import Path

pytest_plugins = ["pytester"]

CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"
LIMIT_SECONDS = 0.05
"""The CPU limit the inner session runs with: far below the busy tests' 0.3 s, far above a test that returns at once."""

BUSY_TESTS = '''
import subprocess
import sys
import time

import pytest

BUSY_SECONDS = 0.3


def _busy():
    end = time.process_time() + BUSY_SECONDS
    while time.process_time() < end:
        pass


def test_unmarked_busy():
    _busy()


def test_unmarked_busy_child():
    subprocess.run([sys.executable, "-c", f"import time; e = time.process_time() + {BUSY_SECONDS}\\nwhile time.process_time() < e: pass"], check=True)


@pytest.mark.slow
def test_marked_busy():
    _busy()


def test_unmarked_quick():
    pass
'''


def test_an_unmarked_test_over_the_limit_fails_and_a_marked_one_passes(pytester):
    conftest = CONFTEST.read_text(encoding="utf-8")
    limited, count = re.subn(r"^UNMARKED_CPU_SECONDS_MAX = .*$", f"UNMARKED_CPU_SECONDS_MAX = {LIMIT_SECONDS}",
                             conftest, flags=re.M)
    assert count == 1, "tests/conftest.py no longer defines UNMARKED_CPU_SECONDS_MAX on one line"
    pytester.makeconftest(limited)
    pytester.makeini("[pytest]\nmarkers =\n    slow: slow\n")
    pytester.makepyfile(test_busy=BUSY_TESTS)
    result = pytester.runpytest_inprocess("-p", "no:cacheprovider", "-p", "no:xdist")
    result.assert_outcomes(passed=2, failed=2)  # the busy test and the busy child's test; marked and quick pass
    outcomes = "\n".join(result.outlines)
    failed = set(re.findall(r"^FAILED test_busy\.py::(\w+)", outcomes, flags=re.M))
    assert failed == {"test_unmarked_busy", "test_unmarked_busy_child"}, outcomes
    assert "mark it @pytest.mark.slow" in outcomes
