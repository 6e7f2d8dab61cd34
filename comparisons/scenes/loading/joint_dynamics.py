"""A joint-space dynamics scene (``kind = "joint_dynamics"``): ``[chain]`` with mass properties, ``[world]``
and ``[sampling]``."""

from __future__ import annotations

from simparity.comparisons.scenes.loading.chain import read_dynamics_chain
from simparity.comparisons.scenes.loading.reader import MAX_SEED, SAMPLES_WHY, TableReader
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene

_JOINT_DYNAMICS_SAMPLING = ("states", "seed", "velocity_scale", "acceleration_scale", "torque_scale")


def read_joint_dynamics(top: TableReader, head: dict) -> JointDynamicsScene:
    """The joint-space dynamics scene of the file's tables ``top``; ``head``: its ``[scene]`` keys."""
    chain = read_dynamics_chain(top, head, floating_allowed=True, mjcf_allowed=True)
    world = top.optional_subtable("world", ("gravity_world",))
    gravity = world.vector("gravity_world", 3, length=1) if world and world.has("gravity_world") else None
    sampling = top.optional_subtable("sampling", _JOINT_DYNAMICS_SAMPLING)
    limit = top.limits.max_samples
    count = sampling.integer("states", 100, minimum=1, maximum=limit, why=SAMPLES_WHY) if sampling else 100
    seed = sampling.integer("seed", 0, maximum=MAX_SEED) if sampling else 0
    velocity, acceleration, torque = (sampling.number(key, 1.0, positive=True) if sampling and sampling.has(key)
                                      else 1.0 for key in _JOINT_DYNAMICS_SAMPLING[2:])
    return JointDynamicsScene(chain=chain, gravity_world=gravity, n_states=count, seed=seed, velocity_scale=velocity,
                              acceleration_scale=acceleration, torque_scale=torque, **head)
