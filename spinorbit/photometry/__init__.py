"""Photometry: how bright a rotating body looks (issue 38; ``docs/photometry.md``).

The plain-float kernels are in :mod:`spinorbit.core.photometry`; this package is their units layer.

- :mod:`.brightness` — the kernel's door, :func:`brightness`: the disk-integrated brightness of a
  shape (facets or an :class:`Ellipsoid`) for body-frame Sun and observer directions, in km², with
  the Lommel–Seeliger, Lambert and Kaasalainen laws, self-shadowing on non-convex shapes;
- :mod:`.phase` — the phase functions (:class:`HG1G2` as sbpy defines it, :class:`LinearExponential`)
  and the reduced magnitudes they give;
- :mod:`.geometry` — the light-time corrected directions to the Sun and the observer (the Earth from
  DE421, another DE421 body, or any positions);
- :mod:`.lightcurve` — :func:`lightcurve` of a RotationState or a Scene's result: a TimeSeries of
  magnitudes, phase and aspect angles;
- :mod:`.observations` — photometric observations (epoch, magnitude, uncertainty, filter, observer)
  from a TimeSeries, checked;
- :mod:`.alcdef`, :mod:`.damit` — the ALCDEF exchange format and DAMIT's lightcurve files, both ways;
- :mod:`.errors` — the layer's error types.
"""

from spinorbit.photometry.alcdef import ALCDEFError, read_alcdef, write_alcdef
from spinorbit.photometry.brightness import Ellipsoid, brightness, shadowing_decision
from spinorbit.photometry.damit import DAMITFormatError, read_damit, write_damit
from spinorbit.photometry.errors import InvalidDirectionsError, PhotometryError
from spinorbit.photometry.geometry import ViewingGeometry, observation_times, viewing_geometry
from spinorbit.photometry.lightcurve import ObserverInsideBodyError, lightcurve
from spinorbit.photometry.observations import (
    KNOWN_FILTERS,
    MissingUncertaintyError,
    ObservationSpanError,
    UnknownFilterError,
    photometric_observations,
)
from spinorbit.photometry.phase import HG1G2, LinearExponential, NoLightError, reduced_magnitudes

__all__ = ["ALCDEFError", "DAMITFormatError", "KNOWN_FILTERS", "MissingUncertaintyError", "ObservationSpanError",
           "UnknownFilterError", "photometric_observations", "read_alcdef", "read_damit", "write_alcdef", "write_damit",
           "Ellipsoid", "HG1G2", "InvalidDirectionsError", "LinearExponential", "NoLightError",
           "ObserverInsideBodyError", "PhotometryError", "ViewingGeometry", "brightness", "lightcurve",
           "observation_times", "reduced_magnitudes", "shadowing_decision", "viewing_geometry"]
