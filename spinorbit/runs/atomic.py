"""Atomic output files: a reader sees the old file or the complete new one, never a part.

Every file spinorbit writes (ECSV tables, PNG plots, checkpoints, coupled-run saves, benchmark pages)
goes through :func:`atomic_path`: the writer fills a temporary file in the *target's own directory*
(``os.replace`` is atomic only within one file system), the data are flushed to disk with ``fsync``,
and only then the temporary file is renamed over the target. If the writer raises — or the process
is killed — the target is untouched (a pre-existing file keeps its old contents) and the temporary
file is removed (after a kill, a hidden ``.<name>.*.tmp`` file may remain; it is never the target).
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile

__all__ = ["atomic_path", "refuse_unsafe_target", "write_bytes_atomically"]


def _default_mode(path: str) -> int:
    """Permissions of the new file: the old file's, else what ``open()`` would give (0o666 − umask).

    ``mkstemp`` creates files readable by the owner only; without this an atomic write would
    silently make outputs private.
    """
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        mask = os.umask(0)
        os.umask(mask)
        return 0o666 & ~mask


def _fsync_path(path: str, directory: bool = False) -> None:
    flags = os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0)
    try:
        handle = os.open(path, flags)
    except OSError:
        if directory:  # some platforms cannot open directories; the rename is still atomic there
            return
        raise
    try:
        os.fsync(handle)
    except OSError:
        if not directory:
            raise
    finally:
        os.close(handle)


def refuse_unsafe_target(path: str) -> None:
    """Raise ``OSError`` if replacing ``path`` would destroy something other than a regular file.

    A rename over a symbolic link replaces the link (not the file it points to), over a device
    such as ``/dev/null`` it removes the device node (as root), and over a directory it fails late.
    These are refused before anything is written; the ``strerror`` says what to do.
    """
    if os.path.islink(path):
        raise OSError(errno.ELOOP, "it is a symbolic link, which an atomic write would replace; give the target's "
                      "own path or another name", path)
    if os.path.isdir(path):
        raise IsADirectoryError(errno.EISDIR, "it is a directory; give a file path", path)
    if os.path.exists(path) and not stat.S_ISREG(os.stat(path).st_mode):
        raise OSError(errno.EINVAL, "it exists and is not a regular file (a device, pipe or socket); give the path "
                      "of a regular file", path)


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path``; when the block succeeds, move it into place.

    Parameters
    ----------
    path : str or os.PathLike
        The file to create or replace.

    Yields
    ------
    str
        A path in the same directory with the same suffix as ``path`` (writers such as matplotlib
        and astropy pick the format from the suffix). Write the whole file there.

    Raises
    ------
    OSError
        The target is a symbolic link, a directory or not a regular file (:func:`refuse_unsafe_target`),
        the directory cannot hold the temporary file, or the rename fails (the target is unchanged).

    Notes
    -----
    Order: write → ``fsync`` the file → ``os.replace`` → ``fsync`` the directory, so that after a
    crash the name points to complete data (POSIX rename semantics).
    """
    path = os.fspath(path)
    refuse_unsafe_target(path)
    directory = os.path.dirname(os.path.abspath(path))
    name = os.path.basename(path)
    suffix = os.path.splitext(name)[1]
    handle, temporary = tempfile.mkstemp(dir=directory, prefix=f".{name}.", suffix=f".tmp{suffix}")
    os.close(handle)
    try:
        os.chmod(temporary, _default_mode(path))
        yield temporary
        _fsync_path(temporary)
        os.replace(temporary, path)
        _fsync_path(directory, directory=True)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)


def write_bytes_atomically(path, data: bytes) -> None:
    """Replace ``path`` by ``data`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as temporary, open(temporary, "wb") as stream:
        stream.write(data)
