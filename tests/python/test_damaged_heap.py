"""Readers refuse a results file whose global heap (HDF5's store of variable-length strings) is damaged,
with exit 1 and a message naming the damage, where HDF5 1.10 alone crashes or reads a wrong string.
The damage is made here, from the HDF5 file format specification ("Global Heap", "Variable-length
data"), on a copy of the committed format 3 file (its /runs text columns are contiguous datasets of
variable-length strings): an object's size past its collection, a string's heap index and its length.

usage: /usr/bin/python3 test_damaged_heap.py KINESWEEP_BINARY FORMAT3_FILE
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest

import h5py

KS = None
SOURCE_FILE = None


def element_reference(path, dataset, i):
    """(file offset of element i's reference, its length, collection address, object index)."""
    with h5py.File(path, "r") as f:
        offset = f[dataset].id.get_offset()
    with open(path, "rb") as fh:
        fh.seek(offset + 16 * i)
        length, heap, index = struct.unpack("<IQI", fh.read(16))
    return offset + 16 * i, length, heap, index


def object_header(path, heap, index):
    """File offset of the header of object `index` in the collection at `heap`."""
    with open(path, "rb") as fh:
        fh.seek(heap)
        head = fh.read(16)
        assert head[:4] == b"GCOL", head
        size = struct.unpack("<Q", head[8:16])[0]
        fh.seek(heap)
        data = fh.read(size)
    p = 16
    while p + 16 <= size:
        idx, _, _, n = struct.unpack("<HHIQ", data[p:p + 16])
        if idx == index:
            return heap + p
        if idx == 0:
            break
        p += 16 + (n + 7) // 8 * 8
    raise AssertionError(f"object {index} not in the collection at {heap}")


def patch(path, offset, data):
    with open(path, "r+b") as fh:
        fh.seek(offset)
        fh.write(data)


class DamagedHeap(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.path = os.path.join(self.dir, "damaged.h5")
        shutil.copy(SOURCE_FILE, self.path)
        self.ref, self.length, self.heap, self.index = element_reference(self.path, "runs/block", 0)

    def tearDown(self):
        shutil.rmtree(self.dir)

    def query(self):
        return subprocess.run([KS, "query", self.path, "--columns", "block", "--limit", "2"],
                              capture_output=True, text=True, timeout=60)

    def test_intact_file_reads(self):
        r = self.query()
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("cases", r.stdout)

    def test_object_size_past_its_collection(self):
        at = object_header(self.path, self.heap, self.index)
        patch(self.path, at + 8, struct.pack("<Q", self.length + (1 << 40)))
        r = self.query()
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("read /runs/block: ", r.stderr)
        self.assertIn("global heap", r.stderr)
        self.assertIn("(a damaged file)", r.stderr)

    def test_reference_to_a_missing_object(self):
        patch(self.path, self.ref + 12, struct.pack("<I", self.index + 4000))
        r = self.query()
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("read /runs/block: the string of element 0 points to no object", r.stderr)

    def test_reference_with_another_length(self):
        patch(self.path, self.ref, struct.pack("<I", self.length + 1))
        r = self.query()
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("read /runs/block: the string of element 0 points to no object of its length", r.stderr)


if __name__ == "__main__":
    KS, SOURCE_FILE = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1], verbosity=2)
