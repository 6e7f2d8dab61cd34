"""Every kind of scene a file may declare has its module on both sides: the type in ``core.model.scenes`` and its
reader in ``comparisons.scenes.loading``, and ``Scene`` is exactly those types."""

import importlib
import typing

from simparity.comparisons.scenes.loading.scene_file import KINDS
from simparity.core.model.scenes.kinds import Scene


def test_every_kind_has_its_type_and_its_reader():
    types = {cls.__dataclass_fields__["kind"].default: cls for cls in typing.get_args(Scene)}
    assert sorted(types) == sorted(KINDS)
    for kind, cls in types.items():
        assert cls.__module__ == f"simparity.core.model.scenes.{kind}"
        reader = importlib.import_module(f"simparity.comparisons.scenes.loading.{kind}")
        assert callable(getattr(reader, f"read_{kind}"))
