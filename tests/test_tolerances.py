"""Tolerances files: bounds with reasons, the most specific wins, bad files refused with the key."""

import math
import os

import pytest

from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, bound_for, load_tolerances
from simparity.core.model.errors import ToleranceError


def _write(tmp_path, text):
    path = tmp_path / "tol.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_most_specific_bound_wins_and_later_wins_a_tie(tmp_path):
    bounds = load_tolerances(_write(tmp_path, """
[[bound]]
metric = "*"
status = ["ok", "n/a"]
reason = "catch-all"
[[bound]]
integrator = "rk4*"
metric = "order_*"
expected = 4.0
band = 0.5
reason = "fourth order"
[[bound]]
integrator = "rk4*"
metric = "order_*"
expected = 4.0
band = 0.1
reason = "later, as specific"
[[bound]]
scene = "s"
integrator = "rk4"
metric = "order_position"
expected = 1.0
band = 0.5
reason = "exact names beat patterns"
"""))
    assert bound_for(bounds, "x", "core", "euler", "time_per_step").reason == "catch-all"
    assert bound_for(bounds, "x", "core", "rk4+matrix", "order_position").reason == "later, as specific"
    assert bound_for(bounds, "s", "core", "rk4", "order_position").reason == "exact names beat patterns"


def test_dt_star_holds_for_time_steps_but_not_order_rows(tmp_path):
    bounds = load_tolerances(_write(tmp_path, """
[[bound]]
dt = "*"
status = "diverged"
reason = "every step blows up"
[[bound]]
dt = 0.004
status = "ok"
reason = "except this one"
"""))
    assert bound_for(bounds, "s", "e", "i", "m", math.nan) is None  # an order row has no dt
    assert bound_for(bounds, "s", "e", "i", "m", 0.002).reason == "every step blows up"
    assert bound_for(bounds, "s", "e", "i", "m", 0.004 * (1 + 1e-12)).reason == "except this one"


def test_limits_scale_with_dt_and_combine_band_and_rel(tmp_path):
    """expected 29.2608 dt^1 with rel 1e-9 at dt = 1/30: 0.97536 +- 9.75e-10; expected 4 +- 0.5."""
    bounds = load_tolerances(_write(tmp_path, """
[[bound]]
metric = "e"
expected = 29.2608
dt_power = 1.0
rel = 1e-9
reason = "g T dt / 2"
[[bound]]
metric = "o"
expected = 4.0
band = 0.5
reason = "order 4"
"""))
    low, high = bound_for(bounds, "s", "e", "i", "e", 1 / 30).limits(1 / 30)
    assert low == pytest.approx(0.97536 * (1 - 1e-9), rel=1e-15) and high == pytest.approx(0.97536 * (1 + 1e-9), rel=1e-15)
    assert bound_for(bounds, "s", "e", "i", "o").limits(math.nan) == (3.5, 4.5)


@pytest.mark.parametrize("text, key, words", [
    ('[[bound]]\nmetric = "m"\nmax = 1.0\n', "bound[0].reason", "needs its reason"),
    ('[[bound]]\nmetric = "m"\nmaximum = 1.0\nreason = "r"\n', "bound[0].maximum", "unknown key"),
    ('[[bound]]\nmetric = "m"\nstatus = "great"\nreason = "r"\n', "bound[0].status", "not a status"),
    ('[[bound]]\nmetric = "m"\nband = 0.1\nreason = "r"\n', "bound[0].band", "need an expected"),
    ('[[bound]]\nmetric = "m"\nmax = nan\nreason = "r"\n', "bound[0].max", "finite number"),
    ('[[bound]]\nmetric = "m"\nreason = "r"\n', "bound[0]", "bounds nothing"),
    ('[[bound]]\nmetric = "m"\ndt = -1.0\nmax = 1.0\nreason = "r"\n', "bound[0].dt", "not a time step"),
    ('[[bounds]]\nmetric = "m"\n', "bounds", "unknown table"),
    ('[[bound]\n', "line 1, column 8", "not valid TOML"),
])
def test_bad_tolerances_name_the_key_and_what_is_allowed(tmp_path, text, key, words):
    with pytest.raises(ToleranceError) as caught:
        load_tolerances(_write(tmp_path, text))
    message = str(caught.value)
    assert f": {key}: " in message and words in message and "(allowed: " in message and "\n" not in message


def test_the_shipped_tolerances_load_and_give_every_bound_a_reason():
    bounds = load_tolerances(DEFAULT_TOLERANCES)
    assert len(bounds) > 20 and all(len(b.reason) > 20 for b in bounds)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need a POSIX system")
def test_a_tolerances_path_that_is_no_regular_file_is_refused_without_opening_it(tmp_path):
    """A FIFO would block forever and /dev/zero never ends: neither is opened."""
    fifo = tmp_path / "tol.toml"
    os.mkfifo(fifo)
    for path in (fifo, tmp_path, "/dev/zero"):
        with pytest.raises(ToleranceError, match=r"not a regular file.*\(allowed: the path of a regular tolerances file\)"):
            load_tolerances(path)
