"""``python -m spinorbit``: the same as the ``spinorbit`` command."""

from spinorbit.cli import console_main

raise SystemExit(console_main())
