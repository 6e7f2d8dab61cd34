"""A scene file's [sweep] (comparisons/scenes/sweep.py): key paths found in the file, values from lists and ranges,
variants combined and named, every bad table refused with the sweep key, what was wrong and what is allowed."""

import pytest

from simparity.comparisons.scenes.sweep import MAX_KEYS, MAX_VARIANTS, read_sweep
from simparity.core.model.errors import SceneError
from simparity.core.model.names import NAME_MAX, name_problem
from simparity.core.model.scenes.suites import SweepPoint

DATA = {
    "scene": {"name": "bounce", "kind": "dynamics", "reference": "analytic"},
    "world": {"gravity_world": [0.0, 0.0, -9.81]},
    "plane": [{"name": "floor", "coefficients": [0.0, 0.0, 1.0, 0.0]}, {"coefficients": [1.0, 0.0, 0.0, 5.0]}],
    "contact": {"restitution": 0.5, "pair": [{"body": "ball", "plane": "floor", "restitution": 0.4}]},
    "body": [{"name": "ball", "mass": 0.5, "inertia_body_diagonal": [0.002, 0.002, 0.002],
              "position_world": [0.0, 0.0, 1.1], "restitution": 0.3},
             {"name": "1", "mass": 2.0, "inertia_body_diagonal": [0.1, 0.1, 0.1]}],
    "simulation": {"duration": 2.0, "dt": [0.0025, 0.005, 0.01]},
    "targets": {"seed": 0, "count": 10},
}
"""Parsed TOML of a scene file (read_sweep looks keys up in it; it never checks the scene itself)."""


def _sweep(table, data=DATA, base="bounce"):
    return read_sweep(table, data, "s.toml", base)


def _values(table):
    return [values for values in _sweep(table).combinations()]


def _refused(table, data=DATA) -> SceneError:
    with pytest.raises(SceneError) as caught:
        _sweep(table, data)
    return caught.value


@pytest.mark.parametrize("spec, expected", [
    ([0.1, 0.2, 0.5], (0.1, 0.2, 0.5)),
    ([2, 1], (2.0, 1.0)),                                                   # ints of a float key become floats
    ({"start": 0.3, "stop": 0.9, "num": 4}, (0.3, 0.5, 0.7, 0.9)),          # 0.7, not 0.7000000000000001
    ({"start": 0.9, "stop": 0.3, "num": 3}, (0.9, 0.6, 0.3)),
    ({"start": 1e-4, "stop": 1e-2, "num": 3, "spacing": "log"}, (1e-4, 1e-3, 1e-2)),
    ({"start": 1.0, "stop": 1e4, "num": 5, "spacing": "log"}, (1.0, 10.0, 100.0, 1000.0, 10000.0)),
    ({"start": 0.0, "stop": 1.0, "num": 2}, (0.0, 1.0)),
])
def test_values_of_a_float_key_from_a_list_or_a_range(spec, expected):
    values = _sweep({"contact.restitution": spec}).entries[0].values
    assert values == expected and all(type(v) is float for v in values)


@pytest.mark.parametrize("key", ["targets.seed", "targets.count"])
def test_a_whole_number_key_keeps_ints(key):
    assert _sweep({key: {"start": 0, "stop": 4, "num": 5}}).entries[0].values == (0, 1, 2, 3, 4)
    assert _sweep({key: {"start": 1, "stop": 1000, "num": 4, "spacing": "log"}}).entries[0].values == (1, 10, 100, 1000)
    large = _sweep({key: {"start": 2**62, "stop": 2**62 + 8, "num": 5}}).entries[0].values   # exact, past 2^53
    assert large == (2**62, 2**62 + 2, 2**62 + 4, 2**62 + 6, 2**62 + 8)
    listed = _sweep({key: [7, 3]}).entries[0].values
    assert listed == (7, 3) and all(type(v) is int for v in listed)


@pytest.mark.parametrize("spec, words", [
    ({"start": 0, "stop": 10, "num": 4}, "not a whole number"),         # 3.33...
    ([1.5], "not a whole number"),
    ([2.0], "not a whole number"),                                       # a float is not a seed, even a whole one
    ([2**64], "out of range"),
])
def test_a_whole_number_key_refuses_fractions(spec, words):
    err = _refused({"targets.seed": spec})
    assert err.key == "sweep.targets.seed" and words in err.problem


