"""A socket guard for tests that must prove they never touch the network.

Import ``no_network`` into a test module (``from _offline import no_network  # noqa: F401``): it is
an autouse fixture there, and any attempt to open a connection fails the test with a clear message
instead of hanging or silently downloading (astropy IERS tables, skyfield files, REBOUND's Horizons).
"""

import socket

import pytest


class NetworkAccessError(RuntimeError):
    """Raised when a test tries to open a network connection."""


def _refuse(*args, **kwargs):
    raise NetworkAccessError(f"test tried to use the network: {args!r}")


@pytest.fixture(autouse=True)
def no_network(monkeypatch):
    """Make every outgoing connection raise :class:`NetworkAccessError` for the test's duration."""
    monkeypatch.setattr(socket.socket, "connect", _refuse)
    monkeypatch.setattr(socket.socket, "connect_ex", _refuse)
    monkeypatch.setattr(socket, "create_connection", _refuse)
    monkeypatch.setattr(socket, "getaddrinfo", _refuse)
    yield
