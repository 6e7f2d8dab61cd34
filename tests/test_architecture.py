"""The import contract: layers import downward only, and no reference borrows the code it checks.

Read from the source with :mod:`ast` (every ``import`` and ``from ... import``, at any
depth, also inside functions), so a violation fails the suite whether or not the import
ever runs.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("core", "references", "comparisons", "reports")

DATA_MODEL = {
    "simparity.core.scene",
    "simparity.core.trajectory",
    "simparity.core.results",
    "simparity.core.engine",
    "simparity.core.errors",
    "simparity.core.arrays",
    "simparity.core.ik.problem",
    "simparity.core.ik.result",
}
"""What references/ may import from core: the data model, never an in-house method (integrators,
forces, rigid-body state, rotations, kinematics, inertia, IK solvers, collision, ...)."""

ENGINES = ("mujoco", "pybullet", "pinocchio")


def _imports(path: Path) -> set[str]:
    """Absolute module names a file imports (``from a.b import c`` gives a.b and a.b.c)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def _modules(layer: str) -> list[Path]:
    return sorted((ROOT / layer).rglob("*.py"))


def _project_modules(names: set[str]) -> set[str]:
    """The imported names that are project modules (a ``from m import function`` gives m only)."""
    return {n for n in names if n.startswith("simparity.") and (
        (ROOT / Path(*n.split(".")[1:])).with_suffix(".py").is_file() or (ROOT / Path(*n.split(".")[1:])).is_dir())}


@pytest.mark.parametrize("path", _modules("references"), ids=lambda p: p.name)
def test_references_import_only_the_data_model_of_core(path):
    """A reference that imported core's methods would agree with a bug in them."""
    borrowed = {n for n in _project_modules(_imports(path)) if n.startswith("simparity.core")} - DATA_MODEL
    borrowed.discard("simparity.core")
    assert not borrowed, f"{path.name} imports in-house code {sorted(borrowed)}; allowed: {sorted(DATA_MODEL)}"


JUDGES = ("metrics.py", "divergence.py", "invariants.py", "ik_runner.py", "transforms.py", "units.py", "perturb.py",
          "rounding_allowance.py", "metamorphic.py", "engine_constants.py")
"""The comparisons that measure and judge (the metamorphic ones included: a transform computed with core's
rotations would agree with a bug in them): like a reference, they must not use the code they judge."""


@pytest.mark.parametrize("name", JUDGES)
def test_metrics_use_no_in_house_method(name):
    """A metric computed with core's rotations would agree with a bug in them."""
    path = ROOT / "comparisons" / name
    borrowed = {n for n in _project_modules(_imports(path)) if n.startswith("simparity.core")} - DATA_MODEL
    borrowed.discard("simparity.core")
    assert not borrowed, f"{name} imports in-house code {sorted(borrowed)}; allowed: {sorted(DATA_MODEL)}"


@pytest.mark.parametrize("module", sorted(DATA_MODEL))
def test_the_data_model_imports_no_in_house_method(module):
    """The data model references may use stays free of core's methods, so the contract above is not bypassed."""
    path = (ROOT / Path(*module.split(".")[1:])).with_suffix(".py")
    used = {n for n in _project_modules(_imports(path)) if n != "simparity.core"}
    assert used <= DATA_MODEL, f"{module} imports {sorted(used - DATA_MODEL)}"


@pytest.mark.parametrize("layer, forbidden", [
    ("core", ("simparity.references", "simparity.comparisons", "simparity.reports") + ENGINES),
    ("references", ("simparity.comparisons", "simparity.reports")),
    ("comparisons", ()),
    ("reports", ("simparity.references", "simparity.comparisons") + ENGINES),
])
def test_layers_import_downward_only(layer, forbidden):
    """core imports no engine and nothing above it; reports never run an engine."""
    for path in _modules(layer):
        bad = [n for n in _imports(path) if n.split(".")[0] in ENGINES and n.split(".")[0] in forbidden
               or any(n == f or n.startswith(f + ".") for f in forbidden if f.startswith("simparity"))]
        assert not bad, f"{path.relative_to(ROOT)} imports {bad}"


@pytest.mark.parametrize("layer", LAYERS)
def test_project_modules_are_imported_through_the_namespace(layer):
    """A bare ``import core`` works only from a checkout; installed, the code lives in simparity.core."""
    for path in _modules(layer):
        bare = [n for n in _imports(path) if n.split(".")[0] in LAYERS]
        assert not bare, f"{path.relative_to(ROOT)} imports {bare} outside the simparity namespace"


EXAMPLE_PLUGIN = ROOT / "examples" / "plugin-engine" / "src"
"""The plugin engine users copy (docs/plugins.md)."""


@pytest.mark.parametrize("path", sorted(EXAMPLE_PLUGIN.rglob("*.py")), ids=lambda p: p.name)
def test_the_example_plugin_imports_only_the_data_model_of_core(path):
    """Like a reference: a user's engine built on core's methods would agree with their bugs."""
    borrowed = _project_modules(_imports(path)) - DATA_MODEL - {"simparity.core"}
    assert not borrowed, f"{path.name} imports {sorted(borrowed)}; allowed: {sorted(DATA_MODEL)}"
