"""The import contract: layers import downward only, and no reference borrows the code it checks.

Read from the source with :mod:`ast` (every ``import`` and ``from ... import``, at any
depth, also inside functions), so a violation fails the suite whether or not the import
ever runs.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("core", "references", "comparisons", "reports")

MODEL = "simparity.core.model"
"""The data model (scenes, trajectories, results, the engine interface, errors, IK types), all of it one folder:
what references/ and the judges may import from core, never an in-house method (integrators, forces, rigid-body
state, rotations, kinematics, inertia, IK solvers, collision, ...)."""

PUBLIC_ALIASES = {
    "simparity.core.scene", "simparity.core.trajectory", "simparity.core.results", "simparity.core.engine",
    "simparity.core.errors", "simparity.core.arrays", "simparity.core.ik.problem", "simparity.core.ik.result",
}
"""The data model's modules at the paths plugins import (docs/plugins.md): re-exports of :data:`MODEL`."""


def _data_model(name: str) -> bool:
    return name == MODEL or name.startswith(MODEL + ".") or name in PUBLIC_ALIASES


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
    borrowed = {n for n in _project_modules(_imports(path)) if n.startswith("simparity.core") and not _data_model(n)}
    borrowed.discard("simparity.core")
    assert not borrowed, f"{path.name} imports in-house code {sorted(borrowed)}; allowed: {MODEL}"


JUDGES = ("measure/metrics.py", "measure/contact_metrics.py", "measure/divergence.py", "measure/invariants.py",
          "measure/joint_motion_metrics.py", "execute/ik_runner.py") + tuple(f"invariance/{p.name}" for p in sorted((ROOT / "comparisons" /
                                                                                  "invariance").glob("*.py")))
"""The comparisons that measure and judge (the metamorphic ones included: a transform computed with core's
rotations would agree with a bug in them): like a reference, they must not use the code they judge."""


@pytest.mark.parametrize("name", JUDGES)
def test_metrics_use_no_in_house_method(name):
    """A metric computed with core's rotations would agree with a bug in them."""
    path = ROOT / "comparisons" / name
    borrowed = {n for n in _project_modules(_imports(path)) if n.startswith("simparity.core") and not _data_model(n)}
    borrowed.discard("simparity.core")
    assert not borrowed, f"{name} imports in-house code {sorted(borrowed)}; allowed: {MODEL}"


@pytest.mark.parametrize("path", sorted((ROOT / "core" / "model").rglob("*.py")), ids=lambda p: p.name)
def test_the_data_model_imports_no_in_house_method(path):
    """The data model references may use stays free of core's methods, so the contract above is not bypassed."""
    used = {n for n in _project_modules(_imports(path)) if n != "simparity.core"}
    assert all(_data_model(n) for n in used), f"{path.name} imports {sorted(used)}"


@pytest.mark.parametrize("alias", sorted(PUBLIC_ALIASES))
def test_the_public_aliases_re_export_the_data_model_alone(alias):
    """``simparity.core.engine`` and the other paths plugins import are the data model under another name: each a
    one-line re-export (one per module for ``core.scene``, whose types are a folder), named in docs/plugins.md."""
    path = (ROOT / Path(*alias.split(".")[1:])).with_suffix(".py")
    used = _project_modules(_imports(path)) - {"simparity.core"}
    assert used and all(n.startswith(MODEL + ".") for n in used), f"{alias} imports {sorted(used)}"
    body = ast.parse(path.read_text(encoding="utf-8")).body
    code = [node for node in body if not (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant))]
    assert code and all(isinstance(node, ast.ImportFrom) and [a.name for a in node.names] == ["*"] for node in code), (
        f"{alias} is more than re-exports `from {MODEL}.… import *`")
    assert f"`{alias}`" in (ROOT / "docs" / "plugins.md").read_text(encoding="utf-8"), (
        f"docs/plugins.md does not name {alias}, a path plugins import")


