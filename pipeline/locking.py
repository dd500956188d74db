"""pipeline.locking - one rockfrag run per output folder, and cleaning what killed runs left.

Input : an output folder.
Output: an advisory lock (``fcntl.flock`` on ``<folder>/.rockfrag.lock``, holding the owner's pid)
        kept while a command writes there. A second run on the same folder stops with one line
        naming the folder and the owner's pid (or waits: ``wait=True``, the CLI's ``--wait``). The
        kernel drops the lock when its owner dies, even by ``kill -9``, so a lock is never stale.

Every rockfrag writer in a folder holds its lock, so the temporary ``.*.part`` files found there
by the process that has just taken the lock belong to runs that died: they are removed then, and
never while another run holds the folder.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
from pathlib import Path

from pipeline.errors import PipelineError

LOCK_NAME = ".rockfrag.lock"

_held: dict[Path, list] = {}  # resolved folder -> [file descriptor, depth]; re-entrant per process


def prepare_output_folder(folder) -> Path:
    """Create ``folder`` if needed; one-line ``PipelineError`` if it is a file or not writable."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise PipelineError(f"output folder {folder} is a file; expected a folder (--output DIR)")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise PipelineError(f"cannot create the output folder {folder}: {error.strerror}") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PipelineError(f"output folder {folder} is not writable")
    return folder


def _owner(path) -> str:
    with contextlib.suppress(OSError, ValueError):
        return f" (pid {int(Path(path).read_text().split()[0])})"
    return ""


def stale_part_files(folder) -> list[Path]:
    """Temporary files of interrupted writes in ``folder`` and its ``.checkpoints``."""
    folder = Path(folder)
    return [path for where in (folder, folder / ".checkpoints") if where.is_dir()
            for path in where.glob(".*.part") if path.is_file()]


BUSY = (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)


@contextlib.contextmanager
def output_lock(folder, wait=False, notify=None):
    """Hold the advisory lock of ``folder`` (created if needed) for the duration of the block.

    Re-entrant within one process. On first acquisition the stale ``.part`` files of dead runs
    are removed. A folder held by another run is a one-line ``PipelineError``, or with ``wait`` the
    call blocks until that run ends, after telling ``notify`` (a callable taking one line) once.
    """
    folder = prepare_output_folder(folder)
    key = folder.resolve()
    if key in _held:
        _held[key][1] += 1
        try:
            yield folder
        finally:
            _held[key][1] -= 1
        return
    lock_path = folder / LOCK_NAME
    try:
        descriptor = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
    except OSError as error:
        raise PipelineError(f"output folder {folder} is not writable ({error.strerror})") from None
    try:
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            if error.errno not in BUSY or not wait:
                raise
            if notify is not None:
                notify(f"output folder {folder} is in use by another rockfrag run{_owner(lock_path)}; "
                       "waiting for it to finish (Ctrl-C stops waiting)")
            fcntl.flock(descriptor, fcntl.LOCK_EX)
    except OSError as error:
        os.close(descriptor)
        if error.errno in BUSY:
            raise PipelineError(f"output folder {folder} is in use by another rockfrag run{_owner(lock_path)}; "
                                "wait for it to finish, choose another --output, or pass --wait") from None
        raise PipelineError(f"cannot lock the output folder {folder} ({error.strerror})") from None
    except BaseException:  # Ctrl-C while waiting
        os.close(descriptor)
        raise
    _held[key] = [descriptor, 1]
    try:
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, f"{os.getpid()}\n".encode(), 0)
        for stale in stale_part_files(folder):
            stale.unlink(missing_ok=True)
        yield folder
    finally:
        del _held[key]
        os.close(descriptor)
