"""The engines simparity knows, by name, imported only when asked for: the built-ins, the installed plugins
(:mod:`comparisons.engines.plugins`), and any engine named by its spec ``module:attr``.

A built-in name wins over a plugin of the same name. Asking for a built-in never looks for plugins, and
nothing here raises for an engine that cannot run: it comes back as an engine standing in for it
(:mod:`comparisons.engines.placeholders`), whose rows say why.
"""

from __future__ import annotations

import functools
import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

from simparity.comparisons.engines.placeholders import NotAnEngine, UnavailableEngine
from simparity.comparisons.engines.plugins import discover, is_spec, load_engine
from simparity.core.model.engine import Engine
from simparity.core.model.errors import UnknownEngineError, one_line

if TYPE_CHECKING:
    from simparity.comparisons.engines.probe import EngineProbes

_ENGINES = {
    "core": ("simparity.core.inhouse", "InHouseEngine"),
    "analytic": ("simparity.references.analytic.engine", "AnalyticEngine"),
    "mujoco": ("simparity.references.mujoco.adapter", "MujocoEngine"),
    "pybullet": ("simparity.references.pybullet.adapter", "PybulletEngine"),
    "pinocchio": ("simparity.references.pinocchio.adapter", "PinocchioEngine"),
    "tight": ("simparity.references.analytic.tight", "TightSolveEngine"),
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
    when it cannot run (:mod:`comparisons.engines.placeholders`)."""
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


def describe_engines(names, scenes=(), probes: EngineProbes | None = None) -> list[Engine]:
    """The engines called ``names`` as simparity itself may hold them: a built-in built here, a plugin or spec
    described by a process of its own, asked about ``scenes`` (:mod:`comparisons.engines.probe`): a user's code
    never runs in this process, so one that crashes or hangs there cannot take simparity down. ``probes``: the
    command's kept probes, asked again (None: a probe per engine, ended here)."""
    from simparity.comparisons.engines.probe import probe_engines  # it starts processes: only when asked

    names = check_engine_names(names)
    outside = [n for n in names if n not in _ENGINES]
    probed = (probes.describe if probes is not None else probe_engines)(outside, scenes) if outside else {}
    return [probed[n] if n in probed else make_engine(n) for n in names]


@dataclass(frozen=True)
class EngineSet:
    """The engines a command uses (``--engines``: names, installed plugins, ``module:attr`` specs): what a scene
    file may name as integrators, and what the quick profile runs. Each command, API call or fixture has its
    own; nothing of one reaches the next."""

    names: tuple[str, ...] = ()

    @property
    def users(self) -> tuple[str, ...]:
        """The user's engines among :attr:`names` (not built-in)."""
        return tuple(n for n in dict.fromkeys(self.names) if n not in _ENGINES)

    @functools.cached_property
    def probes(self) -> EngineProbes:
        """The probes of this set's outside engines, kept to be asked again (each question a process less)."""
        from simparity.comparisons.engines.probe import EngineProbes  # it imports this module

        return EngineProbes()

    def describe(self, names, scenes=()) -> list[Engine]:
        """:func:`describe_engines` by this set's :attr:`probes`."""
        return describe_engines(names, scenes, self.probes)

    @functools.cached_property
    def _users_described(self) -> list[Engine]:
        return self.describe(self.users) if self.users else []

    @functools.cached_property
    def _described(self) -> list[Engine]:
        return list(_built_ins()) + self._users_described

    def refuse_non_engines(self) -> None:
        """Raise UnknownEngineError, before anything runs, when one of the user's engines names no engine at all
        (:class:`~comparisons.engines.placeholders.NotAnEngine`: ``os:path``, ``json:dumps``, a class that is not an
        Engine, an attribute the module lacks); a user's engine whose own code fails still runs, its rows failed.
        Only the user's engines are described for it (each in a process of its own), once per set."""
        mistakes = [engine for engine in self._users_described if isinstance(engine, NotAnEngine)]
        if mistakes:
            raise UnknownEngineError(f"--engines: {one_line(mistakes[0].mistake)}")

    @functools.cached_property
    def _references(self) -> dict[str, Engine]:
        return {}

    def reference(self, name: str) -> Engine:
        """The built-in engine ``name`` built here, once per set (a scene's reference, asked what it supports)."""
        if name not in self._references:
            self._references[name] = make_engine(name)
        return self._references[name]

    @property
    def integrators(self) -> tuple[str, ...]:
        """Every integrator name the built-ins and the user's engines offer; an engine that cannot run offers
        none. Installed plugins the command does not name are not asked (each is a process of its own, up to a
        minute for a slow one): see :attr:`installed_integrators`."""
        return _integrator_names(self._described)

    @property
    def joint_motion_integrators(self) -> tuple[str, ...]:
        """Every joint-motion integrator name the built-ins and the user's engines offer."""
        names: dict[str, None] = {}
        for engine in self._described:
            names.update(dict.fromkeys(getattr(engine, "joint_motion_integrators", tuple)()))
        return tuple(names)

    @functools.cached_property
    def installed_integrators(self) -> tuple[str, ...]:
        """:attr:`integrators` and every installed plugin's, for a scene file that names an integrator the
        command's engines do not offer. The user's engines answer as described already; the other plugins are
        described once, in probes ended here (nothing of them is asked again)."""
        names = check_engine_names(ENGINE_NAMES + plugin_names() + self.users)
        described = dict(zip(self.users, self._users_described))
        others = [name for name in names if name not in described]
        described.update(zip(others, describe_engines(others)))
        return _integrator_names([described[name] for name in names])

    @property
    def other_variants(self) -> frozenset[str]:
        """The integrators that are a further variant of a scheme (:meth:`Engine.integrator_variant`): all of a
        scheme's variants but the first its engine lists (core's ``rk4+matrix`` and ``rk4+expmap``, not ``rk4``)."""
        found = set()
        for engine in self._described:
            first: dict[str, str] = {}
            for integrator in engine.integrators():
                scheme, variant = engine.integrator_variant(integrator)
                if variant and first.setdefault(scheme, integrator) != integrator:
                    found.add(integrator)
        return frozenset(found)


@functools.lru_cache(maxsize=1)
def _built_ins() -> tuple[Engine, ...]:
    """The built-in engines, built once: what they offer never changes within a process."""
    return tuple(make_engine(name) for name in ENGINE_NAMES)


def _integrator_names(engines: list[Engine]) -> tuple[str, ...]:
    names = {}
    for engine in engines:
        names.update(dict.fromkeys(engine.integrators()))
    return tuple(names)
