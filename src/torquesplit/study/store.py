"""The study store: every finished case committed to an SQLite file as it completes.

Why SQLite in WAL mode (and not zarr): a case is one small row, and each row is its own
transaction: a process killed at any instant (SIGKILL included) leaves every committed
case intact and nothing half-written (the write-ahead log is replayed or discarded on the
next open); readers (a second terminal, a notebook) can watch a running study without
blocking the writer; it is one file, in the standard library, with no fixed array shape,
which a Monte Carlo study with a stopping rule does not know in advance.  zarr would need
a chunk rewrite per case and gives no atomicity across the values, status and timing of
a case.  Only the driver process writes; workers return their results to it.

``synchronous = NORMAL`` with WAL: a commit survives the death of the process (the OS has
the data); only a power loss can drop the last few commits, which --resume then
recomputes.

Tables
------
``meta``   key -> JSON value: provenance (study file text and canonical form, model and
           its hash, torquesplit version, design, output names).
``cases``  one row per finished case: status, reason, output values (JSON list in the
           order of ``meta.outputs``; floats written with repr, so they read back
           bit-identical), timings, worker, the run that computed it.
``runs``   one row per start of the study (the first run and each --resume).
"""

from __future__ import annotations

import json
import os
import sqlite3
import time
from pathlib import Path

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    run INTEGER PRIMARY KEY, started REAL, finished REAL, state TEXT,
    runner TEXT, workers INTEGER, computed INTEGER DEFAULT 0);
CREATE TABLE IF NOT EXISTS cases (
    idx INTEGER PRIMARY KEY, status TEXT NOT NULL, reason TEXT NOT NULL,
    vals TEXT NOT NULL, wall_time REAL, integration_time REAL, compile_time REAL,
    simulated_time REAL, runs INTEGER, settled INTEGER, worker TEXT, warnings TEXT,
    run INTEGER, finished REAL);
