"""Damaged run folders (issue #39, section 1): ``results.csv``, ``run.json`` and ``series.csv.gz`` of a valid run
broken one way each, read through ``simparity check DIR``, ``simparity check --baseline DIR``, ``simparity report
DIR`` and ``simparity.read_run``. A damaged run is refused in one line naming its file; a run that checks nothing
fails; the untouched copy (the control) passes."""

from __future__ import annotations

import gzip
import json
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

from tests.fuzz.files import copy_run, pick, read_rows, seed_of, write_rows
from tests.fuzz.oracle import EITHER, FAILS, REFUSED, VALID, Base, Call, Case

ROUTES = ("check", "read_run", "baseline")
"""How a damaged run is read: every damage through the first two, a drawn half also as another run's baseline;
``report`` (seconds per input when it renders) takes :data:`REPORTED` drawn damages."""
REPORTED = 4
"""Damages of each file also tried through ``simparity report``, drawn by the generator's seed."""
RUN_BASELINE = ("header only", "nan value with status ok", "binary results.csv")
"""results.csv damages also given as ``simparity run --check --baseline DIR`` (a run of the tiny scene, seconds, where
the baseline is read only when the run is done)."""

Damage = Callable[[Path, np.random.Generator], None]
"""Breaks the run copied into the given folder, with its own seeded generator."""


def _ok_row(rows: list[list[str]], header: list[str], rng: np.random.Generator) -> list[str]:
    status = header.index("status")
    ok = [row for row in rows if row[status] == "ok"]
    return pick(rng, ok)


def _cells(column: str, texts: tuple[str, ...]) -> Damage:
    """Writes one of ``texts`` into ``column`` of a random row whose status is ok."""

    def damage(run: Path, rng: np.random.Generator) -> None:
        header, rows = read_rows(run / "results.csv")
        _ok_row(rows, header, rng)[header.index(column)] = pick(rng, texts)
        write_rows(run / "results.csv", header, rows)

    return damage


def _header_only(run, rng):
    path = run / "results.csv"
    path.write_text(path.read_text(encoding="utf-8").splitlines()[0] + "\n", encoding="utf-8")


def _rename_column(run, rng):
    header, rows = read_rows(run / "results.csv")
    header[int(rng.integers(len(header)))] = pick(rng, ("Value", "col", "scene ", "metrics", "status2"))
    write_rows(run / "results.csv", header, rows)


def _foreign_header(run, rng):
    header, rows = read_rows(run / "results.csv")
    write_rows(run / "results.csv", [f"c{k}" for k in range(len(header))], rows)


def _drop(column: str | None) -> Damage:
    def damage(run, rng):
        header, rows = read_rows(run / "results.csv")
        k = header.index(column) if column else int(rng.integers(len(header) - 1))
        write_rows(run / "results.csv", header[:k] + header[k + 1:], [row[:k] + row[k + 1:] for row in rows])

    return damage


def _extra_column(run, rng):
    header, rows = read_rows(run / "results.csv")
    k = int(rng.integers(len(header) + 1))
    name = pick(rng, ("extra", "note", "value2"))
    write_rows(run / "results.csv", header[:k] + [name] + header[k:],
               [row[:k] + [str(rng.random())] + row[k:] for row in rows])


def _reorder(run, rng):
    header, rows = read_rows(run / "results.csv")
    order = rng.permutation(len(header))
    write_rows(run / "results.csv", [header[k] for k in order], [[row[k] for k in order] for row in rows])


def _cut_mid_line(run, rng):
    text = (run / "results.csv").read_text(encoding="utf-8")
    lines = text.splitlines(keepends=True)
    k = int(rng.integers(2, len(lines)))
    cut = lines[k][: int(rng.integers(5, len(lines[k]) - 5))]
    (run / "results.csv").write_text("".join(lines[:k]) + cut, encoding="utf-8")


def _repeated_header(run, rng):
    lines = (run / "results.csv").read_text(encoding="utf-8").splitlines(keepends=True)
    k = int(rng.integers(2, len(lines)))
    (run / "results.csv").write_text("".join(lines[:k] + [lines[0]] + lines[k:]), encoding="utf-8")