@pytest.mark.parametrize("layer", LAYERS)
def test_the_project_imports_the_data_model_by_its_own_path(layer):
    """The aliases are for users' code: inside simparity one path per module, so a search finds every use."""
    for path in _modules(layer):
        if path.with_suffix("").relative_to(ROOT).as_posix().replace("/", ".") in {
                a.removeprefix("simparity.") for a in PUBLIC_ALIASES}:
            continue
        aliases = sorted(_imports(path) & PUBLIC_ALIASES)
        assert not aliases, f"{path.relative_to(ROOT)} imports {aliases}; inside simparity: {MODEL}"


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
    borrowed = {n for n in _project_modules(_imports(path)) - {"simparity.core"} if not _data_model(n)}
    assert not borrowed, f"{path.name} imports {sorted(borrowed)}; allowed: {MODEL} and its public aliases"


COMPARISONS = "simparity.comparisons"

FOLDER_IMPORTS = {
    "common": set(),
    "measure": {"common"},
    "engines": {"common"},
    "scenes": {"common", "engines"},
    "execute": {"common", "engines", "measure"},
    "invariance": {"common", "engines", "execute", "measure"},
    "gate": {"common", "engines", "scenes"},
    "pipeline": {"common", "engines", "execute", "gate", "invariance", "measure", "scenes"},
    "bench": {"common", "engines", "execute", "gate", "invariance", "measure", "pipeline", "scenes"},
    "cli": {"bench", "common", "engines", "execute", "gate", "invariance", "measure", "pipeline", "scenes"},
}
"""Which folder of comparisons/ may import which, bottom up: ``common/`` (the names every folder shares) under
everything; the measuring, the engines and the scenes under the execution; the pipeline (``Session``) above the folders
it orchestrates; the bench (``simparity bench``, which times every folder's work) above them; the CLI on top. A folder may
import itself; the modules at comparisons/'s top (the public API) may import every folder. One way only: no folder is in the set of a folder it may import."""

def _folder_of(name: str) -> str | None:
    """The comparisons folder a dotted module name is in (None: not in a folder of comparisons)."""
    parts = name.split(".")
    if parts[:2] != COMPARISONS.split(".") or len(parts) < 3:
        return None
    return parts[2] if (ROOT / "comparisons" / parts[2]).is_dir() else None


def _folder_violations(relative: str, imported: set[str]) -> list[str]:
    """The comparisons folders a module at ``relative`` (its path inside comparisons/) importing ``imported`` imports
    against :data:`FOLDER_IMPORTS`."""
    parts = relative.split("/")
    if len(parts) < 2:
        return []
    used = {_folder_of(n) for n in imported} - {None, parts[0]}
    return sorted(f for f in used if f not in FOLDER_IMPORTS[parts[0]])


def test_the_folder_table_names_every_folder_and_is_one_way():
    """A new folder takes its place in the table before it imports anything; the table itself has no cycle."""
    folders = {p.name for p in (ROOT / "comparisons").iterdir() if p.is_dir() and (p / "__init__.py").is_file()}
    assert folders == set(FOLDER_IMPORTS), f"folders {sorted(folders ^ set(FOLDER_IMPORTS))} in one of the folders " \
                                           "and the table only"
    for folder, allowed in FOLDER_IMPORTS.items():
        assert folder not in allowed
        assert not [other for other in allowed if folder in FOLDER_IMPORTS[other]], f"{folder} both ways"


@pytest.mark.parametrize("path", [p for p in _modules("comparisons") if len(p.relative_to(ROOT / "comparisons").parts) > 1],
                         ids=lambda p: p.relative_to(ROOT / "comparisons").as_posix())
def test_comparisons_folders_import_one_way(path):
    """Each folder imports only the folders below it (:data:`FOLDER_IMPORTS`), inside functions too."""
    relative = path.relative_to(ROOT / "comparisons").as_posix()
    bad = _folder_violations(relative, _imports(path))
    assert not bad, f"comparisons/{relative} imports comparisons/{bad}; allowed: {sorted(FOLDER_IMPORTS[relative.split('/')[0]])}"


def test_a_function_level_import_against_the_table_fails(tmp_path):
    """The check sees an import inside a function (the way a cycle used to be dodged), not only a module's head."""
    planted = tmp_path / "planted.py"
    planted.write_text("def f():\n    from simparity.comparisons.execute.runner import DEFAULT_REPEATS\n"
                       "    return DEFAULT_REPEATS\n", encoding="utf-8")
    assert _folder_violations("measure/planted.py", _imports(planted)) == ["execute"]
    assert _folder_violations("invariance/planted.py", _imports(planted)) == []
