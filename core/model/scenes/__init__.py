"""The scenes, one module per kind, and their parts (:mod:`core.model.scenes.kinds` names them all).

SI units, float64, quaternions (w, x, y, z), velocities in the world frame. A body's
frame has its origin at the centre of mass; its inertia tensor is about the centre of
mass, in body axes. A scene carries only what it needs: ``gravity_world`` is ``None``
when the scene has no gravity, and adapters then give the engines none.

Scenes are built by the loader in ``comparisons.scenes.loading`` (which checks every value
and reports the file and key of a bad one) or directly in code (tests, benchmarks).
"""
