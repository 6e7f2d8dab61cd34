"""Tolerances files: bounds with reasons, the most specific wins, bad files refused with the key."""

import math
import os

import pytest

from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, bound_for, load_tolerances, matching_bounds
from simparity.core.model.errors import ToleranceError


def _write(tmp_path, text):
    """A tolerances file of ``text`` alone (``extends = "none"`` unless the text says what it extends)."""
    path = tmp_path / "tol.toml"
    path.write_text(text if "extends" in text else 'extends = "none"\n' + text, encoding="utf-8")
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
metric = "position_error_final"
expected = 29.2608
dt_power = 1.0
rel = 1e-9
reason = "g T dt / 2"
[[bound]]
metric = "order_position"
expected = 4.0
band = 0.5
reason = "order 4"
"""))
    low, high = bound_for(bounds, "s", "e", "i", "position_error_final", 1 / 30).limits(1 / 30)
    assert low == pytest.approx(0.97536 * (1 - 1e-9), rel=1e-15) and high == pytest.approx(0.97536 * (1 + 1e-9), rel=1e-15)
    assert bound_for(bounds, "s", "e", "i", "order_position").limits(math.nan) == (3.5, 4.5)


@pytest.mark.parametrize("text, key, words", [
    ('[[bound]]\nmetric = "solve_rate"\nmax = 1.0\n', "bound[0].reason", "needs its reason"),
    ('[[bound]]\nmetric = "solve_rate"\nmaximum = 1.0\nreason = "r"\n', "bound[0].maximum", "unknown key"),
    ('[[bound]]\nmetric = "solve_rate"\nstatus = "great"\nreason = "r"\n', "bound[0].status", "not a status"),
    ('[[bound]]\nmetric = "solve_rate"\nband = 0.1\nreason = "r"\n', "bound[0].band", "need an expected"),
    ('[[bound]]\nmetric = "solve_rate"\nmax = nan\nreason = "r"\n', "bound[0].max", "finite number"),
    ('[[bound]]\nmetric = "solve_rate"\nreason = "r"\n', "bound[0]", "bounds nothing"),
    ('[[bound]]\nmetric = "solve_rate"\ndt = -1.0\nmax = 1.0\nreason = "r"\n', "bound[0].dt", "not a time step"),
    ('[[bounds]]\nmetric = "m"\n', "bounds", "unknown table"),
    ('[[bound]\n', "line 2, column 8", "not valid TOML"),  # line 1 is _write's extends
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


ONE_BOUND = """
[[bound]]
metric = "order_*"
min = 0.0
status = ["ok", "n/a"]
reason = "mine: any order at all"
"""


def test_a_users_file_extends_the_shipped_one_and_its_bounds_win_where_they_match(tmp_path):
    """One bound of the user's keeps every shipped bound; where both match a row the user's decides although the
    shipped RK4 order bound (scheme and metric pattern) is more specific; elsewhere the shipped bound decides."""
    path = tmp_path / "mine.toml"
    path.write_text(ONE_BOUND, encoding="utf-8")
    shipped, mine = load_tolerances(DEFAULT_TOLERANCES), load_tolerances(path)
    assert len(mine) == len(shipped) + 1 and mine[:-1] == shipped
    rk4_order = ("s", "e", "rk4", "order_position", math.nan, "rk4")
    shipped_decider = bound_for(shipped, *rk4_order)
    assert shipped_decider.min == 3.5 and shipped_decider.specificity > mine[-1].specificity
    assert bound_for(mine, *rk4_order) is mine[-1]
    error_row = ("s", "e", "rk4", "position_error_max", 0.01, "rk4")
    assert bound_for(mine, *error_row) == bound_for(shipped, *error_row)


def test_extends_none_starts_empty_and_a_chain_of_files_layers_in_order(tmp_path):
    (tmp_path / "empty.toml").write_text('extends = "none"\n' + ONE_BOUND, encoding="utf-8")
    assert len(load_tolerances(tmp_path / "empty.toml")) == 1
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "top.toml").write_text(
        'extends = "../empty.toml"\n[[bound]]\nmetric = "*"\nmax = 1.0\nreason = "top"\n', encoding="utf-8")
    chain = load_tolerances(tmp_path / "sub" / "top.toml")
    assert [b.layer for b in chain] == [0, 1]
    assert bound_for(chain, "s", "e", "i", "order_position") is chain[1]  # the extending file wins


@pytest.mark.parametrize("extends, words", [
    ('"loop.toml"', "closes a loop of extends"),
    ('"nosuch.toml"', "no such file"),
    ("3", "expected text"),
])
def test_a_bad_extends_is_one_line_naming_the_file_and_key(tmp_path, extends, words):
    path = tmp_path / "loop.toml"
    path.write_text(f"extends = {extends}\n" + ONE_BOUND, encoding="utf-8")
    with pytest.raises(ToleranceError) as caught:
        load_tolerances(path)
    message = str(caught.value)
    assert words in message and "(allowed: " in message and "\n" not in message


def test_matching_bounds_lists_the_deciding_bound_first(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text(ONE_BOUND, encoding="utf-8")
    bounds = load_tolerances(path)
    matched = matching_bounds(bounds, "s", "e", "rk4", "order_position", math.nan, "rk4")
    assert matched[0] is bound_for(bounds, "s", "e", "rk4", "order_position", math.nan, "rk4")
    assert len(matched) >= 3 and [b.precedence for b in matched] == sorted((b.precedence for b in matched), reverse=True)


def test_a_bound_keyed_by_a_case_s_scheme_holds_its_derivative_rows(tmp_path):
    """A derivative row's scheme is its case's joined with what its derivatives declare ("rk4+analytic_derivatives"):
    a hard case's verdict keyed by the case's scheme holds it (it beat the row's metric bound before: a bounded RK4
    case read its derivative rows against the diverged verdict of the other schemes), and a bound keyed by the
    derivative kind holds only the rows that declare it."""
    bounds = load_tolerances(_write(tmp_path, """
[[bound]]
scene = "whip"
metric = "*"
status = "diverged"
reason = "every scheme diverges"
[[bound]]
scene = "whip"
scheme = ["rk4"]
metric = "*"
status = ["ok", "n/a"]
reason = "RK4 holds"
[[bound]]
scheme = "*differences"
metric = "step_jacobian_error_max"
max = 1e-3
reason = "differenced"
"""))
    assert bound_for(bounds, "whip", "core", "rk4", "step_jacobian_error_max", scheme="rk4+analytic_derivatives"
                     ).reason == "RK4 holds"
    assert bound_for(bounds, "whip", "core", "euler", "step_jacobian_error_max", scheme="semi_implicit_euler"
                     ).reason == "every scheme diverges"
    assert bound_for(bounds, "calm", "mujoco", "euler", "step_jacobian_error_max",
                     scheme="implicit_damping+central_differences").reason == "differenced"
    assert bound_for(bounds, "calm", "core", "rk4", "step_jacobian_error_max", scheme="rk4+analytic_derivatives") \
        is None
