"""A forward-kinematics scene (``kind = "kinematics"``): ``[chain]`` and ``[sampling]``."""

from __future__ import annotations

from simparity.comparisons.scenes.loading.chain import read_chain
from simparity.comparisons.scenes.loading.reader import MAX_SEED, SAMPLES_WHY, TableReader
from simparity.core.model.scenes.kinematics import KinematicsScene


def read_kinematics(top: TableReader, head: dict) -> KinematicsScene:
    """The forward-kinematics scene of the file's tables ``top``; ``head``: its ``[scene]`` keys."""
    chain = read_chain(top, head["name"])
    sampling = top.optional_subtable("sampling", ("configurations", "seed"))
    limit = top.limits.max_samples
    n = sampling.integer("configurations", 100, minimum=1, maximum=limit, why=SAMPLES_WHY) if sampling else 100
    seed = sampling.integer("seed", 0, maximum=MAX_SEED) if sampling else 0
    return KinematicsScene(chain=chain, n_configurations=n, seed=seed, **head)
