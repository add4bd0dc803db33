"""``python -m spinorbit``: the same as the ``spinorbit`` command."""

from spinorbit.cli import main

raise SystemExit(main())
