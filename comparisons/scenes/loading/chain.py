"""The ``[chain]`` every chain scene has: ``[[chain.joint]]``, a URDF file or a ``[chain.dh]`` table; and the
per-joint values chain scenes give (a number per joint in its unit, within its limits)."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from simparity.comparisons.scenes.limits import allowed_at_most
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.core.dh import chain_from_dh
from simparity.core.dynamics.inertia import LINK_TENSOR_RULE, link_tensor_problem
from simparity.core.model.errors import SceneError, echo, one_line
from simparity.core.model.files import file_problem
from simparity.core.model.ranges import RANGES
from simparity.core.model.scenes.chain import Chain, DHTable, Joint, LinkInertia
from simparity.core.rotations import rpy_to_matrix
from simparity.core.mjcf import chain_from_mjcf
from simparity.core.urdf import chain_from_urdf

JOINT_TYPES = ("revolute", "prismatic")
_CHAIN = ("name", "joint", "end_effector", "end_effector_xyz", "end_effector_rpy", "urdf", "mjcf", "base_link",
          "tip_link", "dh", "floating_base")
FLOATING_SCENES = "a joint_dynamics scene's URDF or MJCF chain, or a joint_motion scene's URDF chain"
"""What may have a floating base: its base link's mass properties come from the file."""
_DH = ("convention", "a", "alpha", "d", "theta_offset", "lower", "upper")
PYBULLET_DATA_PREFIX = "pybullet_data:"
"""A ``urdf`` path starting with this is inside the installed pybullet_data package."""
EXAMPLE_ROBOT_DATA_PREFIX = "example-robot-data:"
"""A ``urdf`` path starting with this is inside the installed example-robot-data package's
``robots`` folder (``pip install example-robot-data``)."""
EXAMPLE_ROBOT_DATA_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"
"""Where the example-robot-data wheel keeps its robots, relative to its installation."""
_LINK = ("mass", "com_xyz", "inertia")
_JOINT = ("name", "type", "axis", "origin_xyz", "origin_rpy", "lower", "upper", "damping", "armature") + _LINK
_WHERE_URDF = (f"a URDF file relative to the scene file, or {PYBULLET_DATA_PREFIX}... or "
               f"{EXAMPLE_ROBOT_DATA_PREFIX}... inside that package")
_WHERE_MJCF = (f"an MJCF file relative to the scene file, or {PYBULLET_DATA_PREFIX}... or "
               f"{EXAMPLE_ROBOT_DATA_PREFIX}... inside that package")
_WHERE = {"urdf": _WHERE_URDF, "mjcf": _WHERE_MJCF}


def _joint(r: TableReader, before: tuple[str, ...]) -> Joint:
    """One ``[[chain.joint]]``; ``before``: the names of the joints before it (its branch from the base)."""
    name = r.name("name")
    where = f"joint {name!r} on the branch {' > '.join(('base',) + before + (name,))}"
    kind = r.string("type", choices=JOINT_TYPES)
    length = 1 if kind == "prismatic" else 0
    if r.has("lower") != r.has("upper"):
        raise r.fail("lower" if not r.has("lower") else "upper", "missing: limits need both lower and upper",
                     "both lower and upper, or neither for an unlimited joint")
    lower = r.number("lower", length=length) if r.has("lower") else -np.inf
    upper = r.number("upper", length=length) if r.has("upper") else np.inf
    if lower > upper:  # lower == upper: a joint held at that value where limits act (as in a URDF)
        raise r.fail("upper", f"upper {upper:g} is below lower {lower:g} ({where})", "lower <= upper")
    # damping [N m s/rad = kg m^2/s] or [N s/m = kg/s], armature [kg m^2] or [kg]: length^2 or length^0
    power = 0 if kind == "prismatic" else 2
    damping = r.number("damping", 0.0, length=power) if r.has("damping") else 0.0
    armature = r.number("armature", 0.0, length=power) if r.has("armature") else 0.0
    for key, value in (("damping", damping), ("armature", armature)):
        if value < 0:
            raise r.fail(key, f"{value:g} is negative ({where})", "a number >= 0 (0: none)")
    rpy = r.vector("origin_rpy", 3, [0.0] * 3)
    return Joint(
        name=name, type=kind, axis=r.vector("axis", 3, nonzero=True),
        origin_xyz=r.vector("origin_xyz", 3, [0.0] * 3, length=1), origin_rotation=rpy_to_matrix(rpy),
        lower=lower, upper=upper, link=_link(r, where), damping=damping, armature=armature, origin_rpy=rpy,
    )


