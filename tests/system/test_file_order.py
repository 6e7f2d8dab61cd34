"""The order files are handed to the workers in (tests/conftest.py): the files holding the most slow tests first."""

import re
from pathlib import Path

pytest_plugins = ["pytester"]

CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"

QUICK = "def test_a():\n    pass\n\n\ndef test_b():\n    pass\n"
ONE_SLOW = "import pytest\n\n\ndef test_a():\n    pass\n\n\n@pytest.mark.slow\ndef test_b():\n    pass\n"
TWO_SLOW = ("import pytest\n\n\n@pytest.mark.slow\ndef test_z():\n    pass\n\n\ndef test_y():\n    pass\n\n\n"
            "@pytest.mark.slow\ndef test_x():\n    pass\n")


def _collected(pytester, *args):
    result = pytester.runpytest_inprocess("--collect-only", "-q", "-p", "no:cacheprovider", "-p", "no:xdist", *args)
    return [line for line in result.outlines if re.match(r"test_\w+\.py::", line)]


def test_files_with_more_slow_tests_come_first_each_in_its_own_order(pytester):
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makeini("[pytest]\nmarkers =\n    slow: slow\n")
    pytester.makepyfile(test_a_quick=QUICK, test_b_one=ONE_SLOW, test_c_two=TWO_SLOW)
    assert _collected(pytester) == [
        "test_c_two.py::test_z", "test_c_two.py::test_y", "test_c_two.py::test_x",
        "test_b_one.py::test_a", "test_b_one.py::test_b",
        "test_a_quick.py::test_a", "test_a_quick.py::test_b"]
    # counted after -m deselected what it deselects: no slow test left, every file keeps its collected place
    assert _collected(pytester, "-m", "not slow") == [
        "test_a_quick.py::test_a", "test_a_quick.py::test_b", "test_b_one.py::test_a", "test_c_two.py::test_y"]
