"""Error growth of the exact torque-free flow over long spans; writes a section of docs/torque_free.md.

Run: ``python benchmarks/accuracy_torque_free.py`` (≈ 1 min). For each case and span (in polhode
periods 4K/ν) it reports the largest attitude error (rad) against
  * heyoka in long double at tolerance 1e-19 on q̇ = ½ q ⊗ (0, ω), Ṁ = M × ω (the theory), and
  * the 40-digit evaluation of the moving parts (``tests/_mp_reference.py``: the numerics),
plus heyoka-vs-mpmath, which is the long-double reference's own error.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from _heyoka_reference import propagate, rotation_angle  # noqa: E402
from _mp_reference import exact_states  # noqa: E402
from _report import machine_line, write_section  # noqa: E402
from test_torque_free import (  # noqa: E402
    APOPHIS_MOMENTS,
    APOPHIS_MOMENTUM,
    HLW_MOMENTS,
    HLW_MOMENTUM,
    IDENTITY,
    TILTED,
    near_separatrix_momentum,
    rotation_period,
)

from spinorbit.core.free_motion.flow import torque_free_states  # noqa: E402

CASES = [
    ("HLW (LAM)", HLW_MOMENTS, HLW_MOMENTUM, IDENTITY),
    ("Apophis-like SAM 0.61:0.965:1", APOPHIS_MOMENTS, APOPHIS_MOMENTUM, TILTED),
    ("near separatrix, m_c = 1e-3", APOPHIS_MOMENTS, near_separatrix_momentum(APOPHIS_MOMENTS, 1e-3), TILTED),
    ("near separatrix, m_c = −1e-8", APOPHIS_MOMENTS, near_separatrix_momentum(APOPHIS_MOMENTS, -1e-8), TILTED),
]
HEYOKA_SPANS = (1e2, 1e3, 1e4)
MP_SPANS = (1e2, 1e4, 1e6, 1e7)


#: ``--quick`` (benchmarks/run_all.py's smoke run): the first case at the shortest span, print only.
QUICK_SPANS = (1e2,)


def main():
    global CASES, HEYOKA_SPANS, MP_SPANS
    quick = "--quick" in sys.argv[1:]
    if quick:
        CASES, HEYOKA_SPANS, MP_SPANS = CASES[:1], QUICK_SPANS, QUICK_SPANS
    lines = [
        "## Measured error growth (`benchmarks/accuracy_torque_free.py`)",
        "",
        machine_line(),
        "",
        "Largest attitude error (rad) at the listed spans (polhode periods 4K/ν; a fraction of a period "
        "is added so the phase is not special).",
        "",
        "| case | reference | " + " | ".join(f"{s:.0e}" for s in sorted(set(HEYOKA_SPANS + MP_SPANS))) + " |",
        "|---|---|" + "---:|" * len(set(HEYOKA_SPANS + MP_SPANS)),
    ]
    spans_all = sorted(set(HEYOKA_SPANS + MP_SPANS))
    for name, moments, momentum, q0 in CASES:
        period = rotation_period(q0, momentum, moments)
        t_h = period * (np.array(HEYOKA_SPANS) + 0.3)
        t_m = period * (np.array(MP_SPANS) + 0.3)
        q_h, _ = propagate(q0, momentum, moments, t_h)
        q_pkg_h, _ = torque_free_states(q0, momentum, *moments, t_h)
        q_mp_h, _ = exact_states(q0, momentum, moments, t_h)
        q_mp, _ = exact_states(q0, momentum, moments, t_m)
        q_pkg_m, _ = torque_free_states(q0, momentum, *moments, t_m)
        columns = {
            "spinorbit vs heyoka long double": dict(zip(HEYOKA_SPANS, rotation_angle(q_h, q_pkg_h))),
            "spinorbit vs mpmath (40 digits)": dict(zip(MP_SPANS, rotation_angle(q_mp, q_pkg_m))),
            "heyoka long double vs mpmath": dict(zip(HEYOKA_SPANS, rotation_angle(q_mp_h, q_h))),
        }
        for reference, values in columns.items():
            cells = [f"{values[s]:.1e}" if s in values else "" for s in spans_all]
            lines.append(f"| {name} | {reference} | " + " | ".join(cells) + " |")
    markdown = "\n".join(lines)
    print(markdown)
    if not quick and "--no-write" not in sys.argv[1:]:
        write_section("accuracy_torque_free", markdown, page="torque_free.md")


if __name__ == "__main__":
    main()
