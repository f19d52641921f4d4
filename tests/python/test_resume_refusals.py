"""`kinesweep run --resume` and `--overwrite` never destroy what lies on disk: the bytes of the
results file and of its journal (SHA-256 before and after) stay as they were when a resume is
refused, and the previous file stays as it was until an overwriting run holds its first commit.

- a 0-byte file with an empty journal, or one cut within its header, beside it: refused, nothing written;
- a version 1 journal (KSJRNL01, no fingerprint) with a committed size below the finished file's: refused;
- the shards <out>.rank<r>.h5 of a distributed run beside the file: a plain resume refuses, naming them;
- --overwrite killed (SIGKILL) before its first commit: the previous file byte-identical, and once
  killed later the file is either the previous one or the new study's with runs done;
- a read-only output folder: reported as such, not as missing free space.

usage: /usr/bin/python3 test_resume_refusals.py KINESWEEP_BINARY
"""
import hashlib
import os
import signal
import struct
import subprocess
import sys
import time
import unittest

import h5py

from e2e_common import TempDirTest

KS = None

# 40 trajectory runs with full histories: a finished file of about a megabyte.
SMALL = """
[study]
name = "small"
histories = "full"
[[block]]
name = "b"
kind = "trajectory"
[block.axes]
k = { from = 0, to = 1, count = 40 }
"""

# Another study for the same output (an overwrite replaces the file of SMALL with this one's).
OTHER = """
[study]
name = "other"
histories = "full"
[[block]]
name = "b"
kind = "trajectory"
[block.axes]
alpha1A = { from = -20, to = 30, step = 0.25 }
k = { from = 0, to = 1, count = 6 }
"""


def run(*args, env=None, timeout=300):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([KS, *args], capture_output=True, text=True, env=e, timeout=timeout)


def digest(path):
    """SHA-256 of a file's bytes, None when it does not exist."""
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except FileNotFoundError:
        return None


