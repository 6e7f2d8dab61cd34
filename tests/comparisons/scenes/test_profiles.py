"""The quick profile: the same scenes, shorter, still able to fit an order and show a blow-up."""

from simparity.comparisons.scenes.profiles import (
    QUICK_CONTACT_STEPS,
    QUICK_LADDER,
    QUICK_MAX_STEPS,
    QUICK_TARGETS,
    apply_profile,
    quick,
)
from tests.helpers import builtin


def test_contact_scenes_keep_their_coarsest_steps():
    """A contact scene has no order to fit; its verdicts lie at its coarsest steps."""
    bounce = builtin("lecture-bouncing-particle")
    assert quick(bounce).dts == tuple(sorted(bounce.dts))[-QUICK_LADDER:]
    assert quick(bounce).duration == QUICK_CONTACT_STEPS * 0.0025  # 1,000 steps of the finest kept step


def test_dynamics_keep_their_steps_and_a_whole_number_of_them():
    full = builtin("long-horizon")
    short = quick(builtin("dzhanibekov"))
    assert short.dts == (0.0025, 0.005, 0.01) and len(short.dts) == QUICK_LADDER
    assert short.duration == QUICK_MAX_STEPS * 0.0025  # 2,000 steps of the finest, 500 of the coarsest
    variants = {"rk4+matrix", "rk4+expmap", "explicit_euler+matrix"}  # core's further orientation updates
    assert not variants & set(short.integrators) and "rk4" in short.integrators
    assert quick(full).duration == QUICK_MAX_STEPS * full.dts[0] < full.duration


def test_short_scenes_run_whole_and_samples_shrink():
    projectile = builtin("lecture-projectile")
    assert quick(projectile).duration == projectile.duration  # 1,440 steps at the finest step
    assert quick(projectile).dts == tuple(sorted(projectile.dts))  # no contact: the whole ladder, for its orders
    assert quick(builtin("iiwa-ik")).n_targets == QUICK_TARGETS
    assert apply_profile([projectile], "full") == [projectile]


def test_the_quick_default_suite_exercises_every_integrator_variant():
    """Every integrator core offers for free bodies, each orientation update included, runs on at least one scene
    of the quick default suite (the short rotating scenes keep their variants)."""
    from simparity.comparisons.engines.registry import make_engine
    from simparity.comparisons.scenes.library import suite
    from simparity.core.model.scenes.dynamics import DynamicsScene

    core = make_engine("core")
    scenes = [quick(s) for s in suite("default") if isinstance(s, DynamicsScene) and s.contact is None]
    ran = {i for s in scenes for i in core.scene_integrators(s) if not s.integrators or i in s.integrators}
    offered = set(core.scene_integrators(scenes[0]))
    assert {"rk4+matrix", "rk4+expmap"} <= offered <= ran
