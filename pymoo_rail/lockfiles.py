"""OS file locks that leave no file behind once released.

``filelock`` keeps a Unix lock file after release: deleting it there, after the lock is let go,
would let a process that already opened the old file and a process creating a new one both
believe they hold the lock. :func:`release_removing` deletes the file *while still holding* the
lock and only then releases it; ``filelock`` (from 3.20.4) checks after every acquisition that
the file it locked still has a name (``st_nlink`` > 0) and otherwise opens the path afresh, so a
waiter that locked the deleted file retries on the new one and never shares the lock.
"""

from __future__ import annotations

import os
from pathlib import Path

from filelock import BaseFileLock


def release_removing(lock: BaseFileLock) -> None:
    """Delete a held lock's file, then release the lock.

    Parameters
    ----------
    lock : filelock.BaseFileLock
        A lock this process holds (acquired once: a nested hold is released one level, and its
        file is kept while the outer hold remains).
    """
    try:
        if lock.is_locked and getattr(lock, "lock_counter", 1) <= 1 and os.name != "nt":
            # Windows: filelock deletes the file itself on release, and an open file cannot be deleted
            Path(lock.lock_file).unlink(missing_ok=True)
    except OSError:
        pass  # a read-only folder or a file already gone: the lock still has to be released
    finally:
        lock.release()


__all__ = ["release_removing"]
