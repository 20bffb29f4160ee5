"""Atomic file output: readers see the old file or the complete new one, never a part.

Every file the package writes (study records, tables, figures) goes through :func:`atomic_path`:
the data goes to a temporary file in the target's directory, is flushed and fsync'ed, gets the
mode a plain ``open`` would have given it (the existing file's mode, else ``0o666`` minus the
umask; ``tempfile.mkstemp`` alone would leave ``0o600``) and is renamed over the target
(``os.replace`` is atomic on POSIX and Windows); then the directory is fsync'ed.

Temporary files are named ``.tmp-<pid>-<name>.<random>``: a later process removes only those
whose writer is no longer alive (:func:`is_abandoned_temp`), never another live process's file.
"""

from __future__ import annotations

import os
import re
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

TEMP_PREFIX = ".tmp-"
_TEMP_NAME = re.compile(r"^\.tmp-(\d+)-")


def current_umask() -> int:
    """The process umask, read without changing it where the system allows (Linux ``/proc``)."""
    try:
        with open("/proc/self/status", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: read by setting it, and put it straight back
    os.umask(mask)
    return mask


def _target_mode(path: Path) -> int:
    try:
        return stat.S_IMODE(os.stat(path).st_mode)  # overwriting keeps the mode, as open() does
    except OSError:
        return 0o666 & ~current_umask()


def fsync_dir(path: Path) -> None:
    """Flush a directory entry (a rename) to disk; a no-op where directories cannot be opened."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # e.g. Windows; the rename is still atomic
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces ``path`` atomically.

    Parameters
    ----------
    path : path
        The final file; its directory is created if needed.
    suffix : str
        Suffix of the temporary file (e.g. ``".png"``, for writers that read the format from it).

    If the body raises, the temporary file is removed and ``path`` is left as it was.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f"{TEMP_PREFIX}{os.getpid()}-{path.name}.", suffix=suffix,
                                    dir=path.parent)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(tmp, _target_mode(path))
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise
    fsync_dir(path.parent)


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` so that readers never see a partial file."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists (another user's process) or cannot tell: keep its file
    return True


def is_abandoned_temp(path: Path) -> bool:
    """True for a temporary file of :func:`atomic_path` whose writing process has ended."""
    match = _TEMP_NAME.match(Path(path).name)
    if match is None:
        return False  # not ours, or from an older version: leave it alone
    pid = int(match.group(1))
    return pid != os.getpid() and not _pid_alive(pid)