@pytest.mark.parametrize("path, location, whole", [
    ("contact.restitution", ("contact", "restitution"), False),
    ("body[ball].mass", ("body", 0, "mass"), False),
    ("body[0].position_world[2]", ("body", 0, "position_world", 2), False),
    ("body[ball].inertia_body_diagonal[1]", ("body", 0, "inertia_body_diagonal", 1), False),
    ("plane[floor].coefficients[3]", ("plane", 0, "coefficients", 3), False),
    ("plane[1].coefficients[3]", ("plane", 1, "coefficients", 3), False),   # no name: by index
    ("contact.pair[ball,floor].restitution", ("contact", "pair", 0, "restitution"), False),
    ("simulation.dt[1]", ("simulation", "dt", 1), False),
    ("simulation.dt", ("simulation", "dt"), True),                          # the ladder, swept whole
])
def test_a_path_reaches_keys_in_tables_arrays_of_tables_and_lists(path, location, whole):
    entry = _sweep({path: [1.0]}).entries[0]
    assert entry.location == location and entry.whole_list is whole


@pytest.mark.parametrize("path, words, allowed", [
    ("scene.name", "[scene] is never swept", "another table"),
    ("contact.colour", "the file sets no key colour in contact", "pair, restitution"),   # what the file sets there
    ("contact.friction_static", "sets no key friction_static", "restitution"),  # a default is not in the file
    ("body[ball].name", "holds the value 'ball', not a number", "one number"),
    ("body[ball].position_world", "holds a list of 3 values", "body[ball].position_world[0]"),
    ("contact", "holds a table", "one number"),
    ("body[bal].mass", "no entries of body match [bal]", "name"),
    ("body[5].mass", "body has 2 entries: there is no [5]", "0 to 1"),
    ("body[ball].mass[0]", "body[0].mass is not a list", "key path"),
    ("body[ball].position_world[x]", "is a list of values: [x] is not an index", "index"),
    ("body[ball].position_world[3]", "has 3 entries: there is no [3]", "0 to 2"),
    ("body[[x]].mass", "not a key path", "key path"),
    ("body.ball.mass", "body is not a table", "key path"),
    ("contact..restitution", "not a key path", "key path"),
    ("1body.mass", "not a key path", "key path"),
])
def test_a_path_that_reaches_no_number_is_refused(path, words, allowed):
    err = _refused({path: [1.0]})
    assert err.source == "s.toml" and err.key == f"sweep.{path}"
    assert words in err.problem and allowed in err.allowed


def test_an_index_naming_another_entry_is_ambiguous_but_the_entry_itself_is_not():
    """Body 1 is named "1": [1] is then that body by both readings, and fine; [0] reads as index 0."""
    assert _sweep({"body[1].mass": [1.0]}).entries[0].location == ("body", 1, "mass")
    data = dict(DATA, body=[DATA["body"][1], DATA["body"][0]])   # body 0 named "1", body 1 named "ball"
    assert "the name of another entry" in _refused({"body[1].mass": [1.0]}, data).problem


