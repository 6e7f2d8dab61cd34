"""``simparity import FILE``: every reader's verdict on a robot file as a user has it (issue #45), one line each:
core's own reader (``core.urdf``, ``core.mjcf``) and each engine's importer (``references.importers``). The file is
refused (exit 2) only when no reader reads it."""

from __future__ import annotations

import os

from simparity.core.mjcf import chain_from_mjcf
from simparity.core.model.errors import SceneError, SimparityError, one_line
from simparity.core.model.files import MAX_FILE_BYTES, file_problem, parse_xml, read_input
from simparity.core.urdf import chain_from_urdf
from simparity.references.importers import MJCF, URDF, ReaderVerdict, engine_verdicts

ROOT_TAGS = {"robot": URDF, "mujoco": MJCF}
"""A robot file's format by its root element."""
SUFFIXES = {".urdf": URDF, ".xml": MJCF, ".mjcf": MJCF}
"""A robot file's format by its name, where its XML cannot be read."""
TIP_KEYS = ("tip_link", "tip_body")
"""Core's refusal to choose among several leaves: the file is read; a scene names the tip."""


def file_format(path: str) -> str:
    """``urdf`` or ``mjcf``: by the root element, else by the name's suffix; a SimparityError (one line) for neither."""
    data, kind = read_input(path, MAX_FILE_BYTES, "robot file"), None
    for tag, format_ in ROOT_TAGS.items():
        try:
            parse_xml(data, path, tag)
        except SceneError:
            continue
        kind = format_
    kind = kind or SUFFIXES.get(os.path.splitext(path)[1].lower())
    if kind is None:
        raise SimparityError(f"{one_line(path)}: not a robot file (allowed: a URDF file, root <robot>, or an MJCF file, "
                             "root <mujoco>)")
    return kind


def core_verdict(path: str, kind: str) -> ReaderVerdict:
    """Core's reader on the file as a scene's chain reads it (dynamics: mass properties held to the physical rules,
    a non-physical tensor recorded, not refused)."""
    reader = chain_from_mjcf if kind == MJCF else chain_from_urdf
    try:
        chain = reader(path, dynamics=True, refuse_mass=False)
    except SceneError as error:
        if error.key in TIP_KEYS:
            return ReaderVerdict("core", True, f"reads it ({error.problem}: a scene names its tip_link)")
        return ReaderVerdict("core", False, f"refuses it: {error.key}: {error.problem}")
    said = (f"reads it: {chain.n_joints} joints from {chain.base_link} to {chain.end_effector_name}, "
            f"{len(chain.held_joints)} held")
    return ReaderVerdict("core", True, said + (f"; declines its mass properties: {chain.mass_problem}"
                                               if chain.mass_problem else ""))


def verdicts(path: str) -> tuple[str, tuple[ReaderVerdict, ...]]:
    """(the format, each reader's verdict: core's first) on the robot file ``path``."""
    problem = file_problem(path, "robot file")
    if problem:
        raise SimparityError(f"{one_line(path)}: {problem} (allowed: the path of a URDF or MJCF file)")
    kind = file_format(path)
    return kind, (core_verdict(path, kind),) + engine_verdicts(path, kind)