class Refusals(TempDirTest):
    def setUp(self):
        super().setUp()
        self.study = self.write("small.toml", SMALL)

    def path(self, name):
        return os.path.join(self.dir, name)

    def finished(self, name):
        out = self.path(name)
        r = run("run", self.study, "-o", out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertFalse(os.path.exists(out + ".journal"))
        return out

    def refused(self, out, expect=None):
        """Runs --resume on `out` and checks the refusal: exit 1, `expect` in the message, the file
        and its journal byte-identical (or still absent)."""
        before = digest(out), digest(out + ".journal")
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        if expect:
            self.assertIn(expect, r.stderr)
        self.assertEqual((digest(out), digest(out + ".journal")), before, r.stderr)
        return r

    def test_zero_byte_file_with_a_journal_holding_nothing(self):
        for i, journal in enumerate((b"", b"KSJRNL02xx", b"KSJRN", b"\0" * 20)):
            with self.subTest(journal=journal):
                out = self.path(f"z{i}.h5")
                open(out, "wb").close()
                with open(out + ".journal", "wb") as f:
                    f.write(journal)
                r = self.refused(out, "not a kinesweep results file")
                self.assertIn("nothing was written", r.stderr)
                self.assertEqual(os.path.getsize(out), 0)

    def test_zero_byte_file_without_a_journal(self):
        out = self.path("z.h5")
        open(out, "wb").close()
        self.refused(out, "not a kinesweep results file")
        self.assertFalse(os.path.exists(out + ".journal"))

    def test_foreign_file_with_an_empty_journal(self):
        out = self.path("foreign.h5")
        with h5py.File(out, "w") as f:  # an HDF5 file, but no results file
            f.attrs["format"] = "something else"
        open(out + ".journal", "wb").close()
        self.refused(out, "not a kinesweep results file")

    def test_version_1_journal_with_a_committed_size(self):
        # FORMAT.md "Crash safety": the 48-byte KSJRNL01 header (device, inode, committed size,
        # sequence, session) of this very file, committing fewer bytes than the finished file has
        for committed in (48, 4096, 65536):
            with self.subTest(committed=committed):
                out = self.finished(f"v1_{committed}.h5")
                st = os.stat(out)
                self.assertGreater(st.st_size, committed)
                with open(out + ".journal", "wb") as f:
                    f.write(b"KSJRNL01" + struct.pack("<QQQQQ", st.st_dev, st.st_ino, committed, 1, 1))
                self.refused(out, "version 1")

    def test_version_1_journal_of_the_file_as_it_is(self):
        out = self.finished("v1_same.h5")
        st = os.stat(out)
        with open(out + ".journal", "wb") as f:
            f.write(b"KSJRNL01" + struct.pack("<QQQQQ", st.st_dev, st.st_ino, st.st_size, 1, 1))
        self.refused(out, "version 1")

    def test_plain_resume_names_the_shards(self):
        out = self.path("m.h5")
        # a shard is a results file of the same study under <out>.rank<r>.h5 (runner/mpi_sweep.hpp):
        # a finished file renamed is one, holding every run
        shard = self.finished("shard.h5")
        os.rename(shard, out + ".rank1.h5")
        shard = out + ".rank1.h5"
        before = digest(shard)
        for resume_args, file_exists in ((["--resume"], False), ([], False), (["--resume"], True)):
            with self.subTest(args=resume_args, file_exists=file_exists):
                if file_exists and not os.path.exists(out):
                    os.rename(self.finished("m2.h5"), out)
                file_before = digest(out)
                r = run("run", self.study, "-o", out, "-q", *resume_args)
                self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
                self.assertIn(shard, r.stderr)
                self.assertIn("mpirun -np 1", r.stderr)
                self.assertEqual((digest(out), digest(shard)), (file_before, before))


class Overwrite(TempDirTest):
    """--overwrite writes the new file aside and renames it over the previous one at its first
    commit of runs."""

    def setUp(self):
        super().setUp()
        self.out = os.path.join(self.dir, "r.h5")
        self.small = self.write("small.toml", SMALL)
        r = run("run", self.small, "-o", self.out, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.previous = digest(self.out)
        self.other = self.write("other.toml", OTHER)

    def start(self, env=None):
        e = dict(os.environ)
        e.update(env or {})
        return subprocess.Popen([KS, "run", self.other, "-o", self.out, "--overwrite", "-q", "--threads", "1"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=e)

    def wait_stopped(self, p):
        """Waits until process p has stopped itself (SIGSTOP at a KS_STORE_TEST_PAUSE step)."""
        for _ in range(6000):
            with open(f"/proc/{p.pid}/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "T":
                    return
            self.assertIsNone(p.poll(), "the process ended before its pause point")
            time.sleep(0.01)
        self.fail("the process never reached its pause point")

    def killed(self, p):
        p.send_signal(signal.SIGKILL)
        p.wait()
        p.stderr.close()

    def test_killed_once_the_new_file_is_open(self):
        # the writer of the new file has opened it and its journal (store step "ready"): the sweep
        # has not committed a run yet
        p = self.start({"KS_STORE_TEST_PAUSE": "ready"})
        self.wait_stopped(p)
        self.assertEqual(digest(self.out), self.previous)
        self.killed(p)
        self.assertEqual(digest(self.out), self.previous)
        r = run("info", self.out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("small", r.stdout)
        # the killed writer's aside file and journal: removed by the next writer of the path
        self.assertNotEqual([n for n in os.listdir(self.dir) if n.startswith(".r.h5.tmp-")], [])
        r = run("run", self.small, "-o", self.out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual([n for n in os.listdir(self.dir) if n.startswith(".r.h5.tmp-")], [])

    def test_killed_at_once(self):
        p = self.start()
        self.killed(p)
        self.assertEqual(digest(self.out), self.previous)

    def test_killed_after_a_delay_leaves_either_file_whole(self):
        for delay in (0.2, 0.6, 1.5, 3.0):
            with self.subTest(delay=delay):
                p = self.start()
                time.sleep(delay)
                self.killed(p)
                if digest(self.out) == self.previous:
                    continue
                # replaced: then by the new study's file holding its first commit of runs
                with h5py.File(self.out, "r") as f:
                    name = f.attrs["study_name"]
                    self.assertEqual(name.decode() if isinstance(name, bytes) else name, "other")
                    self.assertGreater(int(f["runs"]["done"][()].sum()), 0)
                return

    def test_completed_overwrite_replaces_the_file(self):
        r = run("run", self.other, "-o", self.out, "--overwrite", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotEqual(digest(self.out), self.previous)
        self.assertFalse(os.path.exists(self.out + ".journal"))
        self.assertEqual([n for n in os.listdir(self.dir) if n.startswith(".r.h5")], [])
        with h5py.File(self.out, "r") as f:
            self.assertTrue(bool(f["runs"]["done"][()].all()))


class ReadOnlyFolder(TempDirTest):
    def test_permission_not_free_space(self):
        study = self.write("small.toml", SMALL)
        # /proc is a folder no one creates files in, whatever the user (root included)
        for out in ("/proc/kinesweep_results.h5", "/proc/self/kinesweep_results.h5"):
            with self.subTest(out=out):
                r = run("run", study, "-o", out, "-q")
                self.assertNotEqual(r.returncode, 0)
                self.assertNotIn("free space", r.stderr)
                self.assertIn("cannot create a file in directory", r.stderr)
        if os.geteuid() != 0:  # root writes in any folder of a writable file system
            ro = os.path.join(self.dir, "ro")
            os.mkdir(ro, 0o555)
            r = run("run", study, "-o", os.path.join(ro, "r.h5"), "-q")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("Permission denied", r.stderr)
            self.assertNotIn("free space", r.stderr)


if __name__ == "__main__":
    KS = sys.argv.pop(1)
    unittest.main()
