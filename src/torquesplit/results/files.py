"""Results files written safely: checked before the run, claimed, complete or absent.

A results file is worth the minutes of computation behind it; writing one must never
destroy an earlier good file, leave a partial one behind or let two runs both believe
they wrote it.  Four steps, each usable on its own:

=====================  ================================================================
step                   what it guarantees
=====================  ================================================================
:func:`check_output`   before any computation: a suffix torquesplit writes, an existing
                       folder it may write in, not a folder, no existing file (with its
                       CSV companions) unless overwriting is asked for
:func:`claim_output`   a lock per output file, held from before the computation until
                       the file is written: a second run on the same path is refused at
                       once, naming the run that holds it.  The lock is ``flock`` on a
                       hidden ``.NAME.lock`` beside the file; the kernel releases it
                       when a process dies, even by SIGKILL, so no lock goes stale
:meth:`OutputClaim.    each file is serialised in memory first, then written to an
write`                 unnamed temporary file in the target folder (Linux
                       ``O_TMPFILE``, which vanishes with the process; elsewhere a
                       hidden ``.NAME.*.tmp`` that the next write of NAME removes),
                       fsynced and linked or renamed into place: the file is the old
                       one or the new one, never a mixture, and a kill at any moment
                       leaves no partial file under any name
:func:`provenance`     attributes that say which run wrote the file (``run_id``, UTC
                       time, torquesplit version, command line)
=====================  ================================================================

Without overwriting, the new file is linked to its name, which fails if the name
exists: even a writer that ignores the lock (another program) cannot be silently
overwritten.

Examples
--------
>>> import tempfile, pathlib
>>> from torquesplit.results import files
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> plan = files.check_output(folder / "run.nc")
>>> with files.claim_output(plan) as claim:
...     _ = claim.write({plan.path: b"complete"})
>>> (folder / "run.nc").read_bytes()
b'complete'
>>> files.check_output(folder / "run.nc")
Traceback (most recent call last):
...
torquesplit.errors.OutputError: ... exists; use --force (overwrite=True in Python) to replace it, or choose another file
"""

from __future__ import annotations

import contextlib
import datetime
import errno
import functools
import io
import json
import os
import secrets
import sys
import uuid
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import OutputBusyError, OutputError, OutputFormatError, clip_path, clip_text

try:  # POSIX; elsewhere the lock is an exclusively created file
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None

#: suffix -> format of the files ``Results.save`` writes
RESULT_FORMATS = {".nc": "netcdf", ".netcdf": "netcdf", ".h5": "netcdf", ".mat": "mat",
                  ".csv": "csv"}
#: suffixes of NetCDF files (``static --out``, ``Results.to_netcdf``)
NETCDF_FORMATS = {".nc": "netcdf", ".netcdf": "netcdf", ".h5": "netcdf"}

_OVERWRITE_HINT = "use --force (overwrite=True in Python) to replace it, or choose another file"

#: write into an unnamed O_TMPFILE file where the system offers one (tests switch it off
#: to exercise the named-temporary fallback)
USE_O_TMPFILE = sys.platform.startswith("linux") and hasattr(os, "O_TMPFILE")

_CHUNK = 1 << 20


@dataclass(frozen=True)
class OutputPlan:
    """A checked output request: where, in which format, which files it writes."""

    path: Path
    """The file named by the user."""
    format: str
    """``"netcdf"``, ``"mat"``, ``"csv"`` or the suffix's own name."""
    files: tuple[Path, ...]
    """Every file the save writes (CSV: the summary and its two companions)."""
    overwrite: bool
    """Existing files may be replaced."""


def companion_files(path: Path, fmt: str) -> tuple[Path, ...]:
    """The files a save of ``fmt`` to ``path`` writes: CSV writes ``NAME_groups.csv``,
    ``NAME_history.csv``, ``NAME_cycles.csv``, ``NAME_bearings.csv``,
    ``NAME_elements.csv`` and ``NAME_about.json`` (:func:`about_bytes`) beside
    ``NAME.csv``."""
    if fmt == "csv":
        return (path, path.with_name(path.stem + "_history.csv"),
                path.with_name(path.stem + "_cycles.csv"),
                path.with_name(path.stem + "_groups.csv"),
                path.with_name(path.stem + "_bearings.csv"),
                path.with_name(path.stem + "_elements.csv"), about_path(path))
    return (path,)


