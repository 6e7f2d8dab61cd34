"""An example of checking numerics in your own test suite with simparity's pytest plugin.

Run it with ``pytest docs/examples/test_my_numerics.py`` after ``pip install simparity``; add
``--simparity-baseline simparity-results/<run>`` to fail on anything that moved since that run.
"""


def test_the_lecture_projectile_keeps_its_known_errors(simparity):
    """Core on the lecture's projectile, quick profile: Euler off by exactly g T dt / 2, RK4 exact."""
    simparity.check("lecture-projectile", engines=["core"], profile="quick")
