"""A scene file, read and checked: its ``[scene]`` table (name, kind, reference, unit, suites), the tables its
kind allows handed to that kind's module, and the variants of a ``[sweep]``."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from simparity.comparisons.engines.registry import ENGINE_NAMES, EngineSet
from simparity.comparisons.scenes.limits import DEFAULT_LIMITS, Limits
from simparity.comparisons.scenes.loading.dynamics import read_dynamics
from simparity.comparisons.scenes.loading.ik import read_ik
from simparity.comparisons.scenes.loading.joint_dynamics import read_joint_dynamics
from simparity.comparisons.scenes.loading.joint_motion import read_joint_motion
from simparity.comparisons.scenes.loading.kinematics import read_kinematics
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.comparisons.scenes.loading.reference import check_reference
from simparity.comparisons.scenes.sweep import SWEEP_TABLE, read_sweep
from simparity.core.model.errors import SceneError
from simparity.core.model.files import read_toml
from simparity.core.model.scenes.kinds import Scene
from simparity.core.model.scenes.suites import SUITES

LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "ft": 0.3048, "in": 0.0254}
"""Units a scene may declare for lengths, and their size in metres."""

KINDS = ("dynamics", "kinematics", "ik", "joint_dynamics", "joint_motion")
"""The kinds of scene a file may declare: each read by ``read_<kind>`` in this folder's module of its name."""
_TOP = ("scene", "world", "body", "simulation", "plane", "contact", "chain", "sampling", "targets", "initial", "drive")
_PARTS = {"dynamics": ("world", "body", "simulation", "plane", "contact"), "kinematics": ("chain", "sampling"),
          "ik": ("chain", "targets"), "joint_dynamics": ("chain", "world", "sampling"),
          "joint_motion": ("chain", "world", "initial", "drive", "simulation", "plane", "contact")}
_SCENE = ("name", "description", "kind", "reference", "length_unit", "suites")


def parse_scene(data: dict, source: str = "<scene>", limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None):
    """Build a scene from parsed TOML ``data``; ``source`` names it in error messages. Data with a ``[sweep]``
    is several scenes: :func:`parse_scenes`."""
    if SWEEP_TABLE in data:
        raise SceneError(source, SWEEP_TABLE, "the file sweeps keys: it is several scenes, not one",
                         "load_scenes or parse_scenes (comparisons.scenes.loading.scene_file), library.load, "
                         "simparity.load_scenes or simparity run FILE, which expand it into its variants")
    try:
        return _parse(data, source, limits, engines or EngineSet())
    except SceneError as err:
        if err.source != "<code>":
            raise
        # raised by the data model itself (core.model.scenes): name the file it came from
        raise SceneError(source, err.key, err.problem, err.allowed) from None


def _parse(data: dict, source: str, limits: Limits, engines: EngineSet):
    top = TableReader(source, data, "", _TOP, 1.0, limits)
    s = top.subtable("scene", _SCENE)
    unit = s.string("length_unit", "m", choices=tuple(LENGTH_UNITS))
    kind = s.string("kind", choices=KINDS)
    head = dict(
        name=s.name("name"), description=s.text("description", ""),
        reference=s.string("reference", choices=ENGINE_NAMES), source=source,
        suites=s.strings("suites", SUITES, "there is no suite {}") if s.has("suites") else ("default",),
    )
    top.scale = LENGTH_UNITS[unit]
    for key in _TOP[1:]:
        if top.has(key) and key not in _PARTS[kind]:
            raise top.fail(key, f"not part of a {kind} scene", ", ".join(("scene",) + _PARTS[kind]))
    scene: Scene
    if kind == "dynamics":
        scene = read_dynamics(top, dict(head, length_unit=unit), engines)
    elif kind == "joint_motion":
        scene = read_joint_motion(top, head, engines)
    else:
        readers: dict[str, Callable[[TableReader, dict], Scene]] = {"kinematics": read_kinematics, "ik": read_ik,
                                                                  "joint_dynamics": read_joint_dynamics}
        scene = readers[kind](top, head)
    check_reference(top, scene, engines)
    return scene


def parse_scenes(data: dict, source: str = "<scene>", limits: Limits = DEFAULT_LIMITS,
                 engines: EngineSet | None = None) -> list:
    """The scenes of parsed TOML ``data``: the one it describes, or the variants of its ``[sweep]`` in the
    sweep's order. The file without its ``[sweep]`` must be a valid scene; each variant is checked like a file
    written by hand with its values, and an error in one names the sweep key and value
    (:meth:`comparisons.scenes.sweep.Sweep.refusal`)."""
    if SWEEP_TABLE not in data:
        return [parse_scene(data, source, limits, engines)]
    engines = engines or EngineSet()  # one for every variant: a plugin or a reference is asked once
    base_data = {key: value for key, value in data.items() if key != SWEEP_TABLE}
    base = parse_scene(base_data, source, limits, engines)
    sweep = read_sweep(data[SWEEP_TABLE], base_data, source, base.name)
    scenes = []
    for name, variant, point in sweep.variants(base_data):
        try:
            scene = parse_scene(variant, source, limits, engines)
        except SceneError as err:
            raise sweep.refusal(err, point) from None
        scenes.append(replace(scene, name=name, sweep=point))
    return scenes


def load_scenes(path: str | Path, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None) -> list:
    """Read and check one scene file (a regular file of at most ``limits.max_file_bytes``): its scene, or the
    variants of its ``[sweep]``."""
    source = str(path)
    return parse_scenes(read_toml(source, limits.max_file_bytes, "scene file"), source, limits, engines)


def load_scene(path: str | Path, limits: Limits = DEFAULT_LIMITS, engines: EngineSet | None = None):
    """Read and check one scene file without a ``[sweep]`` (a file with one: :func:`load_scenes`)."""
    source = str(path)
    return parse_scene(read_toml(source, limits.max_file_bytes, "scene file"), source, limits, engines)
