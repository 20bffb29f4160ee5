"""The result store of a study: one JSON file per finished run, written atomically.

Layout of a study directory::

    study.toml              the study that was run (rewritten at each start)
    runs/<run_id>.json      one record per finished run
    failed/<run_id>.json    the error of a run that raised (removed once the run succeeds)

A record is written to a temporary file in the same directory, flushed and fsync'ed, then
renamed over its final name (``os.replace`` is atomic on POSIX and Windows) and the directory
is fsync'ed. A reader therefore sees either no file or a complete one; a killed process leaves
at most a temporary file, which is ignored and cleaned up at the next start. Because the file
name is the run id, a run can never be stored twice.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Iterator

RECORD_FORMAT = "pymoo-rail/run-record/1"
RUNS_DIR = "runs"
FAILED_DIR = "failed"
STUDY_FILE = "study.toml"
_TMP_PREFIX = ".tmp-"


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # e.g. Windows cannot open directories; the rename is still atomic
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_text(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` so that readers never see a partial file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=_TMP_PREFIX + path.name + ".", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    _fsync_dir(path.parent)
    return path


class ResultStore:
    """Records of a study directory (see the module docstring for the layout)."""

    def __init__(self, directory: str | Path):
        self.directory = Path(directory)
        self.runs_dir = self.directory / RUNS_DIR
        self.failed_dir = self.directory / FAILED_DIR

    def prepare(self) -> None:
        """Create the directories and remove temporary files a killed run left behind."""
        self.runs_dir.mkdir(parents=True, exist_ok=True)
        self.failed_dir.mkdir(parents=True, exist_ok=True)
        for folder in (self.directory, self.runs_dir, self.failed_dir):
            for stale in folder.glob(_TMP_PREFIX + "*"):
                try:
                    stale.unlink()
                except OSError:
                    pass

    def path(self, run_id: str) -> Path:
        return self.runs_dir / f"{run_id}.json"

    def done_ids(self) -> set[str]:
        """Ids of the runs with a stored record."""
        if not self.runs_dir.is_dir():
            return set()
        return {p.stem for p in self.runs_dir.glob("*.json") if not p.name.startswith(".")}

    def write(self, record: dict) -> Path:
        """Store a finished run at once; clears an earlier failure of the same run."""
        path = atomic_write_text(self.path(record["run_id"]), json.dumps(record))
        failure = self.failed_dir / f"{record['run_id']}.json"
        if failure.exists():
            failure.unlink()
        return path

    def write_failure(self, run_id: str, failure: dict) -> Path:
        return atomic_write_text(self.failed_dir / f"{run_id}.json", json.dumps(failure, indent=1))

    def failures(self) -> list[dict]:
        if not self.failed_dir.is_dir():
            return []
        return [json.loads(p.read_text(encoding="utf-8")) for p in sorted(self.failed_dir.glob("*.json"))
                if not p.name.startswith(".")]

    def read(self, run_id: str) -> dict:
        return json.loads(self.path(run_id).read_text(encoding="utf-8"))

    def records(self, run_ids: set[str] | None = None) -> Iterator[dict]:
        """Every stored record (or those in ``run_ids``), in file-name order."""
        if not self.runs_dir.is_dir():
            return
        for p in sorted(self.runs_dir.glob("*.json")):
            if p.name.startswith(".") or (run_ids is not None and p.stem not in run_ids):
                continue
            record = json.loads(p.read_text(encoding="utf-8"))
            if record.get("format") != RECORD_FORMAT:
                raise ValueError(f"{p}: field 'format' = {record.get('format')!r}: not a {RECORD_FORMAT} record")
            yield record