def _remove_replaced_set(plan: OutputPlan, contents) -> None:
    """Before a CSV set is written over another one: remove the files of the old set (as
    its ``NAME_about.json`` lists them) that the new set does not write (a reviewer's
    ``--force`` left a quasi-static run's NAME_mesh.csv beside a run's NAME_groups.csv).
    Only files named ``NAME_*`` beside it are touched."""
    about = next((Path(f) for f in contents if Path(f).name.endswith("_about.json")), None)
    if about is None or not about.is_file():
        return
    try:
        listed = json.loads(about.read_text(encoding="utf-8")).get("files") or []
    except (OSError, ValueError, AttributeError):
        return
    stem = about.name[:-len("_about.json")]
    keep = {Path(f).name for f in plan.files}
    for name in listed:
        # (a name of this folder only: no separator, not empty, not '..')
        if (not isinstance(name, str) or not name.startswith(stem + "_") or name in keep
                or any(c in name for c in "/\\") or name in (".", "..")):
            continue
        old = about.with_name(name)
        if old.is_file():
            with contextlib.suppress(OSError):
                old.unlink()


def about_path(path: Path) -> Path:
    """``NAME_about.json`` beside the CSV table ``NAME.csv``."""
    return path.with_name(path.stem + "_about.json")


def about_bytes(run_id: str, model_json: str | None, warnings=(), **more) -> bytes:
    """What a CSV set cannot hold in its tables, as JSON (NaN as null, :mod:`torquesplit.
    _json`): the :func:`provenance` of the run, the model, the warnings the command
    printed, and ``more`` (the metrics, the load-sharing definition...).  The ``model``
    entry is a model file in JSON (SI numbers): saved alone, it runs again."""
    from .. import _json

    about = {"provenance": provenance(run_id, model_json),
             "model": json.loads(model_json) if model_json else None,
             "warnings": list(warnings)}
    about.update(more)
    if "files" in about:  # (the set's file names: an overwrite removes what it leaves out)
        about["files"] = [Path(f).name for f in about["files"]]
    return (_json.dumps(about, indent=1, default=str) + "\n").encode("utf-8")


def check_output(path, *, formats: dict[str, str] | None = None, overwrite: bool = False,
                 what: str = "results") -> OutputPlan:
    """Check an output path before any computation.

    Parameters
    ----------
    path : str or Path
        The file to write.
    formats : dict, optional
        Accepted suffixes and their formats (default :data:`RESULT_FORMATS`).
    overwrite : bool
        Existing files may be replaced; without it an existing file is an error.
    what : str
        What is written, for messages ("results", "the model file").

    Returns
    -------
    OutputPlan

    Raises
    ------
    OutputFormatError
        The suffix is not one of ``formats`` (also a ``ValueError``).
    OutputError
        The folder does not exist or cannot be written, the path is a folder, or a file
        exists and ``overwrite`` is false.
    """
    formats = RESULT_FORMATS if formats is None else formats
    path = Path(os.path.expanduser(str(path)))
    suffix = path.suffix.lower()
    if path.is_dir():
        example = path / ("results" + next(iter(formats)))
        raise OutputError(f"{clip_path(path)} is a folder; give a file name in it, e.g. "
                          f"{clip_path(example)}")
    if suffix not in formats:
        known = sorted(set(formats), key=list(formats).index)
        listed = (", ".join(known[:-1]) + " or " + known[-1]) if len(known) > 1 else known[0]
        if set(formats) == set(RESULT_FORMATS):
            listed = ".nc, .mat or .csv"
        elif set(formats) == set(NETCDF_FORMATS):
            listed = ".nc"
        raise OutputFormatError(f"cannot save {what} as {clip_text(path.name)!r}; use a "
                                f"{listed} file")
    parent = path.parent
    if not parent.exists():
        raise OutputError(f"cannot write {clip_path(path)}: the folder "
                          f"{clip_path(parent)} does not exist; create it first or "
                          f"choose another folder")
    if not parent.is_dir():
        raise OutputError(f"cannot write {clip_path(path)}: {clip_path(parent)} is "
                          f"not a folder; choose a path in a folder")
    check_writable_folder(parent, path)
    fmt = formats[suffix]
    targets = companion_files(path, fmt)
    for f in targets:
        if f.is_dir():
            raise OutputError(f"{clip_path(f)} is a folder; choose another file name")
        if f.exists() and not f.is_file():
            raise OutputError(f"{clip_path(f)} is not a regular file; choose another "
                              f"file name")
        if (f.exists() or f.is_symlink()) and not overwrite:
            raise OutputError(f"{clip_path(f)} exists; {_OVERWRITE_HINT}")
    return OutputPlan(path=path, format=fmt, files=targets, overwrite=overwrite)


