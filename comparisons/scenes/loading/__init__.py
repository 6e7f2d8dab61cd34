"""Scene files (TOML) -> the scenes of :mod:`core.model.scenes`: a free-body ``DynamicsScene``
(:mod:`.dynamics`, with :mod:`.bodies` and :mod:`.contact`), a ``KinematicsScene`` (:mod:`.kinematics`), an
``IKScene`` (:mod:`.ik`), a ``JointDynamicsScene`` (:mod:`.joint_dynamics`) or a ``JointMotionScene``
(:mod:`.joint_motion`), the chain scenes' ``[chain]`` read by :mod:`.chain`.

Every value is checked (:class:`.reader.TableReader`); a bad one raises :class:`core.model.errors.SceneError`
naming the file, the key path, what was wrong and what is allowed. :mod:`.scene_file` reads a file and hands each
kind's tables to its module; :mod:`.reference` refuses a reference that cannot serve the scene. A file with a
``[sweep]`` is several scenes, one per variant (:mod:`comparisons.scenes.sweep`;
:func:`.scene_file.load_scenes`). The format is documented in ``docs/scenes.md``.
"""
