"""The engines simparity knows, by name, imported only when asked for: the built-ins, the installed plugins
(:mod:`comparisons.plugins`), and any engine named by its spec ``module:attr``.

A built-in name wins over a plugin of the same name. Asking for a built-in never looks for plugins, and
nothing here raises for an engine that cannot run: it comes back as an engine standing in for it
(:mod:`comparisons.placeholder_engines`), whose rows say why.
"""

from __future__ import annotations

import functools
import importlib

from simparity.comparisons.placeholder_engines import UnavailableEngine
from simparity.comparisons.plugins import discover, is_spec, load_engine
from simparity.core.engine import Engine
from simparity.core.errors import UnknownEngineError, one_line

_ENGINES = {
    "core": ("simparity.core.inhouse", "InHouseEngine"),
    "analytic": ("simparity.references.analytic", "AnalyticEngine"),
    "mujoco": ("simparity.references.mujoco_adapter", "MujocoEngine"),
    "pybullet": ("simparity.references.pybullet_adapter", "PybulletEngine"),
    "pinocchio": ("simparity.references.pinocchio_adapter", "PinocchioEngine"),
    "tight": ("simparity.references.tight", "TightSolveEngine"),
}
ENGINE_NAMES = tuple(_ENGINES)
"""The built-in engines (a scene's reference is one of them)."""
DEFAULT_ENGINES = ("core", "analytic", "mujoco", "pybullet", "pinocchio")
"""What ``simparity run`` runs unless told otherwise; ``tight`` serves as a reference only."""


def plugin_names() -> tuple[str, ...]:
    """The installed plugins ``--engines`` can name (shadowed ones left out)."""
    return tuple(discover(ENGINE_NAMES).usable())


def allowed_engines() -> str:
    """What ``--engines`` takes, for messages and help: the built-ins, the installed plugins, a spec."""
    plugins = "".join(f", {name} (plugin)" for name in plugin_names())
    return f"{', '.join(ENGINE_NAMES)}{plugins}, or module:Class"


def check_engine_names(names) -> tuple[str, ...]:
    """The names, checked against the built-ins, the installed plugins and the spec form ``module:attr``
    (not imported here), duplicates dropped; raises UnknownEngineError."""
    unknown = [n for n in names if n not in _ENGINES and not is_spec(n)]
    if unknown:  # only now look for plugins: naming built-ins never does
        unknown = [n for n in unknown if n not in plugin_names()]
    if unknown:
        raise UnknownEngineError(f"unknown engine(s): {one_line(', '.join(unknown))} (allowed: {allowed_engines()}; "
                                 "'simparity engines' lists them)")
    if not names:
        raise UnknownEngineError(f"no engine named (allowed: {allowed_engines()})")
    return tuple(dict.fromkeys(names))


def make_engine(name: str) -> Engine:
    """The engine called ``name`` (a built-in, a plugin, or a spec ``module:attr``), or one standing in for it
    when it cannot run (:mod:`comparisons.placeholder_engines`)."""
    check_engine_names([name])
    if name in _ENGINES:
        module, cls = _ENGINES[name]
        try:
            return getattr(importlib.import_module(module), cls)()
        except ImportError as err:
            return UnavailableEngine(name, str(err))
    plugins = discover(ENGINE_NAMES).usable()
    if name in plugins:
        return load_engine(plugins[name].target, name)
    return load_engine(name, taken=frozenset(ENGINE_NAMES) | frozenset(plugins))


def describe_engines(names, scenes=()) -> list[Engine]:
    """The engines called ``names`` as simparity itself may hold them: a built-in built here, a plugin or spec
    described by a process of its own, asked about ``scenes`` (:mod:`comparisons.engine_probe`): a user's code
    never runs in this process, so one that crashes or hangs there cannot take simparity down."""
    from simparity.comparisons.engine_probe import probe_engines  # it starts processes: only when asked

    names = check_engine_names(names)
    outside = [n for n in names if n not in _ENGINES]
    probed = probe_engines(outside, scenes) if outside else {}
    return [probed[n] if n in probed else make_engine(n) for n in names]


_RUN_ENGINES: list[str] = []
"""The user's engines (installed plugins and ``module:attr`` specs) of the command running (:func:`use_engines`):
their integrators may be named in scene files, and the quick profile runs them."""


def use_engines(names) -> None:
    """Let the integrators of the user's engines among ``names`` (``--engines``; () for none) be named in scene
    files, instead of those of the command before."""
    users = [n for n in dict.fromkeys(names) if n not in _ENGINES]
    if users != _RUN_ENGINES:
        _RUN_ENGINES[:] = users
        known_integrators.cache_clear()
        installed_integrators.cache_clear()


@functools.lru_cache(maxsize=1)
def known_integrators() -> tuple[str, ...]:
    """Every integrator name the built-ins and the user's engines of this run offer. Cached; an engine that
    cannot run offers none. Installed plugins the run does not name are not asked (each is a process of its
    own, up to a minute for a slow one): see :func:`installed_integrators`."""
    return _integrator_names(ENGINE_NAMES + tuple(_RUN_ENGINES))


@functools.lru_cache(maxsize=1)
def installed_integrators() -> tuple[str, ...]:
    """:func:`known_integrators` and every installed plugin's, for a scene file that names an integrator the
    run's engines do not offer. Cached."""
    return _integrator_names(ENGINE_NAMES + plugin_names() + tuple(_RUN_ENGINES))


def _integrator_names(engines: tuple[str, ...]) -> tuple[str, ...]:
    names = {}
    for engine in describe_engines(engines):
        names.update(dict.fromkeys(engine.integrators()))
    return tuple(names)