def check_writable_folder(folder, target=None) -> None:
    """Refuse a folder in which no file can be created, by creating (and removing) one.

    ``os.access`` is not enough: it says yes to root, and to ``/proc`` or a read-only
    mount.  ``target`` is the file the user named, for the message.
    """
    folder = Path(folder)
    named = clip_path(target if target is not None else folder)
    where = clip_path(folder)
    if not os.access(folder, os.W_OK | os.X_OK):
        reason = "permission denied"
    else:
        probe = folder / f".{Path(str(target or 'torquesplit')).name}.{secrets.token_hex(6)}.tmp"
        try:
            os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        except OSError as exc:
            reason = exc.strerror or exc.__class__.__name__
            if exc.errno == errno.ENOENT and folder.is_dir():
                # (/proc: 'not writable (No such file or directory)' of a folder that
                # exists, a reviewer)
                reason = "it accepts no new files"
        else:
            with contextlib.suppress(OSError):
                os.unlink(probe)
            return
    raise OutputError(f"cannot write {named}: the folder {where} is not writable ({reason}); "
                      f"choose a folder you can write to")


# --------------------------------------------------------------------------- provenance
def new_run_id() -> str:
    """A fresh identifier of a run (UUID4 text)."""
    return str(uuid.uuid4())


def cell_column(texts):
    """Texts as a MATLAB cell column (N x 1; none: an empty cell, 0 x 1, which
    ``isempty`` sees, where {''} counted as one text)."""
    import numpy as np

    texts = list(texts)
    out = np.empty((len(texts), 1), dtype=object)
    for i, t in enumerate(texts):
        out[i, 0] = str(t)
    return out


def provenance(run_id: str, model_json: str | None = None) -> dict[str, str]:
    """Attributes that say which run wrote a file: its id and time, the software with
    its git commit (:func:`software_commit`), the command as a shell would take it back
    and the folder it ran in, and with ``model_json`` (the model embedded in the file)
    that model's SHA-256, the same for the same model whatever file it came from.

    Examples
    --------
    >>> sorted(provenance("abc", "{}"))
    ['command', 'created_utc', 'model_sha256', 'run_id', 'software', 'working_directory']
    """
    import hashlib
    import shlex

    from .. import __version__

    commit = software_commit()
    out = {
        "run_id": run_id,
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
            timespec="seconds"),
        "software": f"torquesplit {__version__}" + (f" (commit {commit})" if commit else ""),
        "command": clip_text(shlex.join([Path(sys.argv[0]).name] + sys.argv[1:])
                             if sys.argv else "", 500),
        "working_directory": clip_text(os.getcwd(), 500),
    }
    if model_json is not None:
        out["model_sha256"] = hashlib.sha256(model_json.encode("utf-8")).hexdigest()
    return out


@functools.lru_cache(maxsize=1)
def software_commit() -> str:
    """The git commit of this torquesplit ("1fac9aa, with local changes" when its
    sources differ from it), or "" when it is not run from a git checkout."""
    import subprocess

    here = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(["git", "-C", str(here), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=3)
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--",
                                str(here)], capture_output=True, text=True, timeout=3)
    except (OSError, subprocess.SubprocessError):
        return ""
    if head.returncode != 0 or not head.stdout.strip():
        return ""
    return head.stdout.strip() + (", with local changes" if dirty.stdout.strip() else "")