"""

STORE_NAME = "study.sqlite"
LOCK_NAME = "study.lock"


class StoreLock:
    """An exclusive lock on a study folder for the life of a run (``flock``: the OS drops
    it when the process dies, SIGKILL included), so that two processes never run the
    same study at once.  Where ``fcntl`` does not exist (Windows) it locks nothing."""

    def __init__(self, folder: Path):
        self.path = Path(folder) / LOCK_NAME
        self.file = open(self.path, "a+")
        try:
            import fcntl
        except ImportError:  # pragma: no cover - Windows
            return
        try:
            fcntl.flock(self.file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.file.seek(0)
            holder = self.file.read().strip() or "another process"
            self.file.close()
            raise BlockingIOError(holder) from None
        self.file.seek(0)
        self.file.truncate()
        self.file.write(f"pid {os.getpid()}")
        self.file.flush()

    def release(self) -> None:
        """Remove the lock file (still holding the lock) and let go: a finished study
        folder holds no stale ``study.lock``."""
        if not self.file.closed:
            try:
                self.path.unlink()
            except OSError:
                pass
            self.file.close()


class _StoreWrite:
    """Context of a write to the store: sqlite's error as an
    :class:`~torquesplit.errors.OutputError` naming the file, what is kept (every case
    committed before) and how to go on (free space, --resume)."""

    def __init__(self, path):
        self.path = path

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if exc is None or not isinstance(exc, sqlite3.Error):
            return False
        from ..errors import OutputError

        raise OutputError(f"cannot write the study store {self.path} ({exc}); the cases "
                          f"finished before are kept in it: free disk space (or mend the "
                          f"folder), then run the same command with --resume "
                          f"(resume=True in Python)") from None


class Store:
    """An open study store (``path`` ``":memory:"`` for a study without an output folder)."""

    def __init__(self, path):
        self.path = path if path == ":memory:" else Path(path)
        self.run_id: int | None = None
        self.lock: StoreLock | None = None
        try:
            self.db = sqlite3.connect(str(path), isolation_level=None, timeout=30.0)
            if path != ":memory:":
                self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")
            self.db.executescript(SCHEMA)
        except sqlite3.DatabaseError as exc:  # (a traceback, a reliability reviewer)
            from ..errors import OutputError

            if "locked" in str(exc):
                raise OutputError(f"the study store {path} is in use by another process "
                                  f"({exc}); wait for it to finish, or choose another "
                                  f"folder") from None
            if isinstance(exc, sqlite3.OperationalError):  # (the file is not the cause)
                raise OutputError(f"cannot open the study store {path} ({exc}): check that "
                                  f"its folder exists and can be written, and free disk "
                                  f"space") from None
            raise OutputError(f"{path} is not a readable study store ({exc}): move it "
                              f"aside (its finished cases cannot be read back), or start "
                              f"the study again with --overwrite (overwrite=True in "
                              f"Python)") from None

    def _writing(self):
        """A write that fails (a full disk, a folder gone) as one message that says what
        is kept and how to go on, not sqlite's traceback."""
        return _StoreWrite(self.path)

    # ------------------------------------------------------------------ meta
    def is_new(self) -> bool:
        return self.db.execute("SELECT COUNT(*) FROM meta").fetchone()[0] == 0

    def write_meta(self, meta: dict) -> None:
        with self._writing(), self.db:
            self.db.execute("BEGIN")
            self.db.executemany("INSERT OR REPLACE INTO meta VALUES (?, ?)",
                                [(k, json.dumps(v)) for k, v in meta.items()])

    def meta(self) -> dict:
        return {k: json.loads(v) for k, v in self.db.execute("SELECT key, value FROM meta")}

    # ------------------------------------------------------------------ runs
    def start_run(self, runner: str, workers: int) -> int:
        with self._writing():
            cur = self.db.execute("INSERT INTO runs (started, state, runner, workers) "
                                  "VALUES (?, 'running', ?, ?)",
                                  (time.time(), runner, workers))
        self.run_id = int(cur.lastrowid)
        return self.run_id

    def end_run(self, state: str) -> None:
        """Record how the run ended; best effort (it runs where the study stops, also
        after a write that failed: its error is the one to report)."""
        if self.run_id is not None:
            try:
                self.db.execute("UPDATE runs SET finished = ?, state = ? WHERE run = ?",
                                (time.time(), state, self.run_id))
            except sqlite3.Error:
                pass

    def runs(self) -> list[dict]:
        cols = ("run", "started", "finished", "state", "runner", "workers", "computed")
        return [dict(zip(cols, r)) for r in self.db.execute(
            f"SELECT {', '.join(cols)} FROM runs ORDER BY run")]

    # ------------------------------------------------------------------ cases
    def put(self, r: dict) -> None:
        """Commit one finished case (one transaction)."""
        with self._writing(), self.db:
            self.db.execute("BEGIN")
            self.db.execute(
                # (replaces a case that ended in an error, run again on resume)
                "INSERT OR REPLACE INTO cases VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (int(r["index"]), r["status"], r["reason"], json.dumps(list(r["values"])),
                 r["wall_time"], r["integration_time"], r["compile_time"],
                 r["simulated_time"], r["runs"], int(bool(r["settled"])), r["worker"],
                 json.dumps(r["warnings"]), self.run_id, time.time()))
            self.db.execute("UPDATE runs SET computed = computed + 1 WHERE run = ?",
                            (self.run_id,))

    def done(self) -> set[int]:
        return {int(i) for (i,) in self.db.execute("SELECT idx FROM cases")}

    def count(self) -> int:
        return int(self.db.execute("SELECT COUNT(*) FROM cases").fetchone()[0])

    def cases(self, below: int | None = None):
        """Finished cases ordered by index: dicts with status, reason, values..."""
        sql = ("SELECT idx, status, reason, vals, wall_time, integration_time, compile_time, "
               "simulated_time, runs, settled, worker, run, warnings FROM cases")
        args: tuple = ()
        if below is not None:
            sql += " WHERE idx < ?"
            args = (int(below),)
        for row in self.db.execute(sql + " ORDER BY idx", args):
            yield {"index": row[0], "status": row[1], "reason": row[2],
                   "values": json.loads(row[3]), "wall_time": row[4],
                   "integration_time": row[5], "compile_time": row[6],
                   "simulated_time": row[7], "runs": row[8], "settled": bool(row[9]),
                   "worker": row[10], "run": row[11],
                   "warnings": json.loads(row[12]) if row[12] else []}

    def close(self) -> None:
        self.db.close()
        if self.lock is not None:
            self.lock.release()
