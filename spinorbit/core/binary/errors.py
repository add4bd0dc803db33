"""Error types of the binary propagator (subclasses of the core's SpinorbitError and ValueError)."""

from spinorbit.core.errors import SpinorbitError


class ContactError(SpinorbitError, ValueError):
    """The two bodies touch, overlap, or come closer than the sum of their circumscribing radii.

    Below that distance the mutual-potential series diverges (Hou, Scheeres & Xin 2017, §2), so no
    order of the expansion gives the force: the run is refused, or stopped at the step that got there.
    """


class UnsupportedOrderError(SpinorbitError, ValueError):
    """An expansion order the inertia-integral tables were not built for (0 ≤ order ≤ MAX_ORDER)."""


class UnboundPairError(SpinorbitError, ValueError):
    """The pair is not a binary at some output time: no mutual period or libration exists to report.

    Raised when the mutual orbit's energy (with the figure terms) is ≥ 0, or B is beyond the Hill
    radius with the Sun's tide on (:mod:`spinorbit.core.binary.boundedness`).
    """


class UnresolvedPeriodError(SpinorbitError, ValueError):
    """The run is too short to resolve the period asked for: too few cycles, or two lines too close.

    ``required_span`` is the span (s) the message asks for, computed from the lines this run found
    (a lower bound when they are not the true ones), or None.
    """

    def __init__(self, message, required_span=None):
        super().__init__(message)
        self.required_span = required_span
