"""The documentation builds offline, warning-free, and its API reference shows the public names.

A real ``sphinx-build -W -b html`` of ``docs/`` into a temporary directory (about 5 s), in a
subprocess whose sockets refuse to connect: a build that tried to fetch anything (intersphinx
inventories, remote images) fails here, as it would on an offline machine.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

# Runs Sphinx with the network switched off, so "offline" is checked and not just hoped for.
OFFLINE_SPHINX = """
import socket, sys
def refuse(*args, **kwargs):
    raise OSError(f"the docs build tried to use the network: {args!r}")
socket.socket.connect = socket.socket.connect_ex = refuse
socket.create_connection = socket.getaddrinfo = refuse
from sphinx.cmd.build import main
sys.exit(main(sys.argv[1:]))
"""

# Every page of the API reference and names it must show (a failed autodoc import drops them).
API_NAMES = {
    "spinorbit": ["RigidBody", "RotationState", "from_euler313", "propagate_torque_free", "CanonicalElements",
                  "InvalidBodyError", "InvalidStateError", "SingularElementsError"],
    "special": ["ellipj", "am", "ellipk", "ellipf", "ellippi", "pn"],
    "core": ["andoyer_to_canonical", "canonical_to_andoyer"],
    "fit": ["fit_rotation", "FitResult", "AttitudeObservation", "PeriodObservation", "free_flow_stm",
            "integrate_variational", "integrate_taylor_variational", "mean_elements_stm",
            "osculating_elements_stm"],
    "integrators": ["integrate_taylor", "integrate_taylor_fixed_step", "taylor_series", "TaylorFallbackWarning",
                    "integrate_elements_fixed_step"],
    "time": ["tdb_days", "tdb_day_and_fraction", "time_from_tdb_days", "J2000_JD_TDB"],
    "frames": ["icrf_to_ecliptic", "ecliptic_to_icrf", "body_to_icrf", "OBLIQUITY_J2000"],
    "ephemeris": ["barycentric_state", "moon_orientation", "moon_libration_angles", "de421_constants"],
    "rebound_adapter": ["simulation_from_de421", "install_extra_forces", "perturber_positions"],
    "cli": ["main", "CommandError", "add_arguments"],
    "scene": ["Scene", "plan", "run", "Orbit", "FixedPerturber", "SceneResult", "SceneError", "Plan",
              "attitude_sensitivity", "dropped_torque_bound"],
    "averaged": ["propagate_averaged", "osculating_to_mean", "mean_to_osculating", "polhode_mean_inertia",
                 "torus_mean_rhs", "validity_code"],
    "binary": ["propagate", "BinaryRun", "Figure", "BinarySystem", "BinaryState", "momentum_impulse", "ContactError",
               "UnsupportedOrderError", "mutual_field", "ellipsoid_integrals", "propagate_binary"],
}
NARRATIVE_PAGES = ["index", "cli", "conventions", "theory", "design", "elliptic", "ephemeris", "performance",
                   "fitting", "scenes", "tutorials", "validation", "auto_examples/index", "binary"]


#: What sphinx-gallery generates into the source tree (it cannot write elsewhere; git-ignored, rebuilt each build).
GALLERY_GENERATED = ("auto_examples", "sg_execution_times.rst")


def _source_files():
    return sorted(p.relative_to(DOCS) for p in DOCS.rglob("*")
                  if "_build" not in p.parts and p.relative_to(DOCS).parts[0] not in GALLERY_GENERATED)


@pytest.fixture(scope="module")
def built_docs(tmp_path_factory):
    out = tmp_path_factory.mktemp("html")
    before = _source_files()
    command = [sys.executable, "-c", OFFLINE_SPHINX, "-W", "--keep-going", "-E", "-q", "-b", "html",
               str(DOCS), str(out)]
    result = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert result.returncode == 0, f"sphinx-build -W failed:\n{result.stderr}"
    assert _source_files() == before, "the build wrote files into docs/ (generated stubs belong in the build dir)"
    return out


def test_the_theme_is_a_wide_one(built_docs):
    assert "furo" in (built_docs / "index.html").read_text(encoding="utf-8")


@pytest.mark.parametrize("example", sorted(p.stem for p in (ROOT / "examples").glob("*.py")))
def test_every_example_is_a_gallery_page_with_its_committed_output(built_docs, example):
    page = built_docs / "auto_examples" / f"{example}.html"
    assert page.is_file(), (f"examples/{example}.py has no gallery page: its module docstring must open with a reST "
                            "title (a line, then a rule of = as long as it), as sphinx-gallery needs")
    html = page.read_text(encoding="utf-8")
    assert "<h1>" in html  # its docstring title
    output = DOCS / "gallery" / f"{example}.txt"
    if output.is_file():  # docs/gallery_outputs.py has run it: the page shows what it printed and plotted
        assert "Output of the run" in html
        last = [line for line in output.read_text(encoding="utf-8").splitlines() if line.strip()][-1]
        assert html.count(last.split()[-1]) >= 1
        if output.with_suffix(".png").is_file():
            assert (built_docs / "_images" / f"{example}.png").is_file() and f"{example}.png" in html


def _tutorial_outputs():
    import importlib.util

    spec = importlib.util.spec_from_file_location("tutorial_outputs", DOCS / "tutorial_outputs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("index", _tutorial_outputs().CHEAP)
def test_tutorial_outputs_are_a_fresh_run(index):
    """The printed output on docs/tutorials.md is what the snippet prints now (docs/tutorial_outputs.py)."""
    module = _tutorial_outputs()
    code, committed, _ = module.snippets(module.PAGE.read_text(encoding="utf-8"))[index]
    assert module.run_snippet(code) == committed, "stale: run python docs/tutorial_outputs.py"


def test_docs_build_warning_free_and_offline(built_docs):
    assert (built_docs / "index.html").is_file()


@pytest.mark.parametrize("page", NARRATIVE_PAGES)
def test_markdown_pages_are_in_the_site(built_docs, page):
    assert (built_docs / f"{page}.html").is_file()


@pytest.mark.parametrize("page", sorted(API_NAMES))
def test_api_pages_document_the_public_names(built_docs, page):
    html = (built_docs / "api" / f"{page}.html").read_text(encoding="utf-8")
    # autodoc gives every documented object an anchor with its dotted name: id="spinorbit.special.am"
    missing = [name for name in API_NAMES[page] if not re.search(rf'id="[\w.]*\.{name}"', html)]
    assert not missing, f"api/{page}.html does not document {missing}"
    assert "Parameters" in html, f"api/{page}.html shows no numpydoc Parameters section"


def test_no_unresolved_bars_in_rendered_docstrings(built_docs):
    # conf.py escapes plain |x| in docstrings; an unescaped one would show up as a docutils problem node
    html = (built_docs / "api" / "special.html").read_text(encoding="utf-8")
    assert "problematic" not in html
    assert "|u|" in html