def _link(r: TableReader, where: str) -> LinkInertia | None:
    """The mass properties of a ``[[chain.joint]]``'s child link: all of mass, com_xyz, inertia, or none. The same
    rules as a URDF's ``<inertial>`` (:func:`core.urdf.chain_from_urdf`): a mass of 0 with a non-zero inertia loads
    (a rotor's inertia whose mass is counted elsewhere: real URDFs have it, and every engine keeps it as written);
    the tensor's rounding is judged against the link's own scale (:func:`core.dynamics.inertia.link_tensor_problem`).
    ``where`` (the joint's name and branch) ends every message."""
    given = [key for key in _LINK if r.has(key)]
    if not given:
        return None
    if len(given) != len(_LINK):
        missing = next(key for key in _LINK if key not in given)
        raise r.fail(missing, f"missing: {', '.join(given)} given without it ({where})",
                     "all of mass [kg], com_xyz [length] and inertia (3 x 3 about the centre of mass, in the link's "
                     "axes) or none (a chain for kinematics only)")
    massless = r.table.get("mass") == 0  # a massless link, as a URDF link without <inertial> or with mass 0
    mass = 0.0 if massless else r.number("mass", positive=True)
    inertia = r.matrix("inertia", 3, length=2)
    largest, moments = float(np.max(np.abs(inertia))), RANGES["inertia_moment"]
    if largest > moments.high:
        raise r.fail("inertia", f"an entry of {largest:.3g} kg m^2 is outside the physical range ({where})",
                     moments.text())
    com = r.vector("com_xyz", 3, length=1)
    problem = link_tensor_problem(inertia, mass, com)
    if problem:
        raise r.fail("inertia", f"{problem} ({where})", LINK_TENSOR_RULE)
    return LinkInertia(mass, com, inertia)


def _package_root(c: TableReader, prefix: str, key: str) -> Path:
    """The folder a prefixed ``urdf`` or ``mjcf`` path (``key``) is relative to."""
    if prefix == PYBULLET_DATA_PREFIX:
        import pybullet_data  # data files only; ships with pybullet

        return Path(pybullet_data.getDataPath())
    from importlib import metadata

    try:
        robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
    except metadata.PackageNotFoundError:
        raise c.fail(key, "the example-robot-data package is not installed",
                     "pip install example-robot-data, or the path of a robot file") from None
    return Path(str(robots))


def _robot_path(c: TableReader, key: str) -> Path:
    """The robot file a scene names under ``key`` (``urdf`` or ``mjcf``): relative to the scene file, absolute, or
    inside a package."""
    text = c.string(key)
    prefix = next((p for p in (PYBULLET_DATA_PREFIX, EXAMPLE_ROBOT_DATA_PREFIX) if text.startswith(p)), None)
    if prefix:
        root = _package_root(c, prefix, key)
        path = root / text[len(prefix):]
        if not os.path.realpath(path).startswith(os.path.realpath(root) + os.sep):
            raise c.fail(key, f"{echo(text)} leaves the {prefix[:-1]} package", _WHERE[key])
    else:
        path = Path(os.path.abspath(Path(c.source).parent / text))  # absolute: the same file however the scene was named
    problem = file_problem(path, f"{key.upper()} file")
    if problem:
        raise c.fail(key, f"{problem}: {one_line(path)}", _WHERE[key])
    return path


def _file_chain(c: TableReader, key: str, dynamics: bool, floating: bool) -> Chain:
    """The chain of a ``urdf`` or ``mjcf`` scene (``key``); an error in the file names the scene file, and the robot
    file as the scene does. A robot file's non-physical tensor on a moving link loads, recorded as the chain's
    ``mass_problem``: core declines it, the engines that accept the file compute with it (issue #45)."""
    base, tip = (c.name(name) if c.has(name) else None for name in ("base_link", "tip_link"))
    path = _robot_path(c, key)
    try:
        if key == "mjcf":
            return chain_from_mjcf(str(path), base_body=base, tip_body=tip, max_joints=c.limits.max_joints,
                                   max_bytes=c.limits.max_file_bytes, dynamics=dynamics, floating_base=floating,
                                   refuse_mass=False)
        return chain_from_urdf(str(path), base_link=base, tip_link=tip, max_joints=c.limits.max_joints,
                               max_bytes=c.limits.max_file_bytes, dynamics=dynamics, floating_base=floating,
                               refuse_mass=False)
    except SceneError as err:
        raise c.fail(key, f"{one_line(c.table[key], 120)}: {err.key}: {err.problem}", err.allowed) from None


def _dh_chain(c: TableReader, name: str) -> Chain:
    dh = c.subtable("dh", _DH)
    convention = dh.string("convention", "standard", choices=("standard", "modified"))
    columns = {key: dh.table.get(key) for key in ("a", "alpha", "d", "theta_offset")}
    size = len(columns["a"]) if isinstance(columns["a"], list) else 0
    if size < 1:
        raise dh.fail("a", "expected a non-empty list of numbers", "one number per joint")
    if size > dh.limits.max_joints:
        raise dh.fail("a", f"{size:,} joints", allowed_at_most(dh.limits, "max_joints"))
    values = {key: dh.vector(key, size, [0.0] * size if key == "theta_offset" else None,
                             length=1 if key in ("a", "d") else 0) for key in columns}
    limits = None
    if dh.has("lower") or dh.has("upper"):
        limits = np.stack([dh.vector("lower", size), dh.vector("upper", size)], axis=1)
        bad = np.flatnonzero(limits[:, 0] > limits[:, 1])
        if bad.size:
            raise dh.fail(f"upper[{bad[0]}]", f"the upper limit of joint {bad[0]} is below its lower limit (branch "
                          f"{' > '.join(f'joint {i}' for i in range(bad[0] + 1))})", "lower <= upper for every joint")
    table = DHTable(convention, **values)  # the numbers as given, for the references (core derives the frames)
    return replace(chain_from_dh(name, convention=convention, limits=limits, **values), dh=table)


