"""rockfrag.locking - one rockfrag run per output folder, and cleaning what killed runs left.

Input : an output folder.
Output: an advisory lock (``fcntl.flock`` on ``<folder>/.rockfrag.lock``, holding the owner's pid)
        kept while a command writes there. A second run on the same folder stops with one line
        naming the folder and the owner's pid (or waits: ``wait=True``, the CLI's ``--wait``). The
        kernel drops the lock when its owner dies, even by ``kill -9``, so a lock is never stale; the pool
        workers the owner forked share its lock until they exit, so a lock whose owner is dead is waited
        for (``ORPHAN_GRACE_SECONDS``) rather than reported in use.

Every rockfrag writer in a folder holds its lock, so the temporary ``.*.part`` files found there
by the process that has just taken the lock belong to runs that died: they are removed then, and
never while another run holds the folder.

A command that fails (any exception out of the locked block) leaves the folder as it found it: the
lock file goes if this run created it, so do the empty folders it made inside (``.checkpoints`` of a run
that failed before its first cell), and so does the folder (and any parent it created) if nothing else is
left in it. A run that waited on a lock file removed this way takes the lock again
on the file now at its path, so two runs never hold the same folder.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import time
from pathlib import Path

from rockfrag.checkpoints import FOLDER as CHECKPOINT_FOLDER
from rockfrag.errors import PipelineError

LOCK_NAME = ".rockfrag.lock"

_held: dict[Path, list] = {}  # resolved folder -> [file descriptor, depth]; re-entrant per process


def missing_folders(folder) -> list[Path]:
    """``folder`` and those of its parents that do not exist yet, deepest first (what a mkdir creates)."""
    missing = []
    folder = Path(folder)
    while not folder.exists() and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    return missing


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


def _owner_pid(path) -> int | None:
    """The pid written in the lock file ``path``, or None."""
    with contextlib.suppress(OSError, ValueError, IndexError):
        return int(Path(path).read_text().split()[0])
    return None


def _owner(path) -> str:
    pid = _owner_pid(path)
    return "" if pid is None else f" (pid {pid})"


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, dead but not yet reaped by its parent, does not)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False
    except (OSError, IndexError):  # no /proc (macOS): ask the kernel
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True


# How long [s] a run waits for a lock whose owner is dead. The owner's pool workers share its locked descriptor
# (fork copies it), so a worker forked just before the owner was killed holds the lock until it sees its parent
# gone and exits, milliseconds later: a run started at once would otherwise find the folder "in use".
ORPHAN_GRACE_SECONDS = 5.0


def _take_from_dead_owner(descriptor: int, lock_path: Path) -> bool:
    """Take the lock held on behalf of a dead owner (see ORPHAN_GRACE_SECONDS).

    True once taken; False at once when the owner is alive or unknown, or after the grace period.
    """
    pid = _owner_pid(lock_path)
    if pid is None or _alive(pid):
        return False
    deadline = time.monotonic() + ORPHAN_GRACE_SECONDS
    while time.monotonic() < deadline:
        time.sleep(0.02)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            if error.errno not in BUSY:
                raise
            continue
        return True
    return False


def stale_part_files(folder) -> list[Path]:
    """Temporary files of interrupted writes in ``folder`` and its ``.checkpoints``."""
    folder = Path(folder)
    return [path for where in (folder, folder / CHECKPOINT_FOLDER) if where.is_dir()
            for path in where.glob(".*.part") if path.is_file()]


BUSY = (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)


def _same_file(descriptor: int, path: Path) -> bool:
    """Whether ``path`` still names the open file ``descriptor`` (a failed run may have removed it)."""
    try:
        named = os.stat(path)
    except FileNotFoundError:
        return False
    held = os.fstat(descriptor)
    return (named.st_dev, named.st_ino) == (held.st_dev, held.st_ino)


def _acquire(folder: Path, wait: bool, notify) -> tuple[int, bool]:
    """An exclusive flock on ``folder``'s lock file: (descriptor, whether this call created the file)."""
    lock_path = folder / LOCK_NAME
    told = False
    while True:
        prepare_output_folder(folder)  # again after a failed run removed the folder it had created
        created = not lock_path.exists()
        try:
            descriptor = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except FileNotFoundError:
            continue  # the folder went between the two calls
        except OSError as error:
            raise PipelineError(f"output folder {folder} is not writable ({error.strerror})") from None
        try:
            try:
                fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as error:
                if error.errno not in BUSY:
                    raise
                if not _take_from_dead_owner(descriptor, lock_path):
                    if not wait:
                        raise
                    if notify is not None and not told:
                        notify(f"output folder {folder} is in use by another rockfrag run{_owner(lock_path)}; "
                               "waiting for it to finish (Ctrl-C stops waiting)")
                        told = True
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
        if _same_file(descriptor, lock_path):
            return descriptor, created
        os.close(descriptor)  # the run we waited for failed and removed this lock file: lock the new one


def _subfolders(folder: Path) -> set[str]:
    """Every folder under ``folder``, as paths relative to it."""
    return {os.path.relpath(os.path.join(parent, name), folder)
            for parent, names, _ in os.walk(folder) for name in names}


def _leave_as_found(lock_path: Path, created_lock: bool, created_folders: list[Path],
                    found: set[str] | None = None) -> None:
    """After a failure: remove what this run made that holds nothing.

    The lock file this run created, the empty folders it made inside the output folder (those not among ``found``,
    e.g. ``.checkpoints`` of a run that failed before its first cell), then the folders it created if empty.
    """
    if created_lock:
        with contextlib.suppress(OSError):
            lock_path.unlink()
    if found is not None:
        folder = lock_path.parent
        for name in sorted(_subfolders(folder) - found, key=lambda name: name.count(os.sep), reverse=True):
            with contextlib.suppress(OSError):  # rmdir refuses a folder that holds anything
                (folder / name).rmdir()
    for folder in created_folders:  # deepest first; rmdir refuses a folder that holds anything
        try:
            folder.rmdir()
        except OSError:
            break


@contextlib.contextmanager
def output_lock(folder, wait=False, notify=None):
    """Hold the advisory lock of ``folder`` (created if needed) for the duration of the block.

    Re-entrant within one process. On first acquisition the stale ``.part`` files of dead runs
    are removed. A folder held by another run is a one-line ``PipelineError``, or with ``wait`` the
    call blocks until that run ends, after telling ``notify`` (a callable taking one line) once.
    If the block raises, the lock file and the folders this call created go again when nothing
    else was written to them (see the module docstring).
    """
    folder = Path(folder)
    created_folders = missing_folders(folder) if not folder.is_dir() else []
    folder = prepare_output_folder(folder)
    key = folder.resolve()
    if key in _held:
        _held[key][1] += 1
        try:
            yield folder
        finally:
            _held[key][1] -= 1
        return
    try:
        descriptor, created_lock = _acquire(folder, wait, notify)
    except BaseException:
        _leave_as_found(folder / LOCK_NAME, False, created_folders)
        raise
    _held[key] = [descriptor, 1]
    failed = True
    found = _subfolders(folder)
    try:
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, f"{os.getpid()}\n".encode(), 0)
        for stale in stale_part_files(folder):
            stale.unlink(missing_ok=True)
        yield folder
        failed = False
    finally:
        del _held[key]
        if failed:  # still holding the lock, so no other run can be using the file or the folder
            _leave_as_found(folder / LOCK_NAME, created_lock, created_folders, found)
        os.close(descriptor)
