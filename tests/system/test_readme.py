"""The README's recipes work as written."""

import math
import re
from pathlib import Path

from simparity.comparisons.pipeline.run_info import describe_run

from simparity.reports.store import RunWriter
from simparity.core.model.results import ResultRow

README = Path(__file__).resolve().parents[2] / "README.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_loading_recipes_give_numeric_columns_and_keep_n_a(tmp_path):
    """Both loading recipes read dt and value as numbers and the status n/a as text."""
    writer = RunWriter(tmp_path, describe_run([], "test", []))
    writer.append([ResultRow("s", "core", "rk4", 0.01, "m", 1.5, "m", "r", "ok"),
                   ResultRow("s", "core", "", math.nan, "m", math.nan, "m", "r", "n/a", "why")])
    pandas_recipe = next(b for b in _python_blocks() if "pd.read_csv(path" in b)
    namespace = {"path": tmp_path / "results.csv"}
    exec(pandas_recipe, namespace)  # noqa: S102 - the README's own code
    api_recipe = next(b for b in _python_blocks() if "from simparity import read_run" in b)
    api_namespace: dict = {}
    exec(api_recipe.replace('"simparity-results/20261122-073722"', repr(str(tmp_path))), api_namespace)  # noqa: S102
    for table in (namespace["table"], api_namespace["table"]):
        assert table["dt"].dtype.kind == "f" and table["value"].dtype.kind == "f"
        assert list(table["status"]) == ["ok", "n/a"] and math.isnan(table["value"].iloc[1])
