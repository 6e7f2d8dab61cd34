"""The bench's profile: where core's time goes (cProfile, functions by own time) on its stepping, IK, ABA and joint
motion."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from simparity.comparisons.bench import joint_motion
from simparity.comparisons.bench.stepping import boxes, simulation
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.ik_targets import random_targets
from simparity.comparisons.scenes import library
from simparity.core.model.ik_problem import IKTolerances


def profile_summary(batch: int, say: Callable[[str], None]) -> str:
    """cProfile of core's rk4 on ``batch`` tumbling boxes, of its restarted IK on the iiwa, of its ABA on ``batch``
    iiwa states and of its rk4 joint motion on ``batch`` falling iiwas, top functions."""
    import cProfile
    import io
    import pstats
    out = []
    sim = simulation("core", "rk4", boxes(batch, False))
    scene = replace(library.load(["bench-iiwa-ik"])[0], n_targets=min(batch, 10_000))
    targets = random_targets(scene, make_engine("core").build_kinematics(scene.chain))
    model = make_engine("core").build_ik(scene.chain, "damped_least_squares+restarts",
                                         IKTolerances(scene.position_tolerance, scene.orientation_tolerance,
                                                      scene.max_iterations))
    arm = replace(library.load(["iiwa-dynamics"])[0], n_states=batch)
    q, qd, _, tau = arm.states()
    dynamics = make_engine("core").build_joint_dynamics(arm.chain, "recursive", arm.gravity_world)
    for title, call in ((f"core rk4, {batch:,} tumbling boxes, 20 steps", lambda: sim.run(20)),
                        (f"core damped_least_squares+restarts, {scene.n_targets:,} iiwa targets",
                         lambda: model.solve(targets.position_world, targets.rotation_world, scene.q_start)),
                        (f"core recursive forward dynamics (ABA), {batch:,} iiwa states, 20 calls",
                         lambda: [dynamics.forward_dynamics(q, qd, tau) for _ in range(20)]),
                        joint_motion.profile_case(batch)):
        say(f"  profiling {title}")
        profiler = cProfile.Profile()
        profiler.runcall(call)
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).strip_dirs().sort_stats("tottime").print_stats(8)
        body = [line for line in text.getvalue().splitlines() if line.strip()][2:]
        out += [title] + body + [""]
    return "\n".join(out)