# --------------------------------------------------------------------------- claims
@dataclass
class _Held:
    fd: int
    lock_path: Path
    run_id: str
    count: int = 1


#: locks this process holds, by the output file's real path (a claim is re-entrant, so
#: that ``run --out`` can claim before the computation and ``Results.save`` again)
_HELD: dict[str, _Held] = {}


def _key(path: Path) -> str:
    return os.path.join(os.path.realpath(path.parent), path.name)


def _lock_path(path: Path) -> Path:
    return path.parent / f".{path.name}.lock"


@dataclass
class OutputClaim:
    """The right to write the files of an :class:`OutputPlan`; a context manager.

    Entering takes a lock per file (or joins this process's own earlier claim);
    leaving releases them.  :meth:`write` writes atomically.
    """

    plan: OutputPlan
    run_id: str
    _keys: list[str] = field(default_factory=list)

    def __enter__(self) -> OutputClaim:
        info = {"pid": os.getpid(), "run_id": self.run_id,
                "since_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
                    timespec="seconds"),
                "command": clip_text(" ".join(sys.argv), 200)}
        try:
            for f in self.plan.files:
                key = _key(f)
                held = _HELD.get(key)
                if held is not None:
                    held.count += 1
                    self.run_id = held.run_id
                    self._keys.append(key)
                    continue
                fd = _acquire(_lock_path(f), info, f)
                _HELD[key] = _Held(fd, _lock_path(f), self.run_id)
                self._keys.append(key)
                _remove_stale_temporaries(f)
            if not self.plan.overwrite:
                for f in self.plan.files:
                    if f.exists() or f.is_symlink():
                        raise OutputError(f"{clip_path(f)} was written by another "
                                          f"program or run since it was checked; "
                                          f"{_OVERWRITE_HINT}")
        except BaseException:
            self._release()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self._release()

    def _release(self) -> None:
        while self._keys:
            key = self._keys.pop()
            held = _HELD.get(key)
            if held is None:  # pragma: no cover - defensive
                continue
            held.count -= 1
            if held.count == 0:
                del _HELD[key]
                _release(held.fd, held.lock_path)

    def write(self, contents: dict[Path, bytes]) -> list[Path]:
        """Write each ``{path: bytes}`` atomically (see the module docstring).

        The paths must be files of this claim's plan.  Without ``overwrite`` the new
        files are linked to their names, which fails if a name exists; if one of several
        files fails, the ones this call linked are removed again.

        Returns
        -------
        list of Path
            The files written, in the order given.
        """
        allowed = {_key(f) for f in self.plan.files}
        if self.plan.overwrite:
            _remove_replaced_set(self.plan, contents)
        done: list[Path] = []
        try:
            for path, data in contents.items():
                path = Path(path)
                if _key(path) not in allowed:
                    raise OutputError(f"{path} is not among the claimed files "
                                      f"{[str(f) for f in self.plan.files]}; claim it first")
                _publish(bytes(data) if not isinstance(data, bytes) else data, path,
                         self.plan.overwrite)
                done.append(path)
        except BaseException:
            if not self.plan.overwrite:
                for p in done:
                    with contextlib.suppress(OSError):
                        os.unlink(p)
            raise
        return done


def claim_output(plan: OutputPlan, run_id: str | None = None) -> OutputClaim:
    """Claim the files of ``plan`` for this run (use as ``with claim_output(plan) as c``).

    Raises
    ------
    OutputBusyError
        Another process holds one of the files (its pid and run id are named).
    OutputError
        A file appeared since :func:`check_output` and overwriting was not asked for.
    """
    return OutputClaim(plan=plan, run_id=run_id or new_run_id())


def write_atomically(path, data: bytes, *, overwrite: bool = False,
                     formats: dict[str, str] | None = None, what: str = "results") -> Path:
    """Check, claim and write one file in one call.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.toml"
    >>> write_atomically(p, b"x = 1", formats={".toml": "toml"}).read_text()
    'x = 1'
    """
    plan = check_output(path, formats=formats, overwrite=overwrite, what=what)
    with claim_output(plan) as claim:
        claim.write({plan.path: data})
    return plan.path


