"""Error types of the binary propagator (subclasses of the core's SpinorbitError and ValueError)."""

from spinorbit.core.errors import SpinorbitError


class ContactError(SpinorbitError, ValueError):
    """The two bodies touch, overlap, or come closer than the sum of their circumscribing radii.

    Below that distance the mutual-potential series diverges (Hou, Scheeres & Xin 2017, §2), so no
    order of the expansion gives the force: the run is refused, or stopped at the step that got there.
    """


class UnsupportedOrderError(SpinorbitError, ValueError):
    """An expansion order the inertia-integral tables were not built for (0 ≤ order ≤ MAX_ORDER)."""
