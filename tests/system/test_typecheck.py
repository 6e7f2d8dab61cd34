"""The installed package type-checks: mypy, with pyproject's [tool.mypy], over every ``simparity.*`` module.

The project root is the package (``package-dir = {"simparity" = "."}``), so a checkout has no
``simparity`` folder for a type checker to find; ``.typecheck/simparity`` is a committed symlink to
the root and ``mypy_path`` points there. tests/, examples/, docs/ and build output are left out.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LINK = ROOT / ".typecheck" / "simparity"
MYPY_SECONDS = 240  # a cold run takes ~20 s alone, more beside the other test worker; the cache makes reruns ~2 s


def test_the_typecheck_link_is_the_project_root():
    """Relative, so it holds in any clone; the wheel and the tests' rglob over layers never follow it."""
    assert LINK.is_symlink()
    assert os.readlink(LINK) == ".."
    assert LINK.resolve() == ROOT


@pytest.mark.slow
def test_mypy_passes_over_the_package():
    command = [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"), "-p", "simparity"]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=MYPY_SECONDS)
    assert done.returncode == 0, f"mypy exited {done.returncode}:\n{done.stdout}{done.stderr}"
