"""A user's engine described without running its code in simparity itself.

A plugin's or spec's import, constructor, ``version()``, ``integrators()`` and the rest of what an
engine says of itself run in a child process (this module's :func:`main`, forked from the zygote of
:mod:`comparisons.common.zygote`, or ``python -m simparity.comparisons.engines.probe`` when none answers) with a
time limit (:data:`PROBE_SECONDS`) and a memory limit (:data:`PROBE_MEMORY_BYTES`). An engine that
segfaults, exits, hangs or grows without bound there becomes a
:class:`~comparisons.engines.placeholders.BrokenEngine` naming the cause, and simparity goes on. What it
answered comes back as a :class:`DescribedEngine`: its answers as data, all that ``simparity run``
needs to plan its cases and ``simparity engines`` to list it. The cases themselves build the real
engine in their worker (:mod:`comparisons.execute.case_worker`).
"""

from __future__ import annotations

import faulthandler
import os
import pickle
import signal
import sys
import tempfile
import time
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np

from simparity.comparisons.common.scene_hash import scene_hash
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.common import zygote
from simparity.comparisons.common.processes import death_cause, status_bytes
from simparity.comparisons.engines.placeholders import BrokenEngine, StandInEngine
from simparity.comparisons.common.error_text import error_text
from simparity.core.model.engine import Engine, KinematicsModel, Simulation, Support
from simparity.core.model.errors import PluginError, one_line
from simparity.core.runtime.processes import die_with_parent, kill_group
from simparity.core.model.scenes.chain import Chain, Joint

PROBE = "simparity.comparisons.engines.probe"
"""This module, as its process is started (``python -m``, or forked from :mod:`comparisons.common.zygote`)."""

PROBE_SECONDS = 60.0
"""Time limit [s] to import, build and describe one engine: MuJoCo takes ~0.3 s, a plugin that loads a large
library (torch) ~10 s from a cold disk; one still going after a minute is hung."""

PROBE_MEMORY_BYTES = 4 * 1024 ** 3
"""Memory limit [bytes] of a probe (or 80 % of the machine, if less): a process with every built-in engine
loaded holds ~250 MiB; building an engine's description needs no scene's worth of memory."""

POLL_SECONDS = 0.05
"""How often a probe's time and memory are looked at."""

ANSWER_LENGTH = 8
"""Bytes of the length (little-endian) before each pickled answer of a probe."""

PROBE_CHAIN = Chain("probe", (Joint("joint", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3)),),
                    end_effector_xyz=np.array([1.0, 0.0, 0.0]))
"""One revolute joint about z and a 1 m link: the chain an engine's kinematics support is asked about."""


@dataclass(frozen=True)
class EngineDescription:
    """What an engine says of itself, as data.

    Attributes
    ----------
    name, version : str
    integrators, ik_solvers : tuple of str
    orders : dict of str to int or None
        ``theoretical_order`` of each integrator.
    stages : dict of str to int or None
        ``stages`` of each integrator.
    variants : dict of str to (str, str)
        ``integrator_variant`` of each integrator.
    kinematics : str
        ``yes`` or ``no`` (its support of :data:`PROBE_CHAIN`), or ``unknown (<error>)``.
    scene_integrators : dict of str to tuple of str or str
        ``scene_integrators`` of each scene asked about, by :func:`~comparisons.common.scene_hash.scene_hash`; the error
        text where it raised.
    joint_dynamics_methods, joint_motion_integrators : tuple of str
        (``orders``, ``stages`` and ``variants`` cover the joint-motion integrators too.)
    """

    name: str
    version: str
    integrators: tuple[str, ...]
    ik_solvers: tuple[str, ...]
    orders: dict[str, int | None]
    stages: dict[str, int | None]
    variants: dict[str, tuple[str, str]]
    kinematics: str
    scene_integrators: dict[str, tuple[str, ...] | str] = field(default_factory=dict)
    joint_dynamics_methods: tuple[str, ...] = ()
    joint_motion_integrators: tuple[str, ...] = ()


