"""The layout rules of docs/architecture.md, checked on the source.

Every rule reads the package's own import statements (module level and inside functions alike), so a
new module is checked the day it is added:

- the fast core never imports the units layer or the integrations (checked on a fresh interpreter);
- each folder of the core imports only the folders below it, and the layer above the core keeps its
  order (units bridge, long-run infrastructure, coupling, scene planning, data, command line);
- no import circles between modules;
- no module imports another module's private name (``from x import _y``);
- only the REBOUND door (``spinorbit.coupling.rebound``) imports rebound or ctypes (ctypes also
  ``spinorbit.ensemble.workers``, for prctl).

One public path per name (no old import paths) is checked in ``tests/test_public_paths.py``.
"""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "spinorbit"
FORBIDDEN_IN_CORE = ("astropy", "skyfield", "rebound", "reboundx", "heyoka", "jplephem")

#: The core's folders, lowest first: each may import only itself and those before it.
CORE_LAYERS = ("math", "model", "dynamics", "elements", "free_motion", "integrators", "averaging", "binary",
               "photometry")
#: Core modules every core folder may use (numba settings, error types).
CORE_BASE = ("spinorbit.core.jit", "spinorbit.core.errors")

#: The layer above the core, lowest first (the core below them all).
UPPER_LAYERS = (
    ("bridge", ("spinorbit.quantities", "spinorbit.body", "spinorbit.state", "spinorbit.state_table", "spinorbit.time",
                "spinorbit.frames", "spinorbit.ephemeris", "spinorbit.lunar_librations", "spinorbit.special",
                "spinorbit.orbital_elements", "spinorbit.pole", "spinorbit.spin_forms", "spinorbit.yarkovsky",
                "spinorbit.sbpy_tables")),
    ("runs", ("spinorbit.runs",)),
    ("shape", ("spinorbit.shape",)),
    ("coupling", ("spinorbit.coupling",)),
    ("binary", ("spinorbit.binary",)),
    ("scene", ("spinorbit.scene",)),
    ("photometry", ("spinorbit.photometry",)),
    ("fit", ("spinorbit.fit",)),
    ("data", ("spinorbit.data",)),
    ("ensemble", ("spinorbit.ensemble",)),
    ("command line", ("spinorbit.cli", "spinorbit.commands", "spinorbit.__main__")),
)
#: Modules every layer may import: the front door's lazy table.
ANYWHERE = ("spinorbit",)



