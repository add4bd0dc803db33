"""``python -m spinorbit``: the same as the ``spinorbit`` command."""

from .cli import main

raise SystemExit(main())