def _acquire(lock_path: Path, info: dict, target: Path) -> int:
    """Lock ``lock_path`` without waiting; the fd that holds it."""
    text = json.dumps(info).encode()
    if fcntl is None:  # pragma: no cover - Windows
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:
            raise OutputBusyError(_busy_message(target, _read_holder(lock_path), lock_path,
                                                stale_possible=True)) from None
        os.write(fd, text)
        return fd
    for _ in range(100):
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0),
                         0o644)
        except OSError as exc:
            raise OutputError(f"cannot write {clip_path(target)}: the folder "
                              f"{clip_path(lock_path.parent)} is not writable "
                              f"({exc.strerror or exc}); choose a folder you can write "
                              f"to") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise OutputBusyError(_busy_message(target, _read_holder(lock_path),
                                                    lock_path)) from None
            raise OutputError(f"cannot lock {lock_path} ({exc.strerror}); choose a folder on "
                              f"a local disk") from None
        # the holder we waited for may have removed the file: lock the one in place
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock_path))
        except FileNotFoundError:
            same = False
        if not same:
            os.close(fd)
            continue
        os.ftruncate(fd, 0)
        os.write(fd, text)
        return fd
    raise OutputBusyError(_busy_message(target, {}, lock_path))  # pragma: no cover


def _release(fd: int, lock_path: Path) -> None:
    with contextlib.suppress(OSError):
        os.unlink(lock_path)  # while still holding it: see _acquire
    with contextlib.suppress(OSError):
        os.close(fd)


def _read_holder(lock_path: Path) -> dict:
    try:
        with open(lock_path, "rb") as fh:
            return json.loads(fh.read(4096) or b"{}")
    except (OSError, ValueError):
        return {}


def _busy_message(target: Path, holder: dict, lock_path: Path,
                  stale_possible: bool = False) -> str:
    who = "another torquesplit run"
    details = []
    if holder.get("pid"):
        details.append(f"pid {holder['pid']}")
    if holder.get("run_id"):
        details.append(f"run {holder['run_id']}")
    if holder.get("since_utc"):
        details.append(f"since {holder['since_utc']}")
    if details:
        who += f" ({', '.join(details)})"
    fix = "wait for it to finish or choose another file"
    if stale_possible:  # pragma: no cover - Windows
        fix += f" (if no run is writing it, delete {lock_path})"
    return f"{clip_path(target)} is being written by {who}; {fix}"


# --------------------------------------------------------------------------- writing
def _remove_stale_temporaries(target: Path) -> None:
    """Named temporaries of ``target`` left by a killed writer (we hold its lock)."""
    prefix = f".{target.name}."
    try:
        names = os.listdir(target.parent)
    except OSError:  # pragma: no cover
        return
    for name in names:
        if name.startswith(prefix) and name.endswith(".tmp"):
            with contextlib.suppress(OSError):
                os.unlink(target.parent / name)


def _temp_name(target: Path) -> Path:
    return target.parent / f".{target.name}.{secrets.token_hex(6)}.tmp"


def _write_all(fd: int, data: bytes) -> None:
    """Write ``data`` to ``fd`` in chunks (a partial write continues)."""
    view = memoryview(data)
    while view:
        n = os.write(fd, view[:_CHUNK])
        view = view[n:]


def _publish(data: bytes, target: Path, overwrite: bool) -> None:
    """Write ``data`` to a temporary in ``target``'s folder, fsync it, put it in place."""
    parent = target.parent
    try:
        dir_fd = os.open(parent, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError as exc:
        raise OutputError(f"cannot open the folder {parent} ({exc.strerror}); choose another "
                          f"folder") from None
    try:
        done = False
        if USE_O_TMPFILE:
            done = _publish_unnamed(data, target, overwrite, dir_fd)
        if not done:
            _publish_named(data, target, overwrite)
        with contextlib.suppress(OSError):  # make the new name itself durable
            os.fsync(dir_fd)
    except FileExistsError:
        raise OutputError(f"{clip_path(target)} was written by another program or run "
                          f"meanwhile; {_OVERWRITE_HINT}") from None
    except OSError as exc:
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"cannot write {clip_path(target)} ({exc.strerror or exc}); "
                          f"free disk space or choose another folder") from None
    finally:
        os.close(dir_fd)


