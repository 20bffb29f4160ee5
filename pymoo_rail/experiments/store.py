"""The result store of a study: one checksummed JSON file per finished run, written atomically.

Layout of a study directory::

    study.toml              the study that was run (rewritten at each start)
    runs/<run_id>.json      one record per finished run
    failed/<run_id>.json    the error of a run that raised (removed once the run succeeds)
    corrupt/<run_id>.json.<time>   a record that failed its check, moved aside (then redone)
    stale/<run_id>.json.<time>     a record whose inputs changed, moved aside (then redone)
    locks/<run_id>.lock     the claim of a process computing that run (``filelock``)

Guarantees (``docs/experiments.md`` says how each is tested):

- A record is written through :func:`pymoo_rail.atomic.atomic_path` (temporary file, fsync,
  rename), so a reader sees no file or a complete one. Temporary files carry their writer's pid;
  a start removes only those whose writer has ended.
- Every record carries a SHA-256 checksum of its content. A record that does not parse, lacks
  a field, names another run or fails its checksum is a :class:`RecordError` naming the file;
  the study runner moves it to ``corrupt/`` and redoes the run.
- A record carries the fingerprint of the run's inputs (``inputs``: the case content, files the
  specs name, package versions); the runner compares it with the current one and redoes a run
  whose inputs changed, saying which.
- A run is computed only by the process holding its claim (an OS file lock from ``filelock``,
  released by the system when the holder dies), so two studies on one directory compute each
  run once. A lock file that is not a regular file (a planted symbolic link) is refused.
- A record of an older format (no checksum) is never served: reading it raises
  :class:`LegacyRecordError` and the runner sets it aside and redoes the run.
- A write that fails for want of space (or of permission) is a :class:`StoreError` naming the
  file and saying that the records already written are kept.
"""

from __future__ import annotations

import datetime as _dt
import errno
import hashlib
import json
import os
from pathlib import Path
from contextlib import contextmanager
from typing import Iterator

import numpy as np
from filelock import FileLock, Timeout

from pymoo_rail.atomic import TEMP_PREFIX, atomic_write_text, is_abandoned_temp
from pymoo_rail.experiments.spec import canonical_json
from pymoo_rail.lockfiles import release_removing

RECORD_FORMAT = "pymoo-rail/run-record/2"
# records written before checksums and input fingerprints: readable, but always redone by a study
LEGACY_FORMATS = ("pymoo-rail/run-record/1",)
RUNS_DIR = "runs"
FAILED_DIR = "failed"
CORRUPT_DIR = "corrupt"
STALE_DIR = "stale"
LOCKS_DIR = "locks"
STUDY_FILE = "study.toml"
REQUIRED_FIELDS = ("format", "run_id", "problem", "algorithm", "seed", "budget", "n_var", "n_obj", "front",
                   "indicators", "problem_label", "algorithm_label", "n_eval", "n_gen", "wall_time_s", "feasible")

__all__ = ["ResultStore", "RecordError", "LegacyRecordError", "StoreError", "record_checksum",
           "atomic_write_text", "RECORD_FORMAT"]


