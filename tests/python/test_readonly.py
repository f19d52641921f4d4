"""Read-only commands never change a results file: `kinesweep info`, `kinesweep query` and ksread on
files left by a killed `kinesweep run` (every crash point of a commit, by the store's test hook, and
kill -9 at a few moments), checked by the SHA-256 of the file and of its journal before and after.
A journal that no longer matches its file (h5py appended to it after the crash) is refused by
readers and by --resume, with the file untouched.

usage: /usr/bin/python3 test_readonly.py KINESWEEP_BINARY
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
import numpy as np

from e2e_common import SWEEP, TempDirTest, runs_table, same_tables

KS = None
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(*args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    return subprocess.run([KS, *args], capture_output=True, text=True, env=e)


def digest(path):
    """SHA-256 of a file's bytes, None when it does not exist."""
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except FileNotFoundError:
        return None


def pending_commit(path):
    """FORMAT.md "Crash safety": a journal ending in a complete trailer holds an unapplied commit."""
    try:
        with open(path + ".journal", "rb") as f:
            j = f.read()
    except FileNotFoundError:
        return False
    return len(j) > 56 and j[-32:-24] == b"KSJCMT01"


class ReadOnly(TempDirTest):
    def setUp(self):
        super().setUp()
        self.study = self.write("s.toml", SWEEP)
        ref = os.path.join(self.dir, "ref.h5")
        self.assertEqual(run("run", self.study, "-o", ref, "-q").returncode, 0)
        self.ref = runs_table(ref)

    def read_everything(self, out):
        """info, query and ksread on `out`; returns their exit codes (ksread: 0, or 1 when it raised)."""
        codes = [run("info", out).returncode,
                 run("query", out, "--where", "status=ok", "--limit", "5").returncode]
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        from kinesweep import read as ksread
        try:
            with ksread.open_results(out) as r:
                r.runs()
            codes.append(0)
        except TimeoutError as e:  # a dead writer's commit is not waited for as a live one's
            self.fail(f"ksread waited for the commit of a writer that is gone: {e}")
        except Exception:  # a torn file (a writer killed while applying a commit) may not read with h5py
            codes.append(1)
        return codes

    def check_untouched_then_resume(self, out, what):
        before = digest(out), digest(out + ".journal")
        codes = self.read_everything(out)
        self.assertEqual((digest(out), digest(out + ".journal")), before, f"{what}: a read-only command changed it")
        self.assertEqual(codes[:2], [0, 0], f"{what}: info/query failed")
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertFalse(os.path.exists(out + ".journal"))
        self.assertTrue(same_tables(runs_table(out), self.ref), what)

    def test_every_crash_point_of_a_commit(self):
        n = 0
        for commit in (2, 4):
            for phase in ("journal_half", "journal_done", "apply_half"):
                out = os.path.join(self.dir, f"{phase}{commit}.h5")
                r = run("run", self.study, "-o", out, "-q", env={"KS_STORE_TEST_CRASH": f"{commit}:{phase}"})
                self.assertEqual(r.returncode, 86, r.stderr)
                self.assertEqual(pending_commit(out), phase != "journal_half")
                self.check_untouched_then_resume(out, f"{phase} {commit}")
                n += 1
        print(f"{n} crash points: info, query and ksread changed no byte; --resume completed each")

    def test_kill_9_at_a_few_moments(self):
        for i, delay in enumerate([0.1, 0.3, 0.6]):
            out = os.path.join(self.dir, f"k{i}.h5")
            p = subprocess.Popen([KS, "run", self.study, "-o", out, "-q", "--histories", "full"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(delay)
            p.send_signal(signal.SIGKILL)
            p.wait()
            if os.path.exists(out):
                self.check_untouched_then_resume(out, f"kill after {delay} s")

    def test_a_journal_that_no_longer_matches_is_refused_and_nothing_changes(self):
        out = os.path.join(self.dir, "stale.h5")
        r = run("run", self.study, "-o", out, "-q", env={"KS_STORE_TEST_CRASH": "3:journal_done"})
        self.assertEqual(r.returncode, 86, r.stderr)
        with h5py.File(out, "a") as f:  # another program changes the file after the crash
            f["added"] = np.arange(1000.0)
        before = digest(out), digest(out + ".journal")
        r = run("info", out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("does not match the file", r.stderr)
        self.assertIn(out + ".journal", r.stderr)
        self.assertEqual((digest(out), digest(out + ".journal")), before)
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stderr)  # (run reads the file first: the reader's refusal)
        self.assertIn("does not match", r.stderr)
        self.assertIn("delete the journal", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertEqual((digest(out), digest(out + ".journal")), before)
        print("stale journal:", r.stderr.strip())
        os.remove(out + ".journal")  # the way out the message names: the file as it is now
        self.assertEqual(run("info", out).returncode, 0)
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(same_tables(runs_table(out), self.ref))


class ResumeRefusals(TempDirTest):
    """`run --resume` refuses what is not its own, leaving every byte as it was (exit 1, a message
    naming the file or the journal)."""

    def setUp(self):
        super().setUp()
        self.study = self.write("s.toml", SWEEP)

    def test_a_zero_byte_file_is_refused_untouched(self):
        out = os.path.join(self.dir, "empty.h5")
        open(out, "wb").close()
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("not a kinesweep results file", r.stderr)
        self.assertEqual(os.path.getsize(out), 0)
        self.assertFalse(os.path.exists(out + ".journal"))

    def finished(self, name):
        out = os.path.join(self.dir, name)
        self.assertEqual(run("run", self.study, "-o", out, "-q").returncode, 0)
        self.assertFalse(os.path.exists(out + ".journal"))
        return out

    def refused(self, out, journal_bytes, expect):
        with open(out + ".journal", "wb") as f:
            f.write(journal_bytes)
        before = digest(out), digest(out + ".journal")
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn(out + ".journal", r.stderr)
        self.assertIn(expect, r.stderr)
        self.assertEqual((digest(out), digest(out + ".journal")), before, r.stderr)

    def test_a_journal_committing_zero_bytes_is_refused(self):
        out = self.finished("zero.h5")
        st = os.stat(out)
        # FORMAT.md "Crash safety": a version-1 header (magic, device, inode, committed size,
        # sequence, session) for this very file, claiming 0 committed bytes
        head = b"KSJRNL01" + struct.pack("<QQQQQ", st.st_dev, st.st_ino, 0, 0, 0)
        self.refused(out, head, "committed size of 0 bytes")

    def test_a_journal_of_another_format_is_refused(self):
        out = self.finished("foreign.h5")
        self.refused(out, b"not a journal at all\n" * 8, "not a kinesweep journal")

    def test_a_journal_cut_within_its_header_holds_nothing(self):
        # a writer stopped while writing its header: zeros or the start of the magic
        for i, head in enumerate((b"KSJRN", b"\0" * 20)):
            out = self.finished(f"cut{i}.h5")
            ref = runs_table(out)
            with open(out + ".journal", "wb") as f:
                f.write(head)
            r = run("run", self.study, "-o", out, "--resume", "-q")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(same_tables(runs_table(out), ref))

    def test_an_empty_journal_holds_nothing(self):
        out = self.finished("emptyj.h5")
        ref = runs_table(out)
        open(out + ".journal", "wb").close()
        r = run("run", self.study, "-o", out, "--resume", "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(same_tables(runs_table(out), ref))


if __name__ == "__main__":
    KS = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0], "-v"])