@pytest.mark.parametrize("spec, words", [
    ([], "an empty list"),
    ([0.5, "x"], "value 2 of the list: expected a number, got 'x'"),
    ([0.5, True], "value 2 of the list: expected a number"),
    ([0.5, float("nan")], "not a finite float"),
    ([float("inf")], "not a finite float"),
    ([10**400], "not a finite float"),
    ([0.5, 0.5], "the value 0.5 is given twice"),
    (0.5, "expected a list of numbers or a range table"),
    ("0.5", "expected a list of numbers or a range table"),
    ({"start": 0.1, "stop": 0.9}, "the range has no num"),
    ({"stop": 0.9, "num": 3}, "the range has no start"),
    ({"start": 0.1, "stop": 0.1, "num": 3}, "start and stop are both 0.1"),
    ({"start": 0.1, "stop": 0.9, "num": 1}, "range num: 1 values"),
    ({"start": 0.1, "stop": 0.9, "num": 3.0}, "range num: 3.0 values"),
    ({"start": 0.1, "stop": 0.9, "num": MAX_VARIANTS + 1}, f"range num: {MAX_VARIANTS + 1} values"),
    ({"start": 0.1, "stop": 0.9, "num": 3, "spacing": "cubic"}, "'cubic' is not a spacing"),
    ({"start": 0.0, "stop": 0.9, "num": 3, "spacing": "log"}, "reaches zero or below"),
    ({"start": -1.0, "stop": -0.1, "num": 3, "spacing": "log"}, "reaches zero or below"),
    ({"start": -1e308, "stop": 1e308, "num": 3}, "overflow"),
    ({"start": 1, "stop": 1.0000000000001, "num": 3},
     "3 values from 1.0 to 1.0000000000001 are too close to tell apart"),
    ({"start": 0.1, "stop": 0.9, "num": 3, "step": 0.1}, "'step' is not a range key"),
    ({"start": "a", "stop": 0.9, "num": 3}, "range start: expected a number"),
    ({"restitution": [0.5]}, "TOML reads a bare dotted key"),   # [sweep] contact.restitution = [...], unquoted
    ({}, "the range has no start"),
    (list(range(MAX_VARIANTS + 1)), f"{MAX_VARIANTS + 1:,} values"),
])
def test_bad_values_are_refused_with_what_is_allowed(spec, words):
    err = _refused({"contact.restitution": spec})
    assert err.key == "sweep.contact.restitution" and words in err.problem and err.allowed


def test_the_unquoted_dotted_key_is_answered_with_the_quoted_one():
    err = _refused({"contact": {"restitution": [0.5]}})
    assert err.key == "sweep.contact" and '"contact.restitution" = [...]' in err.allowed


@pytest.mark.parametrize("table, words", [
    ([1, 2], "expected a table"),
    ({}, "sweeps no key"),
    ({"combine": "zip"}, "sweeps no key"),
    ({"contact.restitution": [0.5], "combine": "cross"}, "'cross' is not allowed"),
    ({"contact.restitution": [0.1, 0.2], "body[0].mass": [1.0], "combine": "zip"}, "zips keys of 2, 1 values"),
    ({"contact.restitution": [0.1], "body[ball].restitution": [0.2], "body[0].mass": [1.0], "body[1].mass": [1.0],
      "simulation.duration": [2.0], "simulation.dt[0]": [0.001], "targets.seed": [1]}, "7 keys"),
    ({"contact.restitution": [k / 20 for k in range(11)], "body[0].mass": [1.0 + k for k in range(10)],
      "body[0].position_world[0]": [float(k) for k in range(10)]}, "11 x 10 x 10 = 1,100 variants"),
    ({"body[0].mass": [1.0], "body[ball].mass": [2.0]}, "the key body[0].mass sweeps too"),
])
def test_bad_tables_are_refused(table, words):
    err = _refused(table)
    assert words in err.problem and err.allowed and err.key.startswith("sweep")


def test_the_limits_are_the_documented_ones():
    """docs/scenes.md ("Limits") promises 1,000 variants and 6 keys (issue #29: sweeps of a thousand variants)."""
    assert (MAX_VARIANTS, MAX_KEYS) == (1000, 6)
    assert len(_sweep({"contact.restitution": [k / 1000 for k in range(1000)]}).combinations()) == MAX_VARIANTS
    assert len(_sweep({"contact.restitution": {"start": 0.0, "stop": 1.0, "num": 1000}}).combinations()) == 1000


def test_a_sweep_past_the_limit_is_refused_naming_the_limit_and_why():
    err = _refused({"contact.restitution": [k / 1000 for k in range(40)], "body[0].mass": [1.0 + k for k in range(26)]})
    text = str(err)
    assert "40 x 26 = 1,040 variants" in err.problem and "at most 1,000 variants" in err.allowed
    assert "each variant is a whole scene run by every engine" in err.allowed and "\n" not in text