def _publish_unnamed(data: bytes, target: Path, overwrite: bool, dir_fd: int) -> bool:
    """O_TMPFILE: an unnamed file that disappears if the process dies; False if the
    system does not offer it (the caller falls back to a named temporary)."""
    try:
        fd = os.open(target.parent, os.O_TMPFILE | os.O_RDWR, 0o666)
    except OSError as exc:
        if exc.errno in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT):
            return False
        raise
    try:
        _write_all(fd, data)
        os.fsync(fd)
        source = f"/proc/self/fd/{fd}"
        name = target.name if not overwrite else _temp_name(target).name
        try:
            os.link(source, name, dst_dir_fd=dir_fd, follow_symlinks=True)
        except FileExistsError:
            raise
        except OSError as exc:  # no /proc, or linkat refused: fall back
            if exc.errno in (errno.ENOENT, errno.EXDEV, errno.EPERM, errno.EACCES,
                             errno.EINVAL):
                return False
            raise
        if overwrite:
            try:
                os.replace(name, target.name, src_dir_fd=dir_fd, dst_dir_fd=dir_fd)
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(name, dir_fd=dir_fd)
                raise
        return True
    finally:
        os.close(fd)


def _publish_named(data: bytes, target: Path, overwrite: bool) -> None:
    """A hidden ``.NAME.*.tmp`` in the target folder, removed on any error or interrupt;
    one left by SIGKILL is removed by the next claim of NAME."""
    tmp = _temp_name(target)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        try:
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
        if overwrite:
            os.replace(tmp, target)
        else:
            try:
                os.link(tmp, target)  # fails if target exists: never overwrites
            except FileExistsError:
                raise
            except OSError:  # pragma: no cover - a file system without hard links
                if target.exists():
                    raise FileExistsError(str(target)) from None
                os.replace(tmp, target)  # checked under our lock
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


# --------------------------------------------------------------------------- formats
def netcdf_bytes(dataset) -> bytes:
    """A Dataset as NetCDF-4 (h5netcdf) bytes, serialised in memory."""
    buffer = io.BytesIO()
    # coordinates without a _FillValue (xarray gives every float one): a coordinate has
    # no missing values (CF conventions, 2.5.1)
    encoding = {name: {"_FillValue": None} for name in dataset.coords
                if dataset[name].dtype.kind == "f"}
    try:  # (the Dataset is in memory: under a Dask client xarray took a cluster lock named
        # by the buffer, which the cluster does not know; a study's results on Dask)
        import dask

        local = dask.config.set(scheduler="synchronous")
    except ImportError:
        local = contextlib.nullcontext()
    with local:
        dataset.to_netcdf(buffer, engine="h5netcdf", encoding=encoding)
    return buffer.getvalue()


def mat_bytes(data: dict) -> bytes:
    """A dict as MATLAB .mat bytes (scipy.io.savemat), serialised in memory.  A vector is
    a column (N x 1), as a history's time beside its (N x n) forces."""
    from scipy.io import savemat

    buffer = io.BytesIO()
    savemat(buffer, data, long_field_names=True, do_compression=True, oned_as="column")
    return buffer.getvalue()


def csv_bytes(header, rows) -> bytes:
    """A table as UTF-8 CSV bytes; a NaN is an empty cell (spreadsheets read 'nan' as
    text), an infinity 'inf' / '-inf'."""
    import csv
    import math

    def cell(v):
        return "" if isinstance(v, float) and math.isnan(v) else v

    buffer = io.StringIO(newline="")
    writer = csv.writer(buffer)
    writer.writerow(header)
    writer.writerows([cell(v) for v in row] for row in rows)
    return buffer.getvalue().encode("utf-8")
