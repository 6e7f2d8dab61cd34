"""run.json through one dataclass: what is written is read back equal; what is not a run's information is refused."""

import json

import pytest

from simparity.core.model.errors import ResultsError
from simparity.core.model.run_info import RunInfo


def test_run_info_round_trips(tmp_path):
    info = RunInfo(created_utc="2026-11-26T10:00:00+00:00", command="simparity run", git_commit="abc",
                   machine={"cpu_count": 2}, engine_versions={"core": "1"}, theoretical_orders={"core": {"rk4": 4}},
                   integrator_variants={"core": {"rk4+matrix": ["rk4", "matrix"]}},
                   scenes={"s": {"kind": "dynamics"}}, peak_memory={"this_process_bytes": 1, "largest_child_bytes": 2})
    info.write(tmp_path / "run.json")
    assert RunInfo.read(tmp_path / "run.json") == info
    assert info.scene("s") == {"kind": "dynamics"} and info.scene("other") == {}


def test_an_older_run_reads_with_defaults_and_a_newer_field_is_left_out(tmp_path):
    (tmp_path / "run.json").write_text(json.dumps({"schema_version": 1, "command": "x", "added_later": [1]}))
    info = RunInfo.read(tmp_path / "run.json")
    assert info.command == "x" and info.scenes == {} and info.peak_memory == {} and not hasattr(info, "added_later")


@pytest.mark.parametrize("text, problem", [
    ("{", "not JSON"), ("[1]", "a list .* the run.json"), ('{"schema_version": 99}', "schema_version 99"),
    ('{"schema_version": 2, "scenes": []}', "scenes: a list"),
    ('{"schema_version": 2, "command": 3}', "command: a number 3 .allowed: text"),
    ('{"schema_version": 2, "peak_memory": 300}', "peak_memory: a number 300 .allowed: a table"),
])
def test_what_is_not_a_run_s_information_is_refused_in_one_line(tmp_path, text, problem):
    (tmp_path / "run.json").write_text(text)
    with pytest.raises(ResultsError, match=problem):
        RunInfo.read(tmp_path / "run.json")