def _module_name(path):
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path):
    """(imported module, imported names) of every import statement in ``path``, relative ones resolved."""
    me = _module_name(path)
    package = me if path.name == "__init__.py" else me.rsplit(".", 1)[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(alias.name, ()) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                module = ".".join(base + ([module] if module else []))
            found.append((module, tuple(alias.name for alias in node.names)))
    return found


MODULES = {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _internal_targets(module, names):
    """The spinorbit modules an import statement loads: the module, or its submodules named in ``names``."""
    if not (module == "spinorbit" or module.startswith("spinorbit.")):
        return []
    submodules = [f"{module}.{name}" for name in names if f"{module}.{name}" in MODULES]
    return submodules or [module]


def _edges():
    return {
        name: sorted({target for module, names in _imports(path) for target in _internal_targets(module, names)}
                     - {name})
        for name, path in MODULES.items()
    }


def _upper_layer(module):
    for rank, (_, prefixes) in enumerate(UPPER_LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return rank
    return None


def _core_layer(module):
    parts = module.split(".")
    if len(parts) >= 3 and parts[2] in CORE_LAYERS:
        return CORE_LAYERS.index(parts[2])
    return None


def test_core_imports_no_astropy_skyfield_or_rebound():
    # A fresh interpreter, so modules imported by other tests do not mask an import made by the core.
    code = (
        "import sys, pkgutil, importlib, spinorbit.core as core\n"
        "for info in pkgutil.walk_packages(core.__path__, 'spinorbit.core.'):\n"
        "    importlib.import_module(info.name)\n"
        f"bad = sorted(m for m in sys.modules if m.split('.')[0] in {FORBIDDEN_IN_CORE!r})\n"
        "print(','.join(bad))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "", f"spinorbit.core imported {result.stdout.strip()}"


def test_every_core_module_is_in_a_layer():
    loose = [m for m in MODULES if m.startswith("spinorbit.core.") and _core_layer(m) is None
             and m not in CORE_BASE]
    assert loose == [], f"core modules outside the layers {CORE_LAYERS}: {loose} (docs/architecture.md)"


def test_core_folders_import_only_the_folders_below():
    wrong = []
    for module, targets in _edges().items():
        layer = _core_layer(module)
        if layer is None and module not in CORE_BASE:
            continue
        for target in targets:
            if target in ANYWHERE or target in CORE_BASE or target == "spinorbit.core":
                if target == "spinorbit.core":
                    wrong.append(f"{module} -> {target} (import the owning module, not the lazy front door)")
                continue
            target_layer = _core_layer(target)
            if target_layer is None or (layer is not None and target_layer > layer) or layer is None:
                wrong.append(f"{module} -> {target}")
    assert wrong == [], "core layer order violated (docs/architecture.md):\n" + "\n".join(wrong)


def test_upper_layers_keep_their_order():
    wrong = []
    for module, targets in _edges().items():
        if module.startswith("spinorbit.core") or module in ANYWHERE:
            continue
        layer = _upper_layer(module)
        assert layer is not None, f"{module} is in no layer of UPPER_LAYERS: add it to docs/architecture.md and here"
        for target in targets:
            if target.startswith("spinorbit.core") or target in ANYWHERE:
                continue
            if _upper_layer(target) > layer:
                wrong.append(f"{module} ({UPPER_LAYERS[layer][0]}) -> {target} ({UPPER_LAYERS[_upper_layer(target)][0]})")
    assert wrong == [], "a lower layer imports a higher one (docs/architecture.md):\n" + "\n".join(wrong)


def test_no_import_circles():
    edges = _edges()
    index, low, stack, on_stack, circles = {}, {}, [], set(), []

    def visit(node):  # Tarjan's strongly connected components
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in edges.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for node in edges:
        if node not in index:
            visit(node)
    assert circles == [], f"import circles: {circles}"


def test_no_private_names_cross_modules():
    crossings = []
    for module, path in MODULES.items():
        for target, names in _imports(path):
            if not target.startswith("spinorbit"):
                continue
            for name in names:
                if name.startswith("_") and not name.startswith("__") and f"{target}.{name}" not in MODULES:
                    crossings.append(f"{module}: from {target} import {name}")
    assert crossings == [], "private names imported across modules (make them public where they belong):\n" + \
        "\n".join(crossings)


#: The one package that may import REBOUND or handle raw memory (docs/coupling.md).
REBOUND_DOOR = "spinorbit.coupling.rebound"
BEHIND_THE_REBOUND_DOOR = ("rebound", "reboundx", "ctypes")
#: Modules outside the door that may import ctypes (and nothing else of the door's): prctl for worker lifetime.
CTYPES_ALSO = ("spinorbit.ensemble.workers",)


def test_only_the_rebound_door_imports_rebound_or_ctypes():
    outside = []
    for module, path in MODULES.items():
        if module == REBOUND_DOOR or module.startswith(REBOUND_DOOR + "."):
            continue
        for target, _ in _imports(path):
            if target.split(".")[0] in BEHIND_THE_REBOUND_DOOR and not (module in CTYPES_ALSO and target == "ctypes"):
                outside.append(f"{module}: import {target}")
    assert outside == [], f"only {REBOUND_DOOR} may import {BEHIND_THE_REBOUND_DOOR} (use its exported names):\n" + \
        "\n".join(outside)


def test_no_module_is_too_long():
    # docs/architecture.md: ~600 lines at most, unless the module's docstring says why one concept needs more.
    long = []
    for module, path in MODULES.items():
        lines = path.read_text().count("\n")
        docstring = ast.get_docstring(ast.parse(path.read_text())) or ""
        if lines > 650 and "one concept" not in docstring:
            long.append(f"{module}: {lines} lines")
    assert long == [], "modules over the size rule without a reason in their docstring:\n" + "\n".join(long)


def test_core_entry_points_resolve():
    import spinorbit.core as core

    for name in core.__all__:
        assert callable(getattr(core, name)), name
