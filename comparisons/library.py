"""The built-in scene library (``comparisons/scenes/*.toml``) and scene lookup by name or path."""

from __future__ import annotations

from pathlib import Path

from simparity.comparisons.scene_limits import DEFAULT_LIMITS, Limits
from simparity.comparisons.scene_loader import load_scene
from simparity.core.errors import UnknownSceneError, one_line
from simparity.core.files import file_problem
from simparity.core.scene import SUITES

SCENES_DIR = Path(__file__).parent / "scenes"


def builtin_paths() -> dict[str, Path]:
    """Built-in scene name -> file, sorted by name."""
    return {p.stem: p for p in sorted(SCENES_DIR.glob("*.toml"))}


def resolve(name_or_path: str) -> Path:
    """The file of a built-in scene name, or an existing scene file path."""
    builtin = builtin_paths()
    if name_or_path in builtin:
        return builtin[name_or_path]
    problem = file_problem(name_or_path, "scene file")
    if problem is None:
        return Path(name_or_path)
    where = "" if problem.startswith("no such") else f" ({problem})"
    raise UnknownSceneError(
        f"'{one_line(name_or_path)}' is neither a built-in scene nor a scene file{where} "
        f"(allowed: {', '.join(builtin)}, or the path of a regular TOML file; see 'simparity list')"
    )


def suite(name: str, limits: Limits = DEFAULT_LIMITS) -> list:
    """The built-in scenes of suite ``name`` (:data:`core.scene.SUITES`), loaded, sorted by name."""
    if name not in SUITES:
        raise UnknownSceneError(f"--suite {one_line(name)}: there is no such suite (allowed: {', '.join(SUITES)})")
    return [scene for scene in load(list(builtin_paths().values()), limits) if name in scene.suites]


def load(names_or_paths, limits: Limits = DEFAULT_LIMITS) -> list:
    """Every named scene, all checked before any is returned (so a run never starts on a bad file)."""
    return [load_scene(resolve(n), limits) for n in names_or_paths]