def _ragged(run, rng):
    header, rows = read_rows(run / "results.csv")
    row = pick(rng, rows)
    if rng.random() < 0.5:
        del row[int(rng.integers(len(row)))]
    else:
        row.append("surplus")
    write_rows(run / "results.csv", header, rows)


def _bytes(file: str, size: tuple[int, int]) -> Damage:
    def damage(run, rng):
        (run / file).write_bytes(rng.integers(0, 256, int(rng.integers(*size)), dtype=np.uint8).tobytes())

    return damage


def _empty(file: str) -> Damage:
    def damage(run, rng):
        (run / file).write_bytes(b"")

    return damage


def _folder(file: str) -> Damage:
    def damage(run, rng):
        (run / file).unlink()
        (run / file).mkdir()

    return damage


def _latin1_detail(run, rng):
    header, rows = read_rows(run / "results.csv")
    pick(rng, rows)[header.index("detail")] = "caf\u00e9"
    text = "\n".join(",".join(f'"{c}"' for c in row) for row in [header, *rows]) + "\n"
    (run / "results.csv").write_bytes(text.encode("latin-1"))


def _parquet_nan_ok(run, rng):
    """A results.parquet newer than the CSV (read first) with nan in a row whose status is ok."""
    import pandas as pd

    table = pd.read_csv(run / "results.csv", keep_default_na=False, na_values={"value": [""], "dt": [""]})
    ok = np.flatnonzero((table["status"] == "ok").to_numpy())
    table.loc[int(pick(rng, ok)), "value"] = pick(rng, (np.nan, np.inf))
    table.to_parquet(run / "results.parquet", engine="pyarrow", index=False)


RESULTS_DAMAGES: dict[str, tuple[Damage, frozenset[int]]] = {
    "header only": (_header_only, FAILS),
    "header renamed": (_rename_column, REFUSED),
    "foreign header": (_foreign_header, REFUSED),
    "scheme column dropped": (_drop("scheme"), REFUSED),
    "a column dropped": (_drop(None), REFUSED),
    "extra column": (_extra_column, REFUSED),
    "columns reordered": (_reorder, EITHER),
    "text in value": (_cells("value", ("abc", "1.0.0", "0x10", "1,5", "--1")), REFUSED),
    "text in dt": (_cells("dt", ("abc", "0.01s", "1e", "None")), REFUSED),
    "nan value with status ok": (_cells("value", ("nan", "NaN", "")), REFUSED),
    "inf value with status ok": (_cells("value", ("inf", "-inf", "1e999", "Infinity")), REFUSED),
    "5001-digit value": (_cells("value", ("1" + "0" * 5000,)), REFUSED),
    "unknown status": (_cells("status", ("passed", "OK", "okay", "fail", "")), REFUSED),
    "row cut mid-line": (_cut_mid_line, REFUSED),
    "repeated header row": (_repeated_header, REFUSED),
    "ragged row": (_ragged, REFUSED),
    "empty results.csv": (_empty("results.csv"), REFUSED),
    "binary results.csv": (_bytes("results.csv", (16, 4096)), REFUSED),
    "results.csv a folder": (_folder("results.csv"), REFUSED),
    "latin-1 results.csv": (_latin1_detail, REFUSED),
    "parquet with nan in an ok row": (_parquet_nan_ok, REFUSED),
}
"""results.csv damages: name -> (damage, exit codes accepted through check / read_run / baseline)."""


def _json(edit: Callable[[dict, np.random.Generator], object]) -> Damage:
    """Rewrites run.json as ``edit`` leaves it (or, if it returns text, that text)."""

    def damage(run, rng):
        data = json.loads((run / "run.json").read_text(encoding="utf-8"))
        text = edit(data, rng)
        (run / "run.json").write_text(text if isinstance(text, str) else json.dumps(data), encoding="utf-8")

    return damage


def _deep(data, rng):
    depth = pick(rng, (100_000, 20_000))
    return json.dumps(data)[:-1] + ', "machine2": ' + "[" * depth + "]" * depth + "}"