def test_keys_combine_as_a_product_first_key_slowest_and_name_their_variants():
    sweep = _sweep({"contact.restitution": [0.3, 0.9], "body[ball].position_world[0]": [-1.0, 0.0, 2.5]})
    assert sweep.combinations() == [(0.3, -1.0), (0.3, 0.0), (0.3, 2.5), (0.9, -1.0), (0.9, 0.0), (0.9, 2.5)]
    assert sweep.names() == ["bounce_restitution-0.3_position_world.0--1.0", "bounce_restitution-0.3_position_world.0-0.0",
                             "bounce_restitution-0.3_position_world.0-2.5", "bounce_restitution-0.9_position_world.0--1.0",
                             "bounce_restitution-0.9_position_world.0-0.0", "bounce_restitution-0.9_position_world.0-2.5"]


def test_zip_pairs_the_kth_values():
    sweep = _sweep({"body[0].mass": [1.0, 2.0], "targets.seed": [5, 6], "combine": "zip"})
    assert sweep.combinations() == [(1.0, 5), (2.0, 6)]
    assert sweep.names() == ["bounce_mass-1.0_seed-5", "bounce_mass-2.0_seed-6"]


def test_labels_grow_until_they_tell_keys_apart():
    sweep = _sweep({"contact.restitution": [0.1], "body[ball].restitution": [0.2],
                    "contact.pair[ball,floor].restitution": [0.3]})
    assert sweep.names() == ["bounce_contact.restitution-0.1_body.ball.restitution-0.2_pair.ball_floor.restitution-0.3"]


def test_names_show_exponents_and_ints_in_name_characters():
    names = _sweep({"simulation.dt[0]": [1e-5, 1e20], "targets.seed": [3]}).names()
    assert names == ["bounce_dt.0-1e-05_seed-3", "bounce_dt.0-1e20_seed-3"]
    assert not any(name_problem(n) for n in names)


def test_names_too_long_for_a_name_are_numbered():
    """Past NAME_MAX characters every variant is the base name (cut to fit) and its zero-padded number."""
    base = "b" * (NAME_MAX - len("_restitution-0.1"))   # restitution 0.1 fits; 0.05 does not
    names = _sweep({"contact.restitution": [k / 20 for k in range(12)]}, base=base).names()
    assert names[0] == base + "_01" and names[-1] == base + "_12"
    longest = _sweep({"contact.restitution": [0.1, 0.2]}, base="b" * NAME_MAX).names()
    assert longest == ["b" * (NAME_MAX - 2) + "_1", "b" * (NAME_MAX - 2) + "_2"]
    assert not any(name_problem(n) for n in names + longest)


def test_variants_write_their_values_and_leave_the_file_untouched():
    sweep = _sweep({"body[ball].position_world[2]": [2.0, 3.0], "simulation.dt": [0.01]})
    (name, data, point), _ = sweep.variants(DATA)
    assert name == "bounce_position_world.2-2.0_dt-0.01"
    assert data["body"][0]["position_world"] == [0.0, 0.0, 2.0] and data["simulation"]["dt"] == [0.01]  # a ladder of one
    assert DATA["body"][0]["position_world"] == [0.0, 0.0, 1.1] and DATA["simulation"]["dt"] == [0.0025, 0.005, 0.01]
    assert point == SweepPoint("bounce", (("body[ball].position_world[2]", 2.0), ("simulation.dt", 0.01)), 0, 2)


def test_a_variants_error_names_the_sweep_key_and_value_or_every_value():
    sweep = _sweep({"contact.restitution": [0.5, 1.5], "body[ball].position_world[2]": [1.1]})
    point = sweep.variants(DATA)[1][2]
    own = sweep.refusal(SceneError("s.toml", "contact.restitution", "1.5 is outside [0, 1]", "0 to 1"), point)
    assert str(own) == ("s.toml: sweep.contact.restitution: 1.5 (variant 2 of 2, with body[ball].position_world[2] = 1.1): "
                        "contact.restitution: 1.5 is outside [0, 1] (allowed: 0 to 1)")
    vector = sweep.refusal(SceneError("s.toml", "body[0].position_world", "inside the plane", "outside"), point)
    assert vector.key == "sweep.body[ball].position_world[2]"   # the vector that holds the swept entry
    other = sweep.refusal(SceneError("s.toml", "scene.reference", "cannot serve", "another"), point)
    assert other.key == "sweep" and other.problem == ("variant 2 of 2 (contact.restitution = 1.5, "
                                                      "body[ball].position_world[2] = 1.1): scene.reference: cannot serve")
