"""Grids read a block at a time (kinesweep.grid_blocks, kinesweep.basins_scan) against the whole-grid
computations they replace, on random grids and selections: the blocks cover every cell once in C
order; the frames' parts put together are each frame's slice and their drawn cells its every s-th
cell; the smallest (value, row, column) over the parts is np.nanargmin's cell; clusters built a piece at a
time are kinesweep.solutions.cluster_solutions' labels; the median samples hold every row up to their
limit and every t-th beyond. Needs no kinesweep binary.

usage: /usr/bin/python3 test_grid_blocks.py
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ANALYSIS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis")
sys.path.insert(0, ANALYSIS)
from kinesweep.basins_scan import Medians, StreamClusters  # noqa: E402
from kinesweep.grid_blocks import blocks, first_min, flat_start, frame_parts, read_block, take_drawn  # noqa: E402
from kinesweep.kinds import Axis, Landscape  # noqa: E402
from kinesweep.report_grids import Selection  # noqa: E402
from kinesweep.solutions import cluster_solutions  # noqa: E402


def landscape(shape, rng, categorical=()):
    axes = []
    for d, n in enumerate(shape):
        if d in categorical:
            axes.append(Axis(f"c{d}", "", np.arange(n, dtype=float), [f"v{i}" for i in range(n)]))
        else:
            axes.append(Axis(f"a{d}", "deg", np.linspace(-1, 1, n)))
    g = rng.normal(size=shape)
    g[rng.random(shape) < 0.3] = np.nan
    g = np.round(g, 1)  # ties: the first minimum counts
    return Landscape("b", axes, {"E": g}, {"E": ""}, {"E": ""}, "trajectory"), g


class GridBlocks(unittest.TestCase):
    def test_blocks_cover_every_cell_once_in_order(self):
        rng = np.random.default_rng(1)
        for shape in [(7,), (3, 5), (1, 40, 33), (2, 3, 4, 5), (300, 7), (4, 1, 9)]:
            for cells in (1, 6, 50, 1000):
                seen = np.zeros(shape, dtype=int)
                nxt = 0
                for lo, hi in blocks(shape, cells):
                    self.assertEqual(flat_start(lo, shape), nxt)
                    seen[tuple(slice(a, b) for a, b in zip(lo, hi))] += 1
                    nxt += int(np.prod([b - a for a, b in zip(lo, hi)]))
                np.testing.assert_array_equal(seen, 1)
                g = rng.normal(size=shape)
                flat = np.concatenate([read_block(g, lo, hi).ravel() for lo, hi in blocks(shape, cells)])
                np.testing.assert_array_equal(flat, g.ravel())

    def test_frame_parts_and_drawn_cells_are_the_frames_slices(self):
        rng = np.random.default_rng(2)
        for shape, cat in [((3, 17, 11), (0,)), ((9, 13), ()), ((19,), ()), ((5, 7, 2, 3), (2,)),
                           ((6, 30, 4), (2,)), ((2, 3, 13, 13), (0, 1)), ((11, 3, 8), (1,)),
                           ((4, 5, 30, 3), ())]:
            ls, g = landscape(shape, rng, cat)
            finite = np.isfinite(g)
            best = np.unravel_index(np.nanargmin(g), g.shape) if finite.any() else None
            sel = Selection(ls, best)
            for s in (1, 2, 3, 5):
                nx = len(ls.axes[sel.x].values)
                ny = len(ls.axes[sel.y].values) if sel.y is not None else 1
                xi, yi = np.arange(0, nx, s), (np.arange(0, ny, s) if sel.y is not None else np.array([0]))
                for cells in (1, 10, 64, 10 ** 6):
                    full = [np.full((ny, nx), np.nan) for _ in sel.frames]
                    drawn = [np.full((len(yi), len(xi)), np.nan) for _ in sel.frames]
                    mins = [None] * len(sel.frames)
                    for lo, hi in blocks(shape, cells):
                        b = read_block(g, lo, hi)
                        for k, part, y0, x0 in frame_parts(sel, lo, hi, b):
                            full[k][y0:y0 + part.shape[0], x0:x0 + part.shape[1]] = part
                            c, r, cc = take_drawn(part, y0, x0, s)
                            drawn[k][r, cc] = c
                            m = first_min(part, y0, x0)
                            if m is not None:
                                mins[k] = m if mins[k] is None else min(mins[k], m)
                    for k, (_, f) in enumerate(sel.frames):
                        want = sel.slice(g, f)
                        np.testing.assert_array_equal(full[k], want)
                        np.testing.assert_array_equal(drawn[k], want[np.ix_(yi, xi)])
                        if np.isfinite(want).any():
                            i, j = np.unravel_index(np.nanargmin(want), want.shape)
                            self.assertEqual(mins[k], (float(want[i, j]), int(i), int(j)))
                        else:
                            self.assertIsNone(mins[k])

    def test_clusters_a_piece_at_a_time_are_cluster_solutions(self):
        rng = np.random.default_rng(3)
        for n, joints, spread in [(500, 3, 4.0), (2000, 2, 0.01), (300, 1, 7.0), (1000, 4, 0.5)]:
            centres = rng.uniform(-np.pi, np.pi, size=(12, joints))
            q = centres[rng.integers(0, 12, n)] + rng.normal(scale=1e-4, size=(n, joints))
            stray = rng.random(n) < 0.1  # rows near no centre
            q[stray] = rng.uniform(-spread, spread, size=(int(stray.sum()), joints))
            q += 2 * np.pi * rng.integers(-1, 2, size=q.shape)  # the same angles, other turns
            q[rng.random(n) < 0.05] = np.nan
            rev = [j % 2 == 0 for j in range(joints)]
            want = cluster_solutions(q, rev, 1e-3)
            for piece in (1, 7, 100, n):
                cl = StreamClusters(rev, 1e-3)
                got = np.concatenate([cl.label(q[a:a + piece]) for a in range(0, n, piece)])
                np.testing.assert_array_equal(got, want)

    def test_median_samples(self):
        rng = np.random.default_rng(4)
        labels = rng.integers(-1, 4, 50000)
        labels[labels == 3] = rng.integers(-1, 3, int((labels == 3).sum()))
        labels[:1000] = 3  # a small label: all its rows kept
        q = rng.normal(size=(len(labels), 2))
        for piece in (999, 4096, len(labels)):
            m = Medians(limit=4000)
            for a in range(0, len(labels), piece):
                m.add(labels[a:a + piece], q[a:a + piece])
            np.testing.assert_array_equal(m.median(3), np.median(q[labels == 3], axis=0))
            for lab in (0, 1, 2):
                rows = q[labels == lab]
                t = m.step[lab]
                self.assertGreater(t, 1)
                np.testing.assert_array_equal(m.buf[lab], rows[::t])
                self.assertLessEqual(len(m.buf[lab]), 4000)
                self.assertGreater(len(m.buf[lab]), 2000)


KS = None
BIG = """
[study]
name = "big_grid"
histories = "none"
[[block]]
name = "local"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -34, to = 30, count = 83 }
k = { from = 0, to = 1, count = 61 }
[[block]]
name = "basins"
kind = "ik"
problem = "scara"
method = "newton"
[block.axes]
q0_1 = { from = -180, to = 180, count = 71 }
q0_2 = { from = -180, to = 180, count = 64 }
"""


def blocks_of(g, s, reduce):
    """g (rows y x columns x) reduced over blocks of s x s cells (the last ones smaller)."""
    ny, nx = g.shape
    out = np.full((-(-ny // s), -(-nx // s)), np.nan)
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            b = g[i * s:(i + 1) * s, j * s:(j + 1) * s]
            if np.isfinite(b).any():
                out[i, j] = reduce(b)
    return out


@unittest.skipIf(len(sys.argv) < 2 and KS is None, "needs a kinesweep binary")
class AggregatedPlot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        study = os.path.join(cls.tmp.name, "big.toml")
        with open(study, "w") as f:
            f.write(BIG)
        cls.h5 = os.path.join(cls.tmp.name, "big.h5")
        subprocess.run([KS, "run", study, "-o", cls.h5, "-q"], check=True, capture_output=True)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def plot(self, *args):
        env = dict(os.environ, PYTHONPATH=ANALYSIS)
        r = subprocess.run([sys.executable, "-m", "kinesweep.plot_landscape", self.h5, "-o",
                            os.path.join(self.tmp.name, "p.png"), "--print-data", *args],
                           capture_output=True, text=True, env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        return json.loads(r.stdout)

    def test_blocks_of_a_metric_are_their_min(self):
        import h5py
        for size in ("40x40", "800x30", "41x50", "30x30"):
            d = self.plot("--block", "local", "--size", size)
            with h5py.File(self.h5, "r") as f:
                g = f["landscapes/local"]
                E = np.where(g["status_code"][()] == 0, g["E"][()], np.nan).T  # rows k, columns alpha1A
                st = g["status_code"][()].T
            s = -(-max(E.shape) // min(int(v) for v in size.split("x")))
            self.assertGreater(s, 1)
            self.assertEqual(d["drawn"]["block"], [s, s])
            drawn = np.array(d["drawn"]["z"], dtype=float)
            np.testing.assert_array_equal(drawn, blocks_of(E, s, np.nanmin))
            self.assertEqual(np.nanmin(drawn), np.nanmin(E))
            i, j = np.unravel_index(np.nanargmin(E), E.shape)
            self.assertEqual((d["best"]["i"], d["best"]["j"], d["best"]["value"]), (i, j, E[i, j]))
            np.testing.assert_array_equal(np.array(d["z"], dtype=float), E)  # --print-data: the full grid
            masked = np.array([[c or "" for c in row] for row in d["masked_status"]])
            self.assertEqual(int((masked != "").sum()), int((np.isnan(E) & (st > 0)).sum()))

    def test_bands_give_the_grid_read_whole(self):
        """reduce_grid read a few cells at a time (bands of a few rows) gives what one piece gives."""
        import argparse
        from kinesweep import landscape_grid
        from kinesweep.read import open_results
        with open_results(self.h5) as res:
            for block, metric, pixels in (("local", None, 30), ("local", None, 600), ("basins", None, 25),
                                          ("basins", "iterations", 20)):
                ls = res.landscape(block, degrees=True)
                args = argparse.Namespace(metric=metric, fix=[], x=None, y=None, reduce=None)
                whole = landscape_grid.reduce_grid(ls, args, pixels, keep_full=True)
                saved = landscape_grid.BAND_CELLS
                try:
                    landscape_grid.BAND_CELLS = 200
                    bands = landscape_grid.reduce_grid(ls, args, pixels, keep_full=True)
                finally:
                    landscape_grid.BAND_CELLS = saved
                for k in ("z", "cat", "full_z", "full_cat"):
                    np.testing.assert_array_equal(bands[k], whole[k], err_msg=f"{block} {k}")
                for k in ("best", "vmin", "vmax", "pos", "no_run", "count"):
                    self.assertEqual(bands[k], whole[k], f"{block} {k}")
                np.testing.assert_allclose(bands["sum"], whole["sum"], rtol=1e-12)
                for a, b in zip(bands["counts"], whole["counts"]):
                    np.testing.assert_array_equal(np.trim_zeros(a, "b"), np.trim_zeros(b, "b"))

    def test_blocks_of_the_convergence_fraction_are_their_mean(self):
        import h5py
        d = self.plot("--block", "basins", "--size", "30x30")
        with h5py.File(self.h5, "r") as f:
            conv = f["landscapes/basins/converged"][()].astype(float).T
        s = -(-max(conv.shape) // 30)
        drawn = np.array(d["drawn"]["z"], dtype=float)
        np.testing.assert_allclose(drawn, blocks_of(conv, s, np.nanmean), rtol=1e-12)


if __name__ == "__main__":
    if len(sys.argv) > 1:
        KS = os.path.abspath(sys.argv.pop(1))
    unittest.main(argv=[sys.argv[0], "-v"])