class DescribedEngine(Engine):
    """An engine known by its :class:`EngineDescription` only: it answers what the description holds and runs
    nothing (its cases build the real engine in a worker)."""

    def __init__(self, description: EngineDescription) -> None:
        self.description = description
        self.name = description.name

    def version(self) -> str:
        return self.description.version

    def integrators(self) -> tuple[str, ...]:
        return self.description.integrators

    def ik_solvers(self) -> tuple[str, ...]:
        return self.description.ik_solvers

    def joint_dynamics_methods(self) -> tuple[str, ...]:
        return self.description.joint_dynamics_methods

    def joint_motion_integrators(self) -> tuple[str, ...]:
        return self.description.joint_motion_integrators

    def theoretical_order(self, integrator: str) -> int | None:
        return self.description.orders.get(integrator)

    def stages(self, integrator: str) -> int | None:
        return self.description.stages.get(integrator)

    def integrator_variant(self, integrator: str) -> tuple[str, str]:
        return self.description.variants.get(integrator, (integrator, ""))

    def scene_integrators(self, scene) -> tuple[str, ...]:
        found = self.description.scene_integrators.get(scene_hash(scene))
        if found is None:
            raise PluginError(f"{self.name} was not asked about scene {scene.name} (a harness bug)")
        if isinstance(found, str):
            raise PluginError(found)
        return found

    def supports_kinematics(self, chain) -> Support:
        if chain is not PROBE_CHAIN:
            raise PluginError(f"{self.name} is described, not built: only its worker can answer for {chain.name}")
        if self.description.kinematics == "yes":
            return Support.yes()
        return Support.no(self.description.kinematics)

    def supports_dynamics(self, scene, integrator: str) -> Support:
        raise PluginError(f"{self.name} is described, not built: its cases run in a worker")

    def build_dynamics(self, scene, integrator: str, dt: float) -> Simulation:
        raise PluginError(f"{self.name} is described, not built: its cases run in a worker")

    def build_kinematics(self, chain) -> KinematicsModel:
        raise PluginError(f"{self.name} is described, not built: its cases run in a worker")


def describe(engine: Engine, scenes: list) -> EngineDescription:
    """The description of a built engine, asked about ``scenes`` (an engine that loaded passed the interface
    checks of :func:`~comparisons.engines.plugins.load_engine`, so only ``scene_integrators`` and kinematics support
    may still raise)."""
    integrators = engine.integrators()
    every = tuple(dict.fromkeys(integrators + tuple(engine.joint_motion_integrators())))
    kinematics = "unknown"
    try:
        kinematics = "yes" if engine.supports_kinematics(PROBE_CHAIN).ok else "no"
    except Exception as err:  # noqa: BLE001 - a user's engine: say what it raised
        kinematics = f"unknown ({one_line(error_text(err))})"
    by_scene: dict[str, tuple[str, ...] | str] = {}
    for scene in scenes:
        try:
            by_scene[scene_hash(scene)] = tuple(engine.scene_integrators(scene))
        except Exception as err:  # noqa: BLE001 - its case in that scene fails with the error
            by_scene[scene_hash(scene)] = f"scene_integrators({scene.name}) raised {one_line(error_text(err))}"
    return EngineDescription(engine.name, engine.version(), integrators, engine.ik_solvers(),
                             {i: engine.theoretical_order(i) for i in every},
                             {i: engine.stages(i) for i in every},
                             {i: engine.integrator_variant(i) for i in every}, kinematics, by_scene,
                             engine.joint_dynamics_methods(), tuple(engine.joint_motion_integrators()))


def probe_engines(names: list[str], scenes: Sequence = ()) -> dict[str, Engine]:
    """Each of ``names`` (a plugin's name or a spec ``module:attr``) described in a process of its own, all at
    once: a :class:`DescribedEngine`, or a :class:`BrokenEngine` standing in for one that cannot run, naming
    what went wrong: it does not import, an error, a crash, a hang, a memory blow-up. One question: its
    processes end here (:class:`EngineProbes` keeps them to be asked again)."""
    probes = EngineProbes()
    try:
        return probes.describe(names, scenes)
    finally:
        probes.close()


