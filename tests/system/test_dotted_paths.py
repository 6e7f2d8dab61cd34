"""Every dotted module path the docs and docstrings name resolves in the package as it is.

A path is ``core.…``, ``references.…``, ``comparisons.…`` or ``reports.…``, with or without ``simparity.``,
bare, in a ``:mod:``/``:func:`` role or as ``pkg.module.Name``: it resolves if a prefix of it is a module or
package of the checkout and the rest are names found in it (a top-level definition or import, a class's
attribute, a method's ``self.`` attribute, a name a ``*`` import brings), read from the module's source with
``ast``: nothing is imported, so the test is fast and needs no engine installed. Scanned: the triple-quoted
strings (docstrings, attribute docstrings, help) and comments of the checkout's ``.py`` files (tests and examples
included) and its Markdown documents.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "simparity"
LAYERS = ("core", "references", "comparisons", "reports")
DOCUMENTS = ("ARCHITECTURE.md", "README.md", "BENCHMARKS.md", "docs/*.md", "examples/*/README.md")
# Folders of the checkout that are not the package's source (builds, environments, the typecheck link).
NOT_SOURCE = {".typecheck", ".venv", "build", "dist", "simparity-results", ".git", "__pycache__"}

# A dotted path rooted at a layer; not part of a longer dotted name or file path (``tests.mutation.core.x``,
# ``…/core.py``), since those name other packages.
DOTTED = re.compile(
    rf"(?<![\w./-])(?:{PACKAGE}\.)?(?:{'|'.join(LAYERS)})(?:\.[A-Za-z_]\w*)+"
)
# A triple-quoted string: docstrings and the texts written like them (help, messages).
TRIPLE_QUOTED = re.compile(r'"""(?:[^"\\]|\\.|"(?!""))*"""|' + r"'''(?:[^'\\]|\\.|'(?!''))*'''", re.S)
# A path that names a file of the checkout rather than a module (``core.py``): not a dotted module path.
FILE_SUFFIX = re.compile(r"\.(?:py|md|toml|csv|json|txt|gz|parquet|sqlite|html|png|svg)$")


def _source_files() -> list[Path]:
    return sorted(
        path for path in ROOT.rglob("*.py") if not NOT_SOURCE.intersection(path.relative_to(ROOT).parts)
    )


def _module_file(dotted: str) -> Path | None:
    """The file of module ``dotted`` (without ``simparity.``), or None when it is no module of the checkout."""
    base = ROOT.joinpath(*dotted.split("."))
    for candidate in (base / "__init__.py", base.with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def _self_attributes(function: ast.AST) -> set[str]:
    return {
        node.attr
        for node in ast.walk(function)
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "self"
        and isinstance(node.ctx, ast.Store)
    }


def _names_in(body: list[ast.stmt], module: str) -> dict[str, object]:
    """The names a module or class body defines: name -> its class body (list), an import target, or None."""
    names: dict[str, object] = {}
    for node in body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = node
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names[node.name] = None
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                for leaf in ast.walk(target):
                    if isinstance(leaf, ast.Name):
                        names[leaf.id] = None
        elif isinstance(node, ast.Import):
            for alias in node.names:
                names[(alias.asname or alias.name).split(".")[0]] = None
        elif isinstance(node, ast.ImportFrom):
            source = node.module or ""
            if node.level:
                source = ".".join(module.split(".")[: -node.level] + ([source] if source else []))
            for alias in node.names:
                if alias.name == "*":
                    names.setdefault("*", []).append(source)  # type: ignore[union-attr]
                else:
                    names[alias.asname or alias.name] = ("import", source, alias.name)
        elif isinstance(node, (ast.If, ast.Try)):
            for block in (node.body, node.orelse, *(h.body for h in getattr(node, "handlers", []))):
                names.update({k: v for k, v in _names_in(block, module).items() if k != "*"})
    return names


@cache
def _module_names(module: str) -> dict[str, object]:
    path = _module_file(module)
    return _names_in(ast.parse(path.read_text(encoding="utf-8")).body, module) if path else {}


def _attribute(scope: object, name: str, module: str) -> tuple[bool, object]:
    """Whether ``name`` is found in ``scope`` (a module name, or a ClassDef), and what it is."""
    if isinstance(scope, ast.ClassDef):
        names = _names_in(scope.body, module)
        for node in scope.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                names.update(dict.fromkeys(_self_attributes(node)))
        if name in names:
            return True, names[name]
        return _inherited(scope, name, module), None
    names = _module_names(module)
    if name in names:
        return True, names[name]
    for source in names.get("*", []) or []:  # type: ignore[union-attr]
        if source.startswith(f"{PACKAGE}.") and _resolves_in(source.removeprefix(f"{PACKAGE}."), [name]):
            return True, None
    return _module_file(f"{module}.{name}") is not None, ("module", f"{module}.{name}")


def _inherited(klass: ast.ClassDef, name: str, module: str) -> bool:
    """Whether a base of ``klass`` has ``name``: a base of the package is looked up, one from outside (an Enum, a
    NamedTuple, an exception) may hold names this reading cannot see, so it is taken to."""
    for base in klass.bases:
        if not isinstance(base, ast.Name):
            return True
        known = _module_names(module).get(base.id)
        if isinstance(known, ast.ClassDef):
            if _attribute(known, name, module)[0]:
                return True
        elif isinstance(known, tuple) and known[0] == "import":
            if not known[1].startswith(f"{PACKAGE}.") or _resolves_in(known[1].removeprefix(f"{PACKAGE}."),
                                                                       [known[2], name]):
                return True
        elif base.id != "object":
            return True  # a builtin base (Exception, tuple, ...)
    return False


def _resolves_in(module: str, rest: list[str]) -> bool:
    scope: object = module
    current = module
    for name in rest:
        if isinstance(scope, tuple) and scope[0] == "import":
            _, source, imported = scope
            if source.startswith(f"{PACKAGE}."):
                return _resolves_in(source.removeprefix(f"{PACKAGE}."), [imported, name])
            return True  # a third-party name: not ours to check
        if isinstance(scope, tuple) and scope[0] == "module":
            scope = current = scope[1]
        if scope is None:
            return True  # an attribute of a function or a value: not resolved further
        found, value = _attribute(scope, name, current)
        if not found:
            return False
        scope = value
    return True


def resolves(path: str) -> bool:
    """Whether dotted ``path`` (with or without ``simparity.``) names a module of the checkout and names in it."""
    parts = path.removeprefix(f"{PACKAGE}.").split(".")
    for split in range(len(parts), 0, -1):
        module = ".".join(parts[:split])
        if _module_file(module) is not None:
            return _resolves_in(module, parts[split:])
    return False


def _python_texts(path: Path) -> list[tuple[int, str]]:
    """(first line, text) of each triple-quoted string (docstrings and the like) and comment of a Python file.

    Read with regular expressions, not parsed: parsing every file is most of the cost. Comments are tokenized only
    in a file where a ``#`` precedes a path on some line."""
    source = path.read_text(encoding="utf-8")
    texts = [(source.count("\n", 0, match.start()) + 1, match.group(0)) for match in TRIPLE_QUOTED.finditer(source)]
    if re.search(rf"#.*{DOTTED.pattern}", source):
        texts += [
            (token.start[0], token.string)
            for token in tokenize.generate_tokens(io.StringIO(source).readline)
            if token.type == tokenize.COMMENT
        ]
    return texts


def _documents() -> list[Path]:
    return sorted({path for pattern in DOCUMENTS for path in ROOT.glob(pattern)})


def _unresolved() -> list[str]:
    problems = []
    sources = [(path, _python_texts(path)) for path in _source_files()]
    sources += [(path, [(1, path.read_text(encoding="utf-8"))]) for path in _documents()]
    for path, texts in sources:
        for first_line, text in texts:
            for match in DOTTED.finditer(text):
                dotted = match.group(0)
                if FILE_SUFFIX.search(dotted) or resolves(dotted):
                    continue
                line = first_line + text.count("\n", 0, match.start())
                problems.append(f"{path.relative_to(ROOT)}:{line}: {dotted}")
    return problems


def test_resolver_tells_a_path_from_a_stale_one():
    assert resolves("simparity.core.model.scenes.kinds.Scene")
    assert resolves("core.model.scenes")
    assert not resolves("core.model." + "scene")  # the module before #40 split it (written in two: the rewrite of moved paths skips it)
    assert resolves("simparity.core.engine.Engine")  # through the alias module's * import
    assert not resolves("simparity.core.integrators")
    assert not resolves("core.model.scenes.kinds.NoSuchName")
    assert resolves("core.model.scenes.dynamics.DynamicsScene.n_steps")  # a method of a class
    assert not resolves("core.model.scenes.dynamics.DynamicsScene.no_such_attribute")


def test_every_dotted_module_path_resolves():
    problems = _unresolved()
    assert not problems, (
        f"{len(problems)} dotted module paths in docstrings, comments or docs name no module or name of the"
        " package (move them to where the name lives now):\n" + "\n".join(problems)
    )
