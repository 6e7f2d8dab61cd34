"""The Butcher tableaux: every order condition up to each scheme's claimed order holds, one of the next order fails.

The conditions are the elementary weights of the rooted trees (Hairer, Norsett & Wanner, Solving Ordinary
Differential Equations I, section II.2, table 2.2): sum_i b_i Phi_i(t) = 1 / gamma(t) for every tree t of at most
p nodes. The measured orders (tests/core/dynamics/test_integrators.py, tests/core/articulated/test_stepping.py) are the other half.
"""

import numpy as np
import pytest

from simparity.core.articulated import stepping
from simparity.core.dynamics import integrators
from simparity.core.dynamics.tableau import TABLEAUX, Tableau

ROUNDING = 1e-15
"""float64 rounding of sums of a few products of coefficients of O(1) (1/6 and 1/3 are not exact)."""

VIOLATED = 1e-3
"""A failed condition misses its value by a fraction like 1/24 - 1/32, far above any rounding."""


def _conditions(t: Tableau) -> dict[int, list[tuple[str, float, float]]]:
    """(tree, elementary weight, 1 / gamma) by order, trees of 1 to 5 nodes."""
    a, b, c = np.array(t.a), np.array(t.b), np.array(t.c)
    ac, ac2, ac3 = a @ c, a @ c**2, a @ c**3
    aac = a @ ac
    return {
        1: [("b", b.sum(), 1.0)],
        2: [("bc", b @ c, 1 / 2)],
        3: [("bc^2", b @ c**2, 1 / 3), ("bac", b @ ac, 1 / 6)],
        4: [("bc^3", b @ c**3, 1 / 4), ("bcac", b @ (c * ac), 1 / 8), ("bac^2", b @ ac2, 1 / 12),
            ("baac", b @ aac, 1 / 24)],
        5: [("bc^4", b @ c**4, 1 / 5), ("bc^2ac", b @ (c**2 * ac), 1 / 10), ("bcac^2", b @ (c * ac2), 1 / 15),
            ("bcaac", b @ (c * aac), 1 / 30), ("b(ac)^2", b @ ac**2, 1 / 20), ("bac^3", b @ ac3, 1 / 20),
            ("bacac", b @ (a @ (c * ac)), 1 / 40), ("baac^2", b @ (a @ ac2), 1 / 60),
            ("baaac", b @ (a @ aac), 1 / 120)],
    }


@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_every_order_condition_up_to_the_claimed_order_holds(name):
    tableau = TABLEAUX[name]
    assert np.allclose(np.array(tableau.a).sum(axis=1), tableau.c, rtol=0.0, atol=ROUNDING)  # c_i = sum_j a_ij
    conditions = _conditions(tableau)
    for order in range(1, tableau.order + 1):
        for tree, weight, expected in conditions[order]:
            assert abs(weight - expected) <= ROUNDING, (name, tree, weight, expected)


@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_a_condition_of_the_next_order_fails(name):
    """The claimed order is the scheme's order, not a lower bound: some tree of order + 1 nodes is missed."""
    tableau = TABLEAUX[name]
    missed = [tree for tree, weight, expected in _conditions(tableau)[tableau.order + 1]
              if abs(weight - expected) > VIOLATED]
    assert missed, name


def test_rk4_holds_the_four_conditions_of_fourth_order_by_their_values():
    """The issue's list, written out: sum b c^3 = 1/4, sum b c a c = 1/8, sum b a c^2 = 1/12, sum b a a c = 1/24."""
    fourth = {tree: weight for tree, weight, _ in _conditions(TABLEAUX["rk4"])[4]}
    assert fourth == pytest.approx({"bc^3": 0.25, "bcac": 0.125, "bac^2": 1 / 12, "baac": 1 / 24}, abs=ROUNDING)


@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_the_weights_over_their_common_denominator_are_the_weights(name):
    tableau = TABLEAUX[name]
    assert [n / tableau.weight_denominator for n in tableau.weight_numerators] == list(tableau.b)
    assert all(n == int(n) for n in tableau.weight_numerators)


def test_free_bodies_and_chains_take_order_and_stages_from_the_one_tableau():
    for scheme, tableau in TABLEAUX.items():
        assert (integrators.ORDER[scheme], integrators.STAGES[scheme]) == (tableau.order, len(tableau.b))
    for scheme in stepping.RUNGE_KUTTA:
        assert (stepping.ORDER[scheme], stepping.STAGES[scheme]) == (TABLEAUX[scheme].order, len(TABLEAUX[scheme].b))


@pytest.mark.parametrize("a, b, c", [(((0.0,),), (0.5, 0.5), (0.0,)),
                                     (((0.0, 1.0), (0.0, 0.0)), (0.5, 0.5), (0.0, 1.0))])
def test_a_tableau_of_mismatched_shapes_or_an_implicit_one_is_refused(a, b, c):
    with pytest.raises(ValueError):
        Tableau(a=a, b=b, c=c, order=1)