class EngineProbes:
    """The probes of one command's outside engines, each process kept to be asked again: a run asks its engines
    what they offer (a scene file's integrators), then about its scenes, then about its transformed scenes, and a
    probe costs a process forked from the zygote and the engine's imports (up to a minute). Each question is
    what a new probe would answer (:func:`describe` of the engine it built, under the same time and memory
    limits); an engine that cannot run keeps its stand-in, asked nothing more. The processes end with
    :meth:`close`, or when this object is collected."""

    def __init__(self) -> None:
        self._live: dict[str, _Probe] = {}
        self._final: dict[str, Engine] = {}
        weakref.finalize(self, _close_all, self._live, os.getpid())

    def describe(self, names: Sequence[str], scenes: Sequence = ()) -> dict[str, Engine]:
        """:func:`probe_engines` of ``names`` asked about ``scenes``, each by its kept probe (a new one for a name
        not asked before, or whose process ended)."""
        asking = [name for name in dict.fromkeys(names) if name not in self._final]
        for name in asking:
            if name in self._live and self._live[name].process.poll() is None:
                self._live[name].ask(list(scenes))
            else:  # not asked before, or its process ended while it waited (a new probe answers as it would have)
                if name in self._live:
                    self._live.pop(name).close()
                self._live[name] = _Probe(name, list(scenes))
        deadline = time.monotonic() + PROBE_SECONDS
        while any(self._live[name].working() for name in asking):
            for name in asking:
                if self._live[name].working():
                    self._live[name].enforce(deadline)
            time.sleep(POLL_SECONDS)
        answers = {name: self._live[name].result() for name in asking}
        for name, answer in answers.items():
            if not isinstance(answer, DescribedEngine):  # what a new probe would answer again: no process kept
                self._final[name] = answer
                self._live.pop(name).close()
        return {name: answers[name] if name in answers else self._final[name] for name in names}

    def close(self) -> None:
        """End every kept probe."""
        _close_all(self._live, os.getpid())


def _close_all(probes: dict[str, "_Probe"], owner: int) -> None:
    """End ``probes``, in the process ``owner`` (a pid) that started them only (not in a child forked from it)."""
    if os.getpid() == owner:
        while probes:
            probes.popitem()[1].close()


def asked_about(engines: Sequence[Engine], scenes: Sequence, specs: dict[str, str] | None,
                probes: EngineProbes) -> list[Engine]:
    """``engines`` with every :class:`DescribedEngine` also asked about those of ``scenes`` its description does
    not hold (a run's transformed and one-ulp perturbed scenes, made after the engines were described) by its
    probe in ``probes`` (:meth:`EngineProbes.describe`), all at once. ``specs`` maps an engine's name to what
    it is built from, when that is not its name. A probe that cannot answer (a crash, a hang) leaves its error
    as each new scene's answer: those cases fail with it. Other engines are returned as they are."""
    hashes = {scene_hash(scene): scene for scene in scenes}
    asking = {engine.name: [h for h in hashes if h not in engine.description.scene_integrators]
              for engine in engines if isinstance(engine, DescribedEngine)}
    asking = {name: missing for name, missing in asking.items() if missing}
    if not asking:
        return list(engines)
    spec_of = {name: (specs or {}).get(name, name) for name in asking}
    probed = probes.describe(list(spec_of.values()), [hashes[h] for h in dict.fromkeys(sum(asking.values(), []))])
    out: list[Engine] = []
    for engine in engines:
        if engine.name not in asking:
            out.append(engine)
            continue
        assert isinstance(engine, DescribedEngine)  # only described engines are asked
        answer = probed[spec_of[engine.name]]
        found = (answer.description.scene_integrators if isinstance(answer, DescribedEngine) else
                 {h: f"asking it about scene {hashes[h].name}: {cast(StandInEngine, answer).reason}"
                  for h in asking[engine.name]})
        scene_integrators = {**engine.description.scene_integrators,
                             **{h: found[h] for h in asking[engine.name] if h in found}}
        out.append(DescribedEngine(replace(engine.description, scene_integrators=scene_integrators)))
    return out


def _memory_limit() -> int:
    physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    return min(PROBE_MEMORY_BYTES, int(0.8 * physical))