def read_chain(top: TableReader, name: str, dynamics: bool = False, floating_allowed: bool = False,
               mjcf_allowed: bool = False) -> Chain:
    """The scene's ``[chain]``; for ``dynamics``, a URDF's inertia tensors must be physical; ``floating_base = true``
    only where ``floating_allowed`` (:data:`FLOATING_SCENES`), ``mjcf`` only where ``mjcf_allowed``."""
    c = top.subtable("chain", _CHAIN)
    sources = [key for key in ("joint", "urdf", "mjcf", "dh") if c.has(key)]
    if len(sources) != 1:
        raise c.fail("joint", f"give exactly one chain source, got {sources or 'none'}",
                     "one of [[chain.joint]], urdf, mjcf, [chain.dh]")
    if sources == ["mjcf"] and not mjcf_allowed:
        raise c.fail("mjcf", f"an MJCF chain is read for joint_dynamics scenes only, not for a "
                     f"{top.table.get('scene', {}).get('kind', 'this')} scene", "urdf, [[chain.joint]] or [chain.dh]")
    floating = c.boolean("floating_base", False)
    if floating and not (floating_allowed and sources[0] in ("urdf", "mjcf")):
        where = (f"a {top.table.get('scene', {}).get('kind', 'this')} scene" if not floating_allowed
                 else f"a chain given as {sources[0]}")
        raise c.fail("floating_base", f"a floating base is not available for {where}",
                     f"{FLOATING_SCENES} (false elsewhere)")
    if sources[0] in ("urdf", "mjcf"):
        return _file_chain(c, sources[0], dynamics, floating)
    if sources == ["dh"]:
        return _dh_chain(c, c.name("name", name))
    joints: tuple[Joint, ...] = ()
    for r in c.array_of_tables("joint", _JOINT, "max_joints"):
        joints += (_joint(r, tuple(joint.name for joint in joints)),)
    names = [j.name for j in joints]
    end_effector = c.name("end_effector", "end_effector")
    if len(set(names + [end_effector])) != len(names) + 1:
        repeated = next(n for i, n in enumerate(names + [end_effector]) if n in names[:i])
        raise c.fail("joint", f"the name {repeated!r} is given to two frames", "distinct joint and end-effector names")
    tip_rpy = c.vector("end_effector_rpy", 3, [0.0] * 3)
    return Chain(
        name=c.name("name", name), joints=joints, end_effector_name=end_effector,
        end_effector_xyz=c.vector("end_effector_xyz", 3, [0.0] * 3, length=1),
        end_effector_rotation=rpy_to_matrix(tip_rpy), end_effector_rpy=tip_rpy,
    )


def read_dynamics_chain(top: TableReader, head: dict, floating_allowed: bool = False,
                        mjcf_allowed: bool = False) -> Chain:
    """The ``[chain]`` of a joint-dynamics or joint-motion scene: every link with mass properties (a floating base's
    too, where ``floating_allowed``)."""
    chain = read_chain(top, head["name"], dynamics=True, floating_allowed=floating_allowed,
                       mjcf_allowed=mjcf_allowed)
    problem = chain.dynamics_problem()
    if problem and chain.floating_base and problem.startswith("the floating"):
        raise top.fail("chain", problem, "a floating base link with a mass and a rotational inertia about every axis "
                       "(its own <inertial>, or a body welded to it by a fixed joint)")
    if problem:
        raise top.fail("chain", problem, "a chain whose every link has mass properties: a URDF file with <inertial> "
                       "elements or [[chain.joint]] with mass, com_xyz and inertia ([chain.dh] declares none)")
    return chain


def joint_powers(chain: Chain, revolute: int, prismatic: int) -> np.ndarray:
    """(n,) the power of length in each joint's unit of a quantity (revolute and prismatic joints differ)."""
    return np.array([revolute if j.type == "revolute" else prismatic for j in chain.joints], dtype=float)


def joint_values(r: TableReader, key: str, chain: Chain, powers: np.ndarray, default: float | None = 0.0) -> np.ndarray:
    """(n,) one number per joint in the scene's length unit (scaled joint by joint by ``powers``)."""
    values = r.vector(key, chain.n_joints, None if default is None else [default] * chain.n_joints) * r.scale ** powers
    return np.array([r.in_range(f"{key}[{i}]", float(v)) for i, v in enumerate(values)])


def within_limits(r: TableReader, key: str, chain: Chain, q: np.ndarray) -> np.ndarray:
    """``q`` (n,), refused naming ``key`` and the first joint outside its limits."""
    outside = np.flatnonzero((q < chain.lower) | (q > chain.upper))
    if outside.size:
        joint = chain.joints[outside[0]]
        raise r.fail(key, f"joint {joint.name} starts outside its limits",
                     f"values within [{joint.lower:g}, {joint.upper:g}] for {joint.name}")
    return q
