"""Subcommands of the ``spinorbit`` command line, one module each (see :mod:`spinorbit.cli`).

Modules whose names start with ``_`` are shared helpers, not commands.
"""
