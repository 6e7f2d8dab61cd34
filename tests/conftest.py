"""Shared test set-up: runs the tests make never touch the user's run history."""

import pytest

from simparity.comparisons.gate.history import HISTORY_ENV


@pytest.fixture(autouse=True)
def _private_history(tmp_path_factory, monkeypatch):
    """Every test records runs into its own history database, not simparity-results/ in the checkout."""
    monkeypatch.setenv(HISTORY_ENV, str(tmp_path_factory.mktemp("history") / "history.sqlite"))
