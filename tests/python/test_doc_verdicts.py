"""The verdict tables of the documentation are `kinesweep compare`'s output: every block of a
markdown file that follows a line

    <!-- kinesweep compare STUDY ARGS... -->

(STUDY: a study of studies/, by name) is, line for line, what `kinesweep compare` prints on that
study's results file (the study run here, with the best runs' grid verification, as `kinesweep run`
does by default) with those arguments.

usage: /usr/bin/python3 test_doc_verdicts.py KINESWEEP_BINARY SOURCE_DIR [--shipped DIR] DOC.md [DOC.md ...]
(--shipped: the shipped studies' results files as regression_hashes.py --workdir DIR left them; a study
found there is resumed from a copy, which only verifies its best runs)
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest

KS = SOURCE = SHIPPED = None
DOCS = []
MARKER = re.compile(r"^<!-- kinesweep compare (\S+)(.*?) -->\s*$")


def verdict_blocks(path):
    """(line number, study, args, block text) of every marked block of a markdown file."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    out = []
    for i, line in enumerate(lines):
        m = MARKER.match(line)
        if not m:
            continue
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        k = j + 1
        while k < len(lines) and not lines[k].startswith("```"):
            k += 1
        if j >= len(lines) or k >= len(lines):
            raise AssertionError(f"{path}:{i + 1}: a marker without a fenced block after it")
        out.append((i + 1, m.group(1), shlex.split(m.group(2)), "\n".join(lines[j + 1:k])))
    return out


class DocVerdicts(unittest.TestCase):
    def test_every_marked_table_is_compare_output(self):
        blocks = [(doc, *b) for doc in DOCS for b in verdict_blocks(doc)]
        self.assertGreater(len(blocks), 0, "no marked verdict table")
        with tempfile.TemporaryDirectory() as d:
            files = {}
            for doc, line, study, args, text in blocks:
                if study not in files:
                    files[study] = os.path.join(d, study + ".h5")
                    toml = os.path.join(SOURCE, "studies", study + ".toml")
                    shipped = os.path.join(SHIPPED or "", study + ".h5")
                    if SHIPPED and os.path.exists(shipped):
                        # the runs as regression_hashes wrote them (no histories, not verified): a
                        # resume computes no run and verifies the best ones, as a whole run does
                        shutil.copyfile(shipped, files[study])
                        cmd = [KS, "run", toml, "-o", files[study], "--resume", "-q", "--threads", "2",
                               "--histories", "none"]
                    else:
                        cmd = [KS, "run", toml, "-o", files[study], "-q", "--threads", "2"]
                    p = subprocess.run(cmd, capture_output=True, text=True)
                    self.assertEqual(p.returncode, 0, p.stderr)
                p = subprocess.run([KS, "compare", files[study], *args], capture_output=True, text=True)
                self.assertEqual(p.returncode, 0, p.stderr)
                with self.subTest(doc=f"{os.path.relpath(doc, SOURCE)}:{line}", study=study):
                    self.assertEqual(text.rstrip("\n").split("\n"), p.stdout.rstrip("\n").split("\n"))


if __name__ == "__main__":
    KS, SOURCE = sys.argv[1], sys.argv[2]
    DOCS = sys.argv[3:]
    if DOCS[:1] == ["--shipped"]:
        SHIPPED, DOCS = DOCS[1], DOCS[2:]
    del sys.argv[1:]
    unittest.main()
