"""The command line run in-process, as the stress tests drive it: (exit status, stderr text stripped)."""

import contextlib
import io

from spinorbit import cli


def run_cli(argv):
    """Run ``spinorbit argv``; return (exit status, stderr). argparse's own exits count as statuses."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            status = cli.main(argv)
        except SystemExit as exit_info:
            status = exit_info.code
    return status, err.getvalue().strip()
