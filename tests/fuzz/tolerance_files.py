"""Tolerance files that match nothing or mean nothing (issue #39, section 2): one valid bound of the stored run with
one key made unknown, a regular expression where a glob is meant, an empty or meaningless range, a number out of
range or of a wrong type; top-level keys of wrong types; a file of 100,000 bounds. Each through ``simparity check
RUN --tolerances FILE``: refused in one line naming the file and the key."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from tests.fuzz.files import pick, seed_of
from tests.fuzz.oracle import EITHER, FAILS, REFUSED, VALID, Base, Call, Case

FILE_NAME = "fuzzed-tolerances.toml"
VALID_BOUNDS = (
    {"integrator": "rk4", "metric": "position_error_max", "max": 1.0},
    {"integrator": "midpoint", "metric": "velocity_error_max", "max": 10.0},
    {"integrator": "explicit_euler", "metric": "position_error_final", "max": 100.0},
    {"integrator": "semi_implicit_euler", "metric": "energy_drift_max", "max": 100.0},
)
"""Bounds every row of the stored run (lecture-projectile, core, quick) meets, one drawn per case [SI units]."""

BAD_VALUES: dict[str, tuple[str, ...]] = {
    "scene": ('"no-such-scene"', '"lecture-projectil"', '"lecture-.*"', '"^lecture-projectile$"',
              '"(lecture|x)-projectile"'),
    "engine": ('"mujocoo"', '"nosuch"', '"^core$"', '"core|mujoco"', '"c.re"'),
    "integrator": ('"rk5"', '"rk4$"', '"rk4|midpoint"', '"RK4"'),
    "scheme": ('"rk44"', '"rk.*"', '"semi-implicit euler"', '["rk4", "nosuch"]'),
    "metric": ('"position_eror_max"', '"position_.*"', '"^position_error_max$"'),
    "max": ("nan", "inf", "-inf", "-1.0", '"1"', "true", "[1.0]"),
    "min": ("nan", "-inf", "inf", '"0"'),
    "dt_power": ("1e308", "nan", "-1e308", "inf", '"1"'),
    "expected": ("nan", "inf", '"x"'),
    "band": ("-1.0", "nan", "inf"),
    "rel": ("-1.0", "nan", "inf"),
    "status": ('"okk"', "3", '["ok", "weird"]', "[]"),
    "na_when": ('"nothing"', '["nope"]', "[1]"),
    "reason": ("5", "[]"),
    "dt": ('"abc"', "-0.01", "nan", "0.0", "1e308"),
    "maxx": ("1.0",),
}
"""key -> TOML values that match nothing or mean nothing there (``maxx``: a key no bound has)."""

TOP_LEVEL: dict[str, tuple[str, str]] = {
    "check_engines unknown": ('check_engines = ["nosuch"]', "check_engines"),
    "check_engines a string": ('check_engines = "core"', "check_engines"),
    "check_engines empty": ("check_engines = []", "check_engines"),
    "require_engines of numbers": ("require_engines = [1]", "require_engines"),
    "require_engines unknown": ('require_engines = ["mujocoo"]', "require_engines"),  # FAILS: see cases()
    "extends a missing file": ('extends = "missing.toml"', "extends"),
    "extends a folder": ('extends = "/"', "extends"),
    "extends a number": ("extends = 3", "extends"),
    "extends /proc": ('extends = "/proc/self/status"', "extends"),
    "bound a number": ("bound = 3", "bound"),
    "bound a table": ('[bound]\nmetric = "position_error_max"\nmax = 1.0\nreason = "r"', "bound"),
    "bound an empty table": ("[[bound]]", "bound"),
}
"""A whole file's text: top-level keys of wrong types or pointing nowhere."""

HUGE_BOUNDS = 100_000
"""Bounds of the file that ran past 60 s (matching quadratic in bounds x rows): it must answer in the timeout, or be
refused by a documented size limit."""


def _bound(fields: dict[str, object], extra: str = "") -> str:
    lines = ["[[bound]]", 'scene = "lecture-projectile"', 'engine = "core"']
    for key, value in fields.items():
        lines.append(f'{key} = "{value}"' if isinstance(value, str) else f"{key} = {value!r}")
    return "\n".join(lines + ['reason = "fuzz"', extra]) + "\n"


def _one_key(key: str, text: str, seed: int, folder: Path, base: Base) -> Call:
    bound = dict(pick(np.random.default_rng(seed), VALID_BOUNDS))
    lines = _bound(bound).splitlines()
    lines = [line for line in lines if not line.startswith(f"{key} = ")] + [f"{key} = {text}"]
    return _write(folder, base, "\n".join(lines) + "\n", (key,))


def _min_above_max(seed: int, folder: Path, base: Base) -> Call:
    rng = np.random.default_rng(seed)
    low = float(rng.uniform(0.0, 10.0))
    bound = dict(pick(rng, VALID_BOUNDS), min=low + float(rng.uniform(1e-6, 10.0)), max=low)
    return _write(folder, base, _bound(bound), ("min", "max"))


def _text(text: str, names: tuple[str, ...], folder: Path, base: Base) -> Call:
    return _write(folder, base, text + "\n", names)


def _huge(seed: int, folder: Path, base: Base) -> Call:
    rng = np.random.default_rng(seed)
    metrics = [pick(rng, VALID_BOUNDS)["metric"] for _ in range(HUGE_BOUNDS)]
    text = "".join(f'[[bound]]\nscene="lecture-projectile"\nmetric="{metric}"\nmax={1e3 + k}\nreason="f"\n'
                   for k, metric in enumerate(metrics))  # compact: under the 10 MB file limit
    return _write(folder, base, text, ())


def _control(seed: int, folder: Path, base: Base) -> Call:
    return _write(folder, base, _bound(dict(pick(np.random.default_rng(seed), VALID_BOUNDS))), ())


def _write(folder: Path, base: Base, text: str, keys: tuple[str, ...]) -> Call:
    path = folder / FILE_NAME
    path.write_text(text, encoding="utf-8")
    # the line names the file and the key; a file name alone is accepted for what has no key
    return Call(argv=("check", str(base.run_dir), "--tolerances", str(path)), names=(FILE_NAME,) if not keys else
                tuple(f"{k}" for k in keys))


def cases(rng: np.random.Generator) -> list[Case]:
    found = [Case("tolerance_files", f"{key} = {text}", partial(_one_key, key, text, seed_of(rng)),
                  EITHER if (key, text) == ("dt", "1e308") else REFUSED)
             for key, texts in BAD_VALUES.items() for text in texts]
    found += [Case("tolerance_files", f"min above max #{k}", partial(_min_above_max, seed_of(rng))) for k in range(3)]
    # an engine required and not in the run fails the check (exit 1, documented); one that exists nowhere may be
    # refused as well
    found += [Case("tolerance_files", name, partial(_text, text, (key,)), FAILS if name == "require_engines unknown"
                   else REFUSED) for name, (text, key) in TOP_LEVEL.items()]
    found.append(Case("tolerance_files", f"{HUGE_BOUNDS:,} bounds", partial(_huge, seed_of(rng)), EITHER,
                      note="valid bounds: passes fast, or refused by a documented size limit"))
    found += [Case("tolerance_files", f"control: a valid bound #{k}", partial(_control, seed_of(rng)), VALID)
              for k in range(2)]
    return found