class _Probe:
    """One probe process: its questions (pickled lists of scenes, on its standard input, after the engine's name),
    the pipe it answers each on (:data:`ANSWER_LENGTH` bytes of length, then the pickled answer), its standard error
    (an anonymous file), why it was stopped ("" if not). A killed run leaves no file."""

    def __init__(self, name: str, scenes: list) -> None:
        self.name = name
        self.stderr = tempfile.TemporaryFile()
        answers, child_end = os.pipe()
        child_reads, self.requests = os.pipe()
        try:
            self.process = zygote.start(PROBE, child_reads, self.stderr, (child_end,))
        finally:
            os.close(child_end)
            os.close(child_reads)
        os.set_blocking(answers, False)
        self.answers = answers
        os.set_blocking(self.requests, False)  # written without blocking: a request may outgrow the pipe
        self._send((name, scenes))

    def ask(self, scenes: list) -> None:
        """Ask the probe about ``scenes``, once it answered its last question."""
        self._send(scenes)

    def _send(self, request: object) -> None:
        self.received, self.stopped, self.errors_from = b"", "", os.fstat(self.stderr.fileno()).st_size
        self.unsent = memoryview(pickle.dumps(request))

    def _feed(self) -> None:
        """Write what the pipe takes of the request not yet sent."""
        try:
            while self.unsent:
                self.unsent = self.unsent[os.write(self.requests, self.unsent):]
        except (BlockingIOError, BrokenPipeError):  # full: the probe reads it as it goes; it died: result() says how
            pass

    def answered(self) -> bool:
        """Whether the whole answer to the last question came (what came is read)."""
        try:
            while chunk := os.read(self.answers, 1 << 16):
                self.received += chunk
        except BlockingIOError:
            pass
        head = self.received[:ANSWER_LENGTH]
        return len(head) == ANSWER_LENGTH and len(self.received) >= ANSWER_LENGTH + int.from_bytes(head, "little")

    def working(self) -> bool:
        """Whether the probe is still answering: not stopped, not answered, alive."""
        self._feed()
        return not self.stopped and not self.answered() and self.process.poll() is None

    def enforce(self, deadline: float) -> None:
        """Kill the probe if it is past the deadline or its memory limit."""
        if time.monotonic() > deadline:
            self.stopped = (f"hung: building and describing it took more than {PROBE_SECONDS:g} s; the process was "
                            "killed")
        elif (status_bytes("VmRSS", self.process.pid) or 0) > _memory_limit():
            self.stopped = (f"out of memory: building and describing it went past the limit of "
                            f"{_memory_limit() / 1024 ** 3:.3g} GiB; the process was killed")
        if self.stopped:
            self.kill()

    def kill(self) -> None:
        kill_group(self.process.pid)
        self.process.wait()

    def result(self) -> Engine:
        """The answer to the last question, once the probe is no longer :meth:`working`."""
        if not self.stopped and self.answered():
            kind, value = pickle.loads(self.received[ANSWER_LENGTH:])
            if kind == "described":
                return DescribedEngine(value)
            return value
        if not self.stopped:
            code = self.process.wait()
            errors = os.pread(self.stderr.fileno(), 64 * 1024, max(self.errors_from,
                                                                   os.fstat(self.stderr.fileno()).st_size - 64 * 1024))
            self.stopped = death_cause(code, errors.decode("utf-8", "replace"), "the process building it")
        return BrokenEngine(self.name, self.stopped)

    def close(self) -> None:
        if self.process.poll() is None:
            self.kill()
        os.close(self.requests)
        self.stderr.close()
        os.close(self.answers)


def main(argv: list[str]) -> int:
    """The probe process: build the engine its standard input names, write its description (or stand-in) to the
    descriptor ``argv[1]``; ``argv[2]`` is the parent's pid. A described engine is then asked about each further list
    of scenes its standard input gives, until it closes."""
    die_with_parent(int(argv[2]))
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    faulthandler.enable()
    name, scenes = pickle.load(sys.stdin.buffer)
    engine = make_engine(name)
    with os.fdopen(int(argv[1]), "wb") as answers:
        while True:
            answer = _answer(engine, name, scenes)
            data = pickle.dumps(answer)
            answers.write(len(data).to_bytes(ANSWER_LENGTH, "little") + data)
            answers.flush()
            if answer[0] != "described":
                break
            try:
                scenes = pickle.load(sys.stdin.buffer)
            except EOFError:
                break
    os._exit(0)  # no interpreter shutdown: a user's atexit or finaliser cannot change the answer


def _answer(engine: Engine, name: str, scenes: list) -> tuple[str, object]:
    """What the probe answers of ``engine`` (built from ``name``) asked about ``scenes``: ("described",
    EngineDescription) or ("stand-in", the engine standing in for it)."""
    if isinstance(engine, StandInEngine):
        return "stand-in", engine
    try:
        return "described", describe(engine, scenes)
    except (Exception, SystemExit) as err:  # noqa: BLE001 - a user's code
        return "stand-in", BrokenEngine(name, f"describing it raised {one_line(error_text(err))}")


if __name__ == "__main__":  # run by its package name, so what it pickles names simparity's module, not __main__
    from simparity.comparisons.engines import probe as engine_probe

    sys.exit(engine_probe.main(sys.argv))
