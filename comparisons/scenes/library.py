"""The built-in scene library (``comparisons/scenes/*.toml``) and scene lookup by name or path; a file with a
``[sweep]`` gives its variants, in the sweep's order."""

from __future__ import annotations

import difflib
import os
from pathlib import Path

from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.scenes.limits import DEFAULT_LIMITS, Limits
from simparity.comparisons.scenes.loading.scene_file import load_scenes
from simparity.comparisons.scenes.sweep import SWEEP_TABLE
from simparity.core.model.errors import UnknownSceneError, one_line
from simparity.core.model.files import file_problem, read_toml
from simparity.core.model.scenes.suites import SUITES

SCENES_DIR = Path(__file__).parent


def builtin_paths() -> dict[str, Path]:
    """Built-in scene name -> file, sorted by name."""
    return {p.stem: p for p in sorted(SCENES_DIR.glob("*.toml"), key=lambda p: p.stem)}


PATH_SUFFIXES = (".toml", ".urdf", ".xml")
"""Endings that make an argument a file's path, never a scene name (as does a path separator)."""
CLOSEST_NAMES = 3
"""Built-in names an unknown bare word is answered with, the closest first (not all ~40)."""
_ALLOWED = "a built-in scene name as 'simparity list' prints it, or the path of an existing scene file"


def looks_like_path(name_or_path: str) -> bool:
    """True when ``name_or_path`` is meant as a file: it holds a path separator or ends in .toml, .urdf or .xml."""
    has_separator = any(sep and sep in name_or_path for sep in ("/", os.sep, os.altsep))
    return has_separator or name_or_path.lower().endswith(PATH_SUFFIXES)


def _unknown(name_or_path: str, problem: str, names: list[str]) -> UnknownSceneError:
    """The one-line error for an argument that names no scene: a path that is missing or unusable says so
    (as resolved), a bare word gets the closest built-in names."""
    shown = one_line(name_or_path)
    if not problem.startswith("no such"):
        return UnknownSceneError(f"{shown}: {problem} (allowed: {_ALLOWED})")
    if looks_like_path(name_or_path):
        resolved = one_line(os.path.abspath(name_or_path))
        return UnknownSceneError(f"{shown}: the file {resolved} does not exist (allowed: {_ALLOWED})")
    closest = difflib.get_close_matches(name_or_path, names, n=CLOSEST_NAMES)
    hint = f"; closest: {', '.join(closest)}" if closest else ""
    return UnknownSceneError(f"'{shown}' is not a built-in scene or an existing file{hint} (allowed: {_ALLOWED})")


def resolve(name_or_path: str) -> Path:
    """The file of a built-in scene name, or an existing scene file path.

    Raises
    ------
    UnknownSceneError
        One line: for a path (:func:`looks_like_path`), that the file does not exist (or why it cannot be
        read); for a bare word, the closest built-in names.
    """
    builtin = builtin_paths()
    if name_or_path in builtin:
        return builtin[name_or_path]
    problem = file_problem(name_or_path, "scene file")
    if problem is None:
        return Path(name_or_path)
    raise _unknown(name_or_path, problem, list(builtin))


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
            variant = None if looks_like_path(str(name)) else _builtin_variant(str(name), limits, engines)
            if variant is None:
                raise
            scenes.append(variant)
    return scenes
