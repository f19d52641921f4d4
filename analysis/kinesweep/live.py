"""Consistent reads of a results file that a sweep may be writing (engine/store/FORMAT.md, "Reading
while a sweep runs"). HDF5 reads metadata lazily, so a read that spans one of the writer's commits
may mix two committed states and raise. A read is one snapshot when the file's *stamp* is the same
before the file was opened and after the read: the journal header while a writer lives (no stamp
while a commit is being applied), else the file's size and modification time. `consistent` makes a
method of an object with `path`, `f` and `_reopen()` retry from a fresh open until that holds.
Run with Debian's interpreter: /usr/bin/python3.
"""
import fcntl
import functools
import os
import time

LIVE_READ_TIMEOUT = 60.0  # seconds a read keeps retrying while commits keep landing under it
_PAUSE = 0.01             # seconds between attempts


def writer_alive(fh):
    """True while a writer holds the journal's lock (FORMAT.md "Crash safety": a writer keeps an
    exclusive flock on its journal for its whole life). A shared lock taken and dropped at once
    tells; any other error counts as alive (the caller then waits, as for a live writer)."""
    try:
        fcntl.flock(fh.fileno(), fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    fcntl.flock(fh.fileno(), fcntl.LOCK_UN)
    return False


def stamp(path):
    """The file's stamp (FORMAT.md): ("journal", header bytes) while `path.journal` exists, ("static",
    size, mtime) without one; None while a commit is being applied (a journal longer than its header
    whose writer lives). A longer journal left by a writer that died mid-commit will not change:
    ("stranded", its bytes' length, its tail) - the file is read as it is (it may be torn until
    `kinesweep run --resume` applies the commit)."""
    try:
        with open(path + ".journal", "rb") as fh:
            head = fh.read(64)
            if (head[:8], len(head)) in ((b"KSJRNL02", 56), (b"KSJRNL01", 48)) or len(head) < 48:
                return ("journal", head)  # (shorter: a journal being created; no lock is asked)
            if writer_alive(fh):
                return None
            fh.seek(0, os.SEEK_END)
            size = fh.tell()
            fh.seek(max(0, size - 64))
            return ("stranded", size, fh.read(64))
    except FileNotFoundError:
        st = os.stat(path)
        return ("static", st.st_size, st.st_mtime_ns)


def settled_stamp(path, deadline):
    """stamp(path), waiting while a commit is being applied (TimeoutError past `deadline`)."""
    while True:
        s = stamp(path)
        if s is not None:
            return s
        if time.monotonic() > deadline:
            raise TimeoutError(f"{path}: a commit of the writer has been in progress for {LIVE_READ_TIMEOUT} s")
        time.sleep(_PAUSE)


def open_snapshot(path, opener):
    """opener() (which opens `path` and reads what it must) at one stamp: returns (its result, stamp).
    An error raised while the stamp moved is retried; one raised at a steady stamp is the file's own."""
    deadline = time.monotonic() + LIVE_READ_TIMEOUT
    while True:
        before = settled_stamp(path, deadline)
        try:
            out = opener()
        except (OSError, KeyError, RuntimeError, ValueError):
            if stamp(path) == before or time.monotonic() > deadline:
                raise
            time.sleep(_PAUSE)
            continue
        if stamp(path) == before:
            return out, before
        if hasattr(out, "close"):
            out.close()
        time.sleep(_PAUSE)


def consistent(method):
    """Method decorator: the outermost call of an object's decorated methods runs as one snapshot.
    When the stamp moved since the object's file was opened (a commit landed), or the read raised
    while it moved, the file is reopened (`_reopen()`, which sets `_stamp`) and the call repeated."""

    @functools.wraps(method)
    def wrapper(self, *args, **kw):
        if getattr(self, "_live_depth", 0) > 0:  # inside another decorated call: that one checks
            return method(self, *args, **kw)
        deadline = time.monotonic() + LIVE_READ_TIMEOUT
        while True:
            self._live_depth = 1
            try:
                out = method(self, *args, **kw)
                failed = None
            except (OSError, KeyError, RuntimeError, ValueError) as e:
                out, failed = None, e
            finally:
                self._live_depth = 0
            now = stamp(self.path)
            if now == self._stamp:
                if failed is not None:
                    raise failed
                return out
            if time.monotonic() > deadline:
                if failed is not None:
                    raise failed
                raise TimeoutError(f"{self.path}: no read of {method.__name__} fitted between two commits "
                                   f"in {LIVE_READ_TIMEOUT} s")
            self._reopen()

    return wrapper
