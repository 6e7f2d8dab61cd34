"""A chain driven by a torque that changes with time: the work the torque does enters its power balance and its
energy budget (a held-out check found a joint driven from rest by a timed torque alone judged diverged, the closed
form included, and a power balance that left the torque's work out)."""

from __future__ import annotations

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes.library import resolve

@pytest.mark.slow
def test_a_joint_driven_from_rest_by_a_timed_torque_alone_passes_and_balances(tmp_path, capsys):
    text = resolve("driven-damped-joint").read_text(encoding="utf-8")
    text = text.replace('name = "driven-damped-joint"', 'name = "driven-from-rest"')  # the built-in's bounds are its own
    text = text.replace("qdot = [6.0]", "qdot = [0.0]").replace("[drive]\ntorque = [0.2]", "[drive]\ntorque = [0.0]")
    scene = tmp_path / "from-rest.toml"
    scene.write_text(text, encoding="utf-8")
    out = tmp_path / "run"
    code = main(["run", str(scene), "--engines", "core,analytic", "--quick", "--check", "--out", str(out),
                 "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    assert code == 0, capsys.readouterr().out[-2000:]
    table = pd.read_csv(out / "results.csv")
    assert not (table.status == "diverged").any()
    balance = table[(table.engine == "analytic") & (table.metric == "power_balance_residual_max")]
    assert len(balance) and (balance.flag == "rounding-floor").all()  # the truth balances to its quadrature's floor
