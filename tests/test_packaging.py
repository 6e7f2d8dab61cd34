"""What `pip install .` puts into site-packages: one namespace, the scene library, the command."""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BUILD_SECONDS = 300  # pip may fetch the build backend (setuptools) from the package index first


@pytest.mark.slow
def test_the_wheel_holds_only_the_simparity_namespace(tmp_path):
    """No top-level core/references/comparisons/reports: they are simparity.core and so on."""
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "-q", "-w", str(tmp_path)],
                   check=True, timeout=BUILD_SECONDS, capture_output=True)
    (wheel,) = tmp_path.glob("simparity-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert {n.split("/")[0] for n in names} == {"simparity", wheel.name.split("-py")[0] + ".dist-info"}
    for package in ("core", "core/ik", "references", "comparisons", "reports"):
        assert f"simparity/{package}/__init__.py" in names
    assert "simparity/comparisons/scenes/dzhanibekov.toml" in names
    assert not any(n.startswith("simparity/tests/") or n.startswith("simparity/benchmarks/") for n in names)
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    assert "simparity = simparity.comparisons.cli.console:main" in zipfile.ZipFile(wheel).read(entry_points).decode()