def _deep_known(data, rng):
    depth = 100_000
    return json.dumps(dict(data, machine={}))[:-1].replace('"machine": {}', '"machine": ' + '{"a": ' * depth + "1"
                                                            + "}" * depth) + "}"


def _digits(data, rng):
    key = pick(rng, ("schema_version", "peak_memory"))
    big = "1" + "0" * 5000
    if key == "schema_version":
        return json.dumps(data).replace('"schema_version": 2', f'"schema_version": {big}')
    text = json.dumps(dict(data, peak_memory={}))
    return text.replace('"peak_memory": {}', '"peak_memory": {"this_process_bytes": ' + big + "}")


def _scenes_entry_text(data, rng):
    data["scenes"]["lecture-projectile"] = pick(rng, ("dynamics", "", "x" * 1000))


def _orders_text(data, rng):
    orders = data["theoretical_orders"]["core"]
    orders[pick(rng, sorted(orders))] = pick(rng, ("four", "1", "", "nan"))


def _orders_out_of_range(data, rng):
    orders = data["theoretical_orders"]["core"]
    orders[pick(rng, sorted(orders))] = pick(rng, (float("nan"), float("inf"), -1, 10**30))


WRONG_TYPED = ([1, 2], 3, "text", None, True, 2.5, {"a": 1})
RUN_INFO_KEYS = ("schema_version", "created_utc", "command", "git_commit", "machine", "engine_versions",
                 "theoretical_orders", "integrator_variants", "scenes", "profile", "peak_memory")


def _wrong_type(key: str):
    def edit(data, rng):
        right = type(data[key])
        data[key] = pick(rng, [v for v in WRONG_TYPED if type(v) is not right and not (right is int and v is True)])

    return edit


def _variants_text(data, rng):
    data["integrator_variants"]["core"][pick(rng, sorted(data["integrator_variants"]["core"]))] = "rk4"


def _versions_not_text(data, rng):
    data["engine_versions"]["core"] = pick(rng, ([1, 2], 3, None, {"a": 1}))


RUN_INFO_DAMAGES: dict[str, tuple[Damage, frozenset[int]]] = {
    "run.json nested 100,000 deep": (_json(_deep), REFUSED),
    "run.json machine nested 100,000 deep": (_json(_deep_known), REFUSED),
    "run.json 5001-digit integer": (_json(_digits), REFUSED),
    "run.json scenes entry a string": (_json(_scenes_entry_text), REFUSED),
    "run.json theoretical order a string": (_json(_orders_text), REFUSED),
    "run.json theoretical order not a positive number": (_json(_orders_out_of_range), REFUSED),
    "run.json integrator variant not a pair": (_json(_variants_text), REFUSED),
    "run.json engine version not text": (_json(_versions_not_text), REFUSED),
    **{f"run.json {key} of a wrong type": (_json(_wrong_type(key)), REFUSED) for key in RUN_INFO_KEYS},
    "run.json a list": (_json(lambda data, rng: "[1, 2]"), REFUSED),
    "run.json empty": (_empty("run.json"), REFUSED),
    "run.json binary": (_bytes("run.json", (16, 2048)), REFUSED),
    "run.json a folder": (_folder("run.json"), REFUSED),
}
"""run.json damages (each through check, read_run and baseline)."""


def _series_text(text: str) -> Damage:
    def damage(run, rng):
        (run / "series.csv.gz").write_bytes(gzip.compress(text.encode()))

    return damage


def _series_value(texts: tuple[str, ...]) -> Damage:
    def damage(run, rng):
        lines = gzip.decompress((run / "series.csv.gz").read_bytes()).decode().splitlines()
        k = int(rng.integers(1, len(lines)))
        cells = lines[k].split(",")
        cells[-1] = pick(rng, texts)
        lines[k] = ",".join(cells)
        (run / "series.csv.gz").write_bytes(gzip.compress(("\n".join(lines) + "\n").encode()))

    return damage


