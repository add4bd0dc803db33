"""One public path per name: the rule of docs/architecture.md ("One public path per name"), checked.

- A **public module** is a module of the package with no part of its dotted name starting with ``_``.
- A module **exports** the names in its ``__all__``; a public module without ``__all__`` exports the
  public names it defines itself (``def``, ``class`` or an assignment at module level), never what it
  imports.
- Every exported name has one **home**: the public module that defines it.
- A **door** (the table in docs/architecture.md, :data:`DOORS` here) may export names defined
  elsewhere; a door's ``__all__`` (for the two lazy doors, the table it is built from) is its one list
  of them. Each name is re-exported by at most one door, and only the doors re-export.
- No module forwards names by a module-level ``__getattr__`` except the two lazy doors, which answer
  only the names of their own table.

So a user sees a name at its door when it has one and at its home otherwise, and the package's own
modules import it from its home.
"""

import ast
import importlib
import re
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "spinorbit"
ARCHITECTURE = ROOT / "docs" / "architecture.md"
API = ROOT / "docs" / "api"

#: The doors: modules whose ``__all__`` may hold names defined in other modules (docs/architecture.md).
DOORS = (
    "spinorbit",
    "spinorbit.core",
    "spinorbit.core.math.elliptic",
    "spinorbit.coupling.rebound",
    "spinorbit.shape",
    "spinorbit.binary",
    "spinorbit.scene",
    "spinorbit.photometry",
    "spinorbit.fit",
    "spinorbit.ensemble",
)
#: The doors that load their names on first use (PEP 562) and so define a module ``__getattr__``.
LAZY_DOORS = ("spinorbit", "spinorbit.core")
#: Values whose identity says nothing (small ints and short strings are shared by the interpreter).
SCALARS = (bool, int, float, complex, str, bytes, type(None))


def _module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


PUBLIC_MODULES = {
    _module_name(path): path
    for path in sorted(PACKAGE.rglob("*.py"))
    if not any(part.startswith("_") for part in _module_name(path).split("."))
}


def _top_level_statements(tree):
    """The module's own statements, into ``if``/``try`` blocks but not into functions or classes."""
    pending = list(tree.body)
    while pending:
        node = pending.pop(0)
        yield node
        if isinstance(node, (ast.If, ast.Try)):
            pending += node.body + node.orelse + getattr(node, "finalbody", [])
            pending += [statement for handler in getattr(node, "handlers", []) for statement in handler.body]


def _defined_names(path):
    """Names the module binds itself at module level (not by an import)."""
    names = set()
    for node in _top_level_statements(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
    return names - {"__all__"}


@pytest.fixture(scope="module")
def exports():
    """{module: (module object, exported names, names it defines)} over every public module."""
    found = {}
    for name, path in PUBLIC_MODULES.items():
        module = importlib.import_module(name)
        defined = _defined_names(path)
        if hasattr(module, "__all__"):
            exported = list(module.__all__)
        else:
            exported = sorted(n for n in defined if not n.startswith("_"))
        found[name] = (module, exported, defined)
    return found


def test_every_exported_name_exists(exports):
    missing = [f"{module}.{name}" for module, (obj, names, _) in exports.items()
               for name in names if not hasattr(obj, name)]
    assert missing == [], f"names in __all__ that the module does not have: {missing}"


def test_only_the_doors_re_export(exports):
    wrong = [f"{module}: {name}" for module, (_, names, defined) in exports.items() if module not in DOORS
             for name in names if name not in defined]
    assert wrong == [], (
        "modules that are not doors list names they import in __all__ (a name has one home, the module "
        "that defines it: drop it from this __all__, or make the module a door in docs/architecture.md, "
        "'One public path per name'):\n" + "\n".join(wrong))


def _homes(exports, name, value):
    """The non-door public modules that define ``name`` and export it as this very object."""
    return [module for module, (obj, names, defined) in exports.items()
            if module not in DOORS and name in names and name in defined and getattr(obj, name) is value]


def test_every_re_export_has_one_home(exports):
    wrong = []
    for door in DOORS:
        obj, names, defined = exports[door]
        for name in names:
            if name in defined:
                continue
            homes = _homes(exports, name, getattr(obj, name))
            if len(homes) != 1:
                wrong.append(f"{door}.{name}: homes {homes or 'none'}")
    assert wrong == [], ("a door's name must be the very object its one home defines and exports (the home "
                         "lists it in __all__, or has no __all__):\n" + "\n".join(wrong))


def test_no_name_has_two_doors(exports):
    doors_of = defaultdict(list)
    for door in DOORS:
        obj, names, defined = exports[door]
        for name in names:
            if name not in defined:
                doors_of[(name, id(getattr(obj, name)))].append(door)
    twice = {name: doors for (name, _), doors in doors_of.items() if len(doors) > 1}
    assert twice == {}, ("names re-exported by two doors (keep the one users are shown, docs/architecture.md, "
                         f"'One public path per name'): {twice}")


def test_no_object_is_defined_at_two_homes(exports):
    # ``X = other.X`` would make a second home the AST cannot see as an import; identity can.
    homes_of = defaultdict(list)
    for module, (obj, names, defined) in exports.items():
        for name in names:
            value = getattr(obj, name)
            if name in defined and not isinstance(value, SCALARS):
                homes_of[id(value)].append(f"{module}.{name}")
    twice = [paths for paths in homes_of.values() if len(paths) > 1]
    assert twice == [], f"one object exported as defined by two modules: {twice}"


def test_no_module_forwards_names():
    forwarding = []
    for module, path in PUBLIC_MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        if any(isinstance(node, ast.FunctionDef) and node.name == "__getattr__" for node in tree.body):
            if module not in LAZY_DOORS:
                forwarding.append(module)
    assert forwarding == [], (f"module-level __getattr__ outside the lazy doors {LAZY_DOORS}: {forwarding} "
                              "(old import paths are not forwarded: the package has one path per name)")


@pytest.mark.parametrize("door", LAZY_DOORS)
def test_a_lazy_door_answers_only_its_own_names(door):
    module = importlib.import_module(door)
    with pytest.raises(AttributeError, match="no attribute 'integrate_quaternion_old'"):
        module.integrate_quaternion_old  # noqa: B018


def test_the_doors_are_the_ones_architecture_md_lists():
    text = ARCHITECTURE.read_text(encoding="utf-8")
    section = text.split("## One public path per name", 1)[1].split("\n## ", 1)[0]
    listed = re.findall(r"^\| `(spinorbit[\w.]*)` \|", section, re.M)
    assert sorted(listed) == sorted(DOORS), (
        "the doors table of docs/architecture.md ('One public path per name') and DOORS in "
        f"tests/test_public_paths.py differ: docs {sorted(listed)}, test {sorted(DOORS)}")


def test_docs_api_lists_every_public_module():
    documented = set()
    for page in API.glob("*.rst"):
        documented |= set(re.findall(r"^\.\. (?:auto)?module:: ([\w.]+)", page.read_text(encoding="utf-8"), re.M))
    missing = sorted(set(PUBLIC_MODULES) - documented)
    assert missing == [], ("public modules with no '.. automodule::' on a page of docs/api/ (add it to the page "
                           f"of its layer; ':no-members:' if its names are documented elsewhere): {missing}")