class RecordError(ValueError):
    """A stored record that cannot be trusted; the message names the file and what is wrong."""

    def __init__(self, path: Path, reason: str):
        self.path = Path(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")


class LegacyRecordError(RecordError):
    """A record of an older format (``LEGACY_FORMATS``): it carries no checksum, so it is never served."""


class StoreError(OSError):
    """A study directory that cannot be written or locked; the message names the file and what to do.

    An ``OSError`` (its ``errno`` is the system's), so callers that catch ``OSError`` still do.
    """

    def __init__(self, path: str | Path, reason: str, code: int | None = None):
        super().__init__(f"{path}: {reason}")
        self.path = Path(path)
        self.reason = reason
        self.errno = code

    def __reduce__(self):  # pool workers send it back to the study process
        return type(self), (str(self.path), self.reason, self.errno)


# errors a write can meet that no retry fixes: the study stops, saying so
_FULL = {errno.ENOSPC: "no space left on the device", errno.EDQUOT: "disk quota exceeded",
         errno.EROFS: "the file system is read-only", errno.EACCES: "permission denied",
         errno.EPERM: "operation not permitted"}


@contextmanager
def writing(path: str | Path) -> Iterator[None]:
    """Turn a failed write of ``path`` for want of space or permission into a :class:`StoreError`."""
    try:
        yield
    except StoreError:
        raise
    except OSError as err:
        if err.errno not in _FULL:
            raise
        raise StoreError(path, f"cannot write ({_FULL[err.errno]}): the study stopped; every run finished "
                               "before is kept in runs/, and running the study again resumes once the "
                               "problem is fixed", err.errno) from err


def record_checksum(record: dict) -> str:
    """SHA-256 of the record's content (key-sorted compact JSON, without the checksum itself)."""
    body = {k: v for k, v in record.items() if k != "checksum"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_fields(path: Path, record: dict) -> None:
    """The types a reader relies on, and a run id that is the hash of the record's own identity.

    A checksum only shows the record was not damaged; anyone can write a record with a valid one,
    so a received results folder is read only after these checks (a bad one is a RecordError).
    """
    def bad(name: str, what: str) -> RecordError:
        return RecordError(path, f"field '{name}' = {record.get(name)!r:.80}: {what}")

    if not isinstance(record["run_id"], str):
        raise bad("run_id", "must be a string")
    for key in ("problem", "algorithm"):
        spec = record[key]
        if not isinstance(spec, dict) or not isinstance(spec.get(key), str):
            raise bad(key, f"must be a table naming the {key}")
    if not _is_int(record["seed"]):
        raise bad("seed", "must be an integer")
    budget = record["budget"]
    if not isinstance(budget, dict) or len(budget) != 1 or not all(_is_int(v) for v in budget.values()):
        raise bad("budget", "must be a table with one integer")
    for key in ("n_var", "n_obj"):
        if not _is_int(record[key]) or record[key] < 1:
            raise bad(key, "must be a positive integer")
    identity = {"problem": record["problem"], "algorithm": record["algorithm"], "seed": record["seed"],
                "budget": budget}
    if hashlib.sha256(canonical_json(identity).encode()).hexdigest()[:16] != record["run_id"]:
        raise bad("run_id", "is not the id of the record's own problem, algorithm, seed and budget")
    indicators = record["indicators"]
    if not isinstance(indicators, dict) or not all(_is_number(v) for v in indicators.values()):
        raise bad("indicators", "must be a table of numbers")
    for key in ("unavailable", "inputs"):
        table = record.get(key, {})
        if not isinstance(table, dict) or not all(isinstance(v, str) for v in table.values()):
            raise bad(key, "must be a table of strings")
    if not isinstance(record.get("counters", {}), dict):
        raise bad("counters", "must be a table")
    front = record["front"]
    if not isinstance(front, dict) or not isinstance(front.get("extras", {}), dict):
        raise bad("front", "must be a table with F, X, CV (and extras)")
    try:
        n = len(front["F"])
        shapes = (np.asarray(front["F"], dtype=float).reshape(n, record["n_obj"]),
                  np.asarray(front["X"], dtype=float).reshape(n, record["n_var"]),
                  np.asarray(front["CV"], dtype=float).reshape(n),
                  *(np.asarray(v, dtype=float).reshape(n) for v in front.get("extras", {}).values()))
    except (KeyError, TypeError, ValueError) as err:
        raise bad("front", f"F, X, CV and extras must be arrays of numbers of one member per row ({err})") \
            from None
    del shapes
    for key in ("wall_time_s", "cpu_time_s", "n_eval", "n_gen"):
        if key in record and not _is_number(record[key]):
            raise bad(key, "must be a number")
    for key in ("problem_label", "algorithm_label"):
        if not isinstance(record[key], str):
            raise bad(key, "must be a string")
    if not isinstance(record["feasible"], bool):
        raise bad("feasible", "must be true or false")
    history = record.get("history")
    if history is not None and not (isinstance(history, dict) and all(isinstance(v, list) for v in history.values())):
        raise bad("history", "must be a table of lists (or null)")
    checkpoints = record.get("checkpoints")
    if checkpoints is not None:
        try:
            # an empty F: no feasible member yet at that checkpoint (a run may find none at all)
            if len(checkpoints["n_eval"]) != len(checkpoints["F"]) or not all(
                    len(F) == 0 or np.asarray(F, dtype=float).reshape(len(F), -1).shape[1] == record["n_obj"]
                    for F in checkpoints["F"]):
                raise ValueError("one F of n_obj columns per n_eval")
        except (KeyError, TypeError, ValueError) as err:
            raise bad("checkpoints", f"must hold n_eval and one objective array per n_eval ({err})") from None


def _stamp() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%dT%H%M%S.%fZ")


class ResultStore:
    """Records of a study directory (see the module docstring for the layout and guarantees)."""

    def __init__(self, directory: str | Path):
        self.directory = Path(directory)
        self.runs_dir = self.directory / RUNS_DIR
        self.failed_dir = self.directory / FAILED_DIR
        self.locks_dir = self.directory / LOCKS_DIR

    def prepare(self) -> None:
        """Create the directories; remove temporary files whose writing process has ended."""
        for folder in (self.runs_dir, self.failed_dir, self.locks_dir):
            with writing(folder):
                folder.mkdir(parents=True, exist_ok=True)
        for folder in (self.directory, self.runs_dir, self.failed_dir):
            for temp in folder.glob(TEMP_PREFIX + "*"):
                if is_abandoned_temp(temp):
                    try:
                        temp.unlink()
                    except OSError:  # another process cleaned it first
                        pass

    def path(self, run_id: str) -> Path:
        """The record file of a run."""
        return self.runs_dir / f"{run_id}.json"

    def done_ids(self) -> set[str]:
        """Ids of the runs with a record file (not checked: see :meth:`load`)."""
        if not self.runs_dir.is_dir():
            return set()
        return {p.stem for p in self.runs_dir.glob("*.json") if not p.name.startswith(".")}

    # ------------------------------------------------------------------ writing
    def write(self, record: dict) -> Path:
        """Store a finished run (adding its checksum); clears an earlier failure of the same run."""
        record = {**record, "checksum": record_checksum(record)}
        with writing(self.path(record["run_id"])):
            path = atomic_write_text(self.path(record["run_id"]), json.dumps(record))
        failure = self.failed_dir / f"{record['run_id']}.json"
        try:
            failure.unlink()
        except FileNotFoundError:
            pass
        return path

    def write_failure(self, run_id: str, failure: dict) -> Path:
        """Store the error of a failed run (atomically) and return its file."""
        path = self.failed_dir / f"{run_id}.json"
        with writing(path):
            return atomic_write_text(path, json.dumps(failure, indent=1))

    def set_aside(self, run_id: str, folder: str) -> Path | None:
        """Move the record of ``run_id`` into ``folder`` (``corrupt`` or ``stale``), time-stamped.

        Returns the new path, or None when there was no record.
        """
        target_dir = self.directory / folder
        target = target_dir / f"{run_id}.json.{_stamp()}"
        try:
            with writing(target):
                target_dir.mkdir(parents=True, exist_ok=True)
                os.replace(self.path(run_id), target)
        except FileNotFoundError:
            return None
        return target

    # ------------------------------------------------------------------ claims
    def claim(self, run_id: str, wait: bool = False) -> FileLock | None:
        """Take the lock of one run: the holder alone computes it.

        Returns the held lock (release it with :func:`pymoo_rail.lockfiles.release_removing`, which
        also deletes its file), or None when another process holds it and ``wait`` is false. The operating system releases the lock of a process
        that dies, so a killed study never blocks the next one.
        """
        path = self.locks_dir / f"{run_id}.lock"
        with writing(path):
            self.locks_dir.mkdir(parents=True, exist_ok=True)
        if self.locks_dir.is_symlink() or path.is_symlink() or (path.exists() and not path.is_file()):
            raise StoreError(path, "the lock file is not a regular file (a symbolic link or another kind of "
                                   "file was put in its place): remove it and start the study again")
        lock = FileLock(path, thread_local=False)
        for attempt in range(3):
            try:
                with writing(path):
                    lock.acquire(timeout=-1 if wait else 0)
                return lock
            except Timeout:
                return None
            except StoreError:
                raise
            except FileNotFoundError as err:
                if attempt == 2:
                    raise StoreError(path, f"cannot take the lock of run {run_id}: its folder keeps vanishing "
                                           "(another process removing it?)", err.errno) from err
                with writing(path):  # a study that finished meanwhile removed the empty locks/ folder
                    self.locks_dir.mkdir(parents=True, exist_ok=True)
            except OSError as err:
                raise StoreError(path, f"cannot take the lock of run {run_id} ({err.strerror or err}): check the "
                                       "file and the folder's permissions", err.errno) from err
        return None  # not reached: the loop returns or raises

    # ------------------------------------------------------------------ reading
    def check(self, path: Path) -> dict:
        """The record in ``path`` after every check; :class:`RecordError` names what failed."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError as err:
            raise RecordError(path, f"not UTF-8 text ({err.reason}): the record is corrupt") from None
        if not text.strip():
            raise RecordError(path, "the record is empty (truncated)")
        try:
            record = json.loads(text)
        except json.JSONDecodeError as err:
            raise RecordError(path, f"not valid JSON ({err.msg} at character {err.pos} of {len(text)}): "
                                    "the record is truncated or corrupt") from None
        if not isinstance(record, dict):
            raise RecordError(path, f"holds a {type(record).__name__}, not a run record")
        fmt = record.get("format")
        if fmt in LEGACY_FORMATS:
            raise LegacyRecordError(path, f"field 'format' = {fmt!r}: an older record without a checksum, "
                                          "never served; run the study again to redo the run")
        if fmt != RECORD_FORMAT:
            raise RecordError(path, f"field 'format' = {fmt!r}: not a {RECORD_FORMAT} record")
        missing = [k for k in REQUIRED_FIELDS if k not in record]
        if missing:
            raise RecordError(path, f"field '{missing[0]}' is missing: the record is incomplete")
        if record["run_id"] != path.stem:
            raise RecordError(path, f"field 'run_id' = {record['run_id']!r} does not match the file name")
        expected = record_checksum(record)
        if record.get("checksum") != expected:
            raise RecordError(path, f"field 'checksum' = {record.get('checksum')!r} does not match the "
                                    f"content ({expected}): the record was altered or damaged")
        _check_fields(path, record)
        return record

    def load(self, run_id: str) -> dict | None:
        """The checked record of ``run_id``, None when there is none; :class:`RecordError` when bad."""
        path = self.path(run_id)
        if not path.is_file():
            return None
        return self.check(path)

    def read(self, run_id: str) -> dict:
        """The checked record of a run (:class:`RecordError` when it is corrupt)."""
        return self.check(self.path(run_id))

    def failures(self) -> list[dict]:
        """The stored errors of failed runs, one dict per run."""
        if not self.failed_dir.is_dir():
            return []
        out = []
        for p in sorted(self.failed_dir.glob("*.json")):
            if p.name.startswith("."):
                continue
            try:
                out.append(json.loads(p.read_text(encoding="utf-8")))
            except (json.JSONDecodeError, UnicodeDecodeError):
                out.append({"run_id": p.stem, "run": p.stem, "error": f"{p}: unreadable failure record"})
        return out

    def records(self, run_ids: set[str] | None = None) -> Iterator[dict]:
        """Every stored record (or those in ``run_ids``), checked, in file-name order.

        Raises :class:`RecordError` naming the first record that fails its checks; running the
        study again moves it aside and redoes the run.
        """
        if not self.runs_dir.is_dir():
            return
        for p in sorted(self.runs_dir.glob("*.json")):
            if p.name.startswith(".") or (run_ids is not None and p.stem not in run_ids):
                continue
            try:
                yield self.check(p)
            except LegacyRecordError:
                raise
            except RecordError as err:
                raise RecordError(err.path, f"{err.reason}; run the study again to set it aside and redo "
                                            "the run") from None

    def remove_idle_locks(self) -> int:
        """Delete the lock files of stored runs that no process holds, and ``locks/`` once it is empty.

        The study runner deletes each claim's file as it releases it; this removes what an
        interrupted or older study left. A lock is deleted only while held, and only for a run
        whose record is stored: a process that still opened the old file finds the run stored and
        skips it, so no run is computed twice. Returns how many lock files were deleted.
        """
        if not self.locks_dir.is_dir() or self.locks_dir.is_symlink():
            return 0
        removed = 0
        for path in sorted(self.locks_dir.glob("*.lock")):
            if path.is_symlink() or not path.is_file() or not self.path(path.stem).is_file():
                continue
            lock = FileLock(path, thread_local=False)
            try:
                lock.acquire(timeout=0)
            except (Timeout, OSError):
                continue  # held by a running process, or not ours to take
            release_removing(lock)
            removed += 1
        try:
            self.locks_dir.rmdir()  # only if empty
        except OSError:
            pass
        return removed
