"""``simparity.core.scene``, the path plugins import the scene types by (docs/plugins.md): every public name the
modules of ``simparity.core.model.scenes`` define, as the same object."""

import ast
import importlib
import pkgutil
from pathlib import Path

import simparity.core.model.scenes as scenes
import simparity.core.scene as alias

DOCUMENTED = ("DynamicsScene", "RigidBody", "Forces", "Contact", "Chain", "Joint", "LinkInertia", "KinematicsScene",
              "IKScene", "JointDynamicsScene", "JointMotionScene")
"""The names docs/plugins.md lists for ``simparity.core.scene``."""

SHARED_CHECKS = "checks"
"""The package's module of checks its types share (unit vectors, symmetric tensors): not scene types."""


def _defined_names() -> dict[str, object]:
    """Public names the package's modules define at their top level (classes, functions, constants), with their
    objects; names a module imports are not its own."""
    found: dict[str, object] = {}
    for info in pkgutil.iter_modules(scenes.__path__):
        if info.name == SHARED_CHECKS:
            continue
        module = importlib.import_module(f"{scenes.__name__}.{info.name}")
        tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
        for node in tree.body:
            names = ([node.name] if isinstance(node, (ast.ClassDef, ast.FunctionDef))
                     else [t.id for t in node.targets if isinstance(t, ast.Name)] if isinstance(node, ast.Assign)
                     else [])
            found.update((name, getattr(module, name)) for name in names if not name.startswith("_"))
    return found


def test_the_alias_re_exports_every_public_name_of_the_scene_modules():
    defined = _defined_names()
    assert set(DOCUMENTED) <= set(defined)
    missing = sorted(name for name, value in defined.items() if getattr(alias, name, None) is not value)
    assert not missing, f"simparity.core.scene lacks {missing}"
