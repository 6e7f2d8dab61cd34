"""Issue #38 section 6: the default suite's joint-space scenes hold a 3-D chain, so that a link inertia in the wrong
frame is caught by the gate CI runs, not only by the articulated suite.

On a chain whose every axis is z (the planar arms) each link's inertia is turned into its joint frame by the
identity: an inertia rotated the wrong way changes nothing there. The tests below find, among the default suite's
joint-dynamics and joint-motion scenes, chains with non-parallel axes, rotated products of inertia and centres of
mass off the axes, and show that the catalogue's wrong-frame mutant changes the mass matrix there (and only there).
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from simparity.comparisons.scenes import library
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from tests.mutation.catalogue import by_id
from tests.mutation.copy_of_core import materialise

WRONG_FRAME = "link_inertia_transposed_alignment"
"""The catalogue's mutant: each link's inertia turned into its joint frame by the transposed rotation."""

PARALLEL_TOLERANCE = 1e-9
"""|a x b| below this: two unit axes are parallel (the scene files write axes to ~1e-16)."""

PRODUCT_OF_INERTIA_FRACTION = 1e-3
"""An off-diagonal inertia entry above this fraction of the tensor's trace is a product of inertia a wrong frame
turns into a wrong mass matrix (rounding of a diagonal tensor is ~1e-16 of it)."""

VISIBLE = 1e-6
"""Relative change of the mass matrix that the gate's 1e-12 bound on mass_matrix_error_max sees by far."""

STATES = 5
SEED = 38


def _joint_scenes() -> list:
    return [s for s in library.suite("default") if isinstance(s, (JointDynamicsScene, JointMotionScene))]


def _axes(chain: Chain) -> np.ndarray:
    """Each joint's axis in the base frame at q = 0, (n, 3)."""
    rotation, axes = np.eye(3), []
    for joint in chain.joints:
        if joint.origin_rotation is not None:
            rotation = rotation @ np.asarray(joint.origin_rotation)
        axes.append(rotation @ np.asarray(joint.axis) / np.linalg.norm(joint.axis))
    return np.array(axes)


def _three_dimensional(chain: Chain) -> bool:
    """Two axes not parallel, an axis along none of x, y and z (the joint frames are turned obliquely: a quarter turn
    onto x or y and its transpose can map an inertia alike), a link inertia with products of inertia and a centre of
    mass off its joint's axis."""
    axes = _axes(chain)
    crossed = [np.linalg.norm(np.cross(a, b)) for i, a in enumerate(axes) for b in axes[i + 1:]]
    links = [j.link for j in chain.joints if j.link is not None]
    products = [np.max(np.abs(link.inertia_com - np.diag(np.diag(link.inertia_com)))) / np.trace(link.inertia_com)
                for link in links]
    off_axis = [np.linalg.norm(np.cross(j.link.com_xyz, np.asarray(j.axis) / np.linalg.norm(j.axis)))
                for j in chain.joints if j.link is not None]
    return (max(crossed, default=0.0) > PARALLEL_TOLERANCE
            and any(np.max(np.abs(a)) < 1 - PARALLEL_TOLERANCE
                    for a in (np.asarray(j.axis) / np.linalg.norm(j.axis) for j in chain.joints))
            and max(products, default=0.0) > PRODUCT_OF_INERTIA_FRACTION
            and max(off_axis, default=0.0) > PARALLEL_TOLERANCE)


@pytest.mark.parametrize("kind", [JointDynamicsScene, JointMotionScene], ids=["joint_dynamics", "joint_motion"])
def test_the_default_suite_has_a_3d_chain_of_each_joint_kind(kind):
    """Every joint-space scene of the default suite was planar (every axis z, diagonal inertias) before issue #38."""
    chains = [s.name for s in _joint_scenes() if isinstance(s, kind) and _three_dimensional(s.chain)]
    assert chains, f"no {kind.__name__} of the default suite has a 3-D chain"


@pytest.fixture
def wrong_frame_copy(tmp_path, monkeypatch):
    """The catalogue's wrong-frame mutant and the faithful copy, imported; forgotten afterwards."""
    monkeypatch.syspath_prepend(str(tmp_path))
    copies = [materialise(by_id(WRONG_FRAME), tmp_path), materialise(None, tmp_path)]
    modules = {}
    for copy in copies:
        __import__(f"{copy.package}.articulated.recursive")
        __import__(f"{copy.package}.articulated.chain_arrays")
        modules[copy.mutation is None] = copy.package
    yield {faithful: (sys.modules[f"{p}.articulated.recursive"], sys.modules[f"{p}.articulated.chain_arrays"])
           for faithful, p in modules.items()}
    for name in [n for n in sys.modules if any(n == p or n.startswith(p + ".") for p in modules.values())]:
        del sys.modules[name]


def _mass_matrices(modules, chain: Chain, q: np.ndarray) -> np.ndarray:
    recursive, arrays = modules
    return recursive.Recursive(arrays.chain_arrays(chain), np.zeros(3)).mass_matrix(q)


def test_a_link_inertia_in_the_wrong_frame_shows_on_the_3d_chains_only(wrong_frame_copy):
    """The mutant's mass matrix departs from the faithful copy's on every 3-D chain of the default suite, and not at
    all on its planar ones (every axis z): those alone could not catch it. (A chain between the two, axes off z with
    diagonal inertias such as Solo-12's leg, may show it or not.)"""
    rng = np.random.default_rng(SEED)
    seen = {}
    for scene in _joint_scenes():
        q = rng.uniform(-1.0, 1.0, size=(scene.chain.n_joints, STATES))
        faithful = _mass_matrices(wrong_frame_copy[True], scene.chain, q)
        mutant = _mass_matrices(wrong_frame_copy[False], scene.chain, q)
        planar = bool(np.all(np.abs(_axes(scene.chain)[:, 2]) > 1 - PARALLEL_TOLERANCE))
        seen[scene.name] = (_three_dimensional(scene.chain), planar,
                            float(np.max(np.abs(mutant - faithful)) / np.max(np.abs(faithful))))
    assert {three_d for three_d, _, _ in seen.values()} == {True, False}, seen  # both kinds of chain are there
    assert any(planar for _, planar, _ in seen.values()), seen
    for name, (three_d, planar, change) in seen.items():
        if three_d:
            assert change > VISIBLE, (name, change)
        if planar:
            assert change == 0.0, (name, change)