SERIES_DAMAGES: dict[str, tuple[Damage, frozenset[int]]] = {
    "series.csv.gz empty": (_empty("series.csv.gz"), REFUSED),
    "series.csv.gz not gzip": (_bytes("series.csv.gz", (16, 2048)), REFUSED),
    "series.csv.gz gzip of nothing": (_series_text(""), REFUSED),
    "series.csv.gz header only": (_series_text("scene,engine,integrator,dt,quantity,unit,x,value\n"), EITHER),
    "series.csv.gz foreign columns": (_series_text("a,b\n1,2\n"), REFUSED),
    "series.csv.gz text in a value": (_series_value(("abc", "1.0.0")), REFUSED),
    "series.csv.gz a folder": (_folder("series.csv.gz"), REFUSED),
}
"""series.csv.gz damages, read by ``simparity report`` (check and read_run do not read the series)."""


def _build(damage: Damage, seed: int, route: str, file: str, folder: Path, base: Base) -> Call:
    run = copy_run(base, folder)
    damage(run, np.random.default_rng(seed))
    names = (file, "results.parquet") if file == "results.csv" else (file,)
    if route == "read_run":
        from simparity.reports.store import read_run

        return Call(function=partial(read_run, run), names=names)
    if route == "baseline":
        return Call(argv=("check", str(base.run_dir), "--baseline", str(run)), names=names)
    if route == "run --baseline":
        return Call(argv=("run", str(base.scene), "--engines", "core", "--jobs", "1", "--quick", "--out",
                          str(folder / "out"), "--check", "--allow-unbounded", "--baseline", str(run)), names=names)
    return Call(argv=(route, str(run)), names=names)


def _control(route: str, folder: Path, base: Base) -> Call:
    return _build(lambda run, rng: None, 0, route, "results.csv", folder, base)


def _no_series(route: str, folder: Path, base: Base) -> Call:
    return _build(lambda run, rng: (run / "series.csv.gz").unlink(), 0, route, "series.csv.gz", folder, base)


def _cases(family: str, damages: dict[str, tuple[Damage, frozenset[int], str]], rng: np.random.Generator,
           ) -> list[Case]:
    """Each damage through ``check`` and ``read_run``, a drawn half also as a baseline and :data:`REPORTED` through
    ``report``."""
    names = sorted(damages)
    baseline = set(rng.choice(names, len(names) // 2, replace=False))
    reported = set(rng.choice(names, REPORTED, replace=False))
    found = []
    for name, (damage, accept, file) in damages.items():
        routes = ("check", "read_run") + (("baseline",) if name in baseline else ()) + (("report",) if name in reported
                                                                                        else ())
        for route in routes:
            build = partial(_build, damage, seed_of(rng), route, file)
            found.append(Case(family, f"{name} via {route}", build, accept))
    return found


def results_cases(rng: np.random.Generator) -> list[Case]:
    """results.csv damages, and the controls: the valid run, and one stored without series."""
    found = _cases("run_results", {name: (damage, accept, "results.csv")
                                   for name, (damage, accept) in RESULTS_DAMAGES.items()}, rng)
    for name in RUN_BASELINE:
        damage, accept = RESULTS_DAMAGES[name]
        found.append(Case("run_results", f"{name} via run --baseline",
                          partial(_build, damage, seed_of(rng), "run --baseline", "results.csv"), accept))
    for route in ROUTES:
        found.append(Case("run_results", f"control: the valid run via {route}", partial(_control, route), VALID))
        found.append(Case("run_results", f"control: no series.csv.gz via {route}", partial(_no_series, route), VALID,
                          note="a run stored without series is readable (reports.store.read_series)"))
    return found


def info_cases(rng: np.random.Generator) -> list[Case]:
    """run.json damages, and series.csv.gz damages through ``report``."""
    found = _cases("run_info", {name: (damage, accept, "run.json")
                                for name, (damage, accept) in RUN_INFO_DAMAGES.items()}, rng)
    for name, (damage, accept) in SERIES_DAMAGES.items():
        found.append(Case("run_info", f"{name} via report",
                          partial(_build, damage, seed_of(rng), "report", "series.csv.gz"), accept))
    return found
