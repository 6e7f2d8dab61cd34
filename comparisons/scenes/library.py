"""The built-in scene library (``comparisons/scenes/*.toml``) and scene lookup by name or path; a file with a
``[sweep]`` gives its variants, in the sweep's order."""

from __future__ import annotations

from pathlib import Path

from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.scenes.limits import DEFAULT_LIMITS, Limits
from simparity.comparisons.scenes.loader import load_scenes
from simparity.comparisons.scenes.sweep import SWEEP_TABLE
from simparity.core.model.errors import UnknownSceneError, one_line
from simparity.core.model.files import file_problem, read_toml
from simparity.core.model.scene import SUITES

SCENES_DIR = Path(__file__).parent


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


def _declared_suites(path: Path) -> list:
    """The suites a scene file names in ``[scene] suites`` (default ``["default"]``), read without
    loading the scene: a suite never depends on what the scenes outside it need."""
    head = read_toml(path, what="scene file").get("scene", {})
    return head.get("suites", ["default"]) if isinstance(head, dict) else []


def suite(name: str, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None) -> list:
    """The built-in scenes of suite ``name`` (:data:`core.scene.SUITES`), loaded, sorted by name."""
    if name not in SUITES:
        raise UnknownSceneError(f"--suite {one_line(name)}: there is no such suite (allowed: {', '.join(SUITES)})")
    members = [path for path in builtin_paths().values() if name in _declared_suites(path)]
    return load(members, limits, engines or EngineSet())


def _builtin_variant(name: str, limits: Limits, engines: EngineSet):
    """The variant named ``name`` (as ``simparity list`` shows it) of a built-in file with a ``[sweep]``, or None.
    Found by loading the built-in sweeps, never by reading values back from the name."""
    for path in builtin_paths().values():
        if SWEEP_TABLE in read_toml(path, what="scene file"):
            found = [scene for scene in load_scenes(path, limits, engines) if scene.name == name]
            if found:
                return found[0]
    return None


def load(names_or_paths, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None) -> list:
    """Every named scene, all checked before any is returned (so a run never starts on a bad file); a file
    with a ``[sweep]`` in its place gives its variants, in the sweep's order, and a built-in variant's name
    (``restitution-sweep_restitution-0.7``) that one variant."""
    engines = engines or EngineSet()  # one for the whole call: a plugin is asked once
    scenes = []
    for name in names_or_paths:
        try:
            scenes += load_scenes(resolve(name), limits, engines)
        except UnknownSceneError:
            variant = _builtin_variant(str(name), limits, engines)
            if variant is None:
                raise
            scenes.append(variant)
    return scenes
