"""What `pip install .` puts into site-packages: one namespace, the scene library, the command."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD_SECONDS = 300  # pip may fetch the build backend (setuptools) from the package index first
NOT_SOURCE = (".git", "build", "dist", ".venv", "__pycache__", "*.egg-info", "simparity-results", ".pytest_cache",
              "test-artifacts", ".typecheck", ".mypy_cache")
"""What the wheel is not built from: version control, earlier builds, environments, results, caches (mypy's, which the
type check's test may be writing on the other worker while this copies: its SQLite journal files come and go, and a
copy that lists one and then misses it failed this test once)."""
LAYERS = ("core", "references", "comparisons", "reports")
"""The design's folders that install as simparity's sub-packages."""


@pytest.mark.slow
def test_the_wheel_holds_only_the_simparity_namespace(tmp_path):
    """No top-level core/references/comparisons/reports: they are simparity.core and so on."""
    # from a copy without build/: setuptools keeps what an earlier build put there, which hid a package missing from
    # pyproject's list (a fresh clone has no build/)
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(*NOT_SOURCE))
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "-q", "-w", str(tmp_path)],
                   check=True, timeout=BUILD_SECONDS, capture_output=True)
    (wheel,) = tmp_path.glob("simparity-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert {n.split("/")[0] for n in names} == {"simparity", wheel.name.split("-py")[0] + ".dist-info"}
    # every package of the layers, found on disk (a new sub-package missing from pyproject's list installs a
    # simparity whose core cannot import: found when core/articulated was added), and every built-in scene's files
    packages = {str(p.parent.relative_to(ROOT)) for layer in LAYERS for p in (ROOT / layer).rglob("__init__.py")
                if "__pycache__" not in p.parts and "build" not in p.parts}
    assert packages >= {"core", "core/ik", "references", "comparisons", "reports"}
    missing = sorted(p for p in packages if f"simparity/{p}/__init__.py" not in names)
    assert not missing, f"packages not in the wheel (pyproject's packages): {missing}"
    scene_files = {str(p.relative_to(ROOT)) for p in (ROOT / "comparisons" / "scenes").rglob("*")
                   if p.suffix in (".toml", ".urdf")}
    assert {"comparisons/scenes/dzhanibekov.toml", "comparisons/scenes/urdf/crafted-arm.urdf"} <= scene_files
    assert not sorted(f for f in scene_files if f"simparity/{f}" not in names)
    assert not any(n.startswith("simparity/tests/") or n.startswith("simparity/benchmarks/") for n in names)
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    assert "simparity = simparity.comparisons.cli.console:main" in zipfile.ZipFile(wheel).read(entry_points).decode()
