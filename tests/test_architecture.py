"""The fast core must never import the units layer or the integrations."""

import subprocess
import sys

FORBIDDEN_IN_CORE = ("astropy", "skyfield", "rebound", "reboundx", "heyoka", "jplephem")


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
