"""End-to-end tests of kinesweep.report: run the engine on small studies (a trajectory landscape
with full histories, an IK basins grid, a study with an [[optimize]] block), write the reports and
check them: the sections present, the tables' numbers against h5py's reading of the file, no network
references, a file a sweep is still writing, the size caps, and in headless Chromium (skipped when
it is not installed): no JavaScript errors, every figure drawn, each section's screenshot not blank.

usage: /usr/bin/python3 test_report.py KINESWEEP_BINARY REPO_ROOT
"""
import base64
import gzip
import html
import json
import re
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from html.parser import HTMLParser

import h5py
import numpy as np

from e2e_common import ANALYSIS_ENV, OPTIMIZE, Histories, analysis_command, is_text, run_study_text, runs_column
from kinesweep import read as ksread  # noqa: E402 (e2e_common puts analysis/ on the path)

KS = None
ROOT = None
D = 180.0 / math.pi
# plotly.js minified by esbuild (installed by .ci/setup) and compressed, with the figures' data
MAX_PAGE_BYTES = 4_000_000 if shutil.which("esbuild") else 20 * 1024 * 1024

# Two methods x 5 x 3 cells, full histories; alpha1A = -30 deg is unreachable (failed cells).
TRAJECTORY = """
[study]
name = "report_trajectory"
histories = "full"
[robot]
inertia = "thesis_m11"
[[block]]
name = "local"
kind = "trajectory"
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { from = -30, to = 10, step = 10 }
k = { from = 0, to = 1, step = 0.5 }
[[block]]
name = "presets"
kind = "trajectory"
[block.axes]
preset = ["1a", "1h", "2g"]
"""

BASINS = """
[study]
name = "report_basins"
histories = "full"
[[block]]
name = "basins"
kind = "ik"
problem = "scara"
lambda = 0.1
[block.axes]
method = ["newton", "lm", "halley"]
q0_1 = { from = -180, to = 180, count = 11 }
q0_2 = { from = -180, to = 180, count = 9 }
"""

# A Latin hypercube of (alpha1A, k) for both local methods (alpha1A below -20 deg is unreachable: failed
# runs) and a Saltelli design of (alpha1A, k, K_N): blocks of sampled points, no grid.
SAMPLED = """
[study]
name = "report_sampled"
histories = "none"
[robot]
inertia = "thesis_m11"
[[block]]
name = "lhs"
kind = "trajectory"
lhs = { count = 30, seed = 11 }
[block.axes]
method = ["local_weighted", "local_unweighted"]
alpha1A = { lhs = { from = -30, to = 35 } }
k = { lhs = { from = 0, to = 1 } }
[[block]]
name = "design"
kind = "trajectory"
method = "local_weighted"
saltelli = { count = 64, seed = 1 }
[block.axes]
alpha1A = { saltelli = { from = -20, to = 30 } }
k = { saltelli = { from = 0, to = 0.2 } }
K_N = { saltelli = { from = 5, to = 40 } }
"""

SECTIONS = {"trajectory": ["study", "status", "best", "verdicts", "landscapes", "histories"],
            "basins": ["study", "status", "best", "landscapes", "basins", "importance", "histories"],
            "optimize": ["study", "status", "best", "verdicts", "landscapes", "optimizations"],
            "sampled": ["study", "status", "best", "verdicts", "landscapes", "samples", "sensitivity", "importance"]}
GOOD = {"trajectory": ("ok", ["E"]), "ik": ("converged", ["iterations", "error"])}


def s(v):
    return v.decode() if isinstance(v, bytes) else str(v)


class Page(HTMLParser):
    """The parts of a report the tests read: sections, contents links, tables (cells' data-v),
    metadata cells, script/link sources, figure placeholders and data islands."""

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.sections, self.toc, self.tables, self.meta, self.sources = [], [], {}, {}, []
        self.plots, self.islands = [], {}
        self._table = self._row = self._cell = self._key = self._island = None
        self._pre = None
        self.study_text = ""
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.sections.append(a.get("id"))
        elif tag == "a" and a.get("href", "").startswith("#") and not self.sections:
            self.toc.append(a["href"][1:])
        elif tag == "table" and a.get("id"):
            self._table = a["id"]
            self.tables[self._table] = {"columns": [], "rows": []}
        elif tag == "th" and self._table and "data-col" in a:
            self.tables[self._table]["columns"].append(a["data-col"])
        elif tag == "tr" and self._table:
            self._row = []
        elif tag == "td":
            if self._table and self._row is not None and "data-v" in a:
                self._row.append(a["data-v"])
            if "data-key" in a:
                self._key = a["data-key"]
                self.meta[self._key] = ""
        elif tag in ("script", "link", "img", "iframe"):
            for k in ("src", "href"):
                if a.get(k):
                    self.sources.append(a[k])
            if tag == "script" and a.get("type") == "application/gzip":
                self._island = a["id"]
                self.islands[self._island] = ""
        elif tag == "div" and "plot" in a.get("class", "").split():
            self.plots.append(a["id"])
        elif tag == "pre" and a.get("id") == "study-text":
            self._pre = True

    def handle_endtag(self, tag):
        if tag == "table":
            self._table = None
        elif tag == "tr" and self._table and self._row:
            self.tables[self._table]["rows"].append(self._row)
            self._row = None
        elif tag == "td":
            self._key = None
        elif tag == "script":
            if self._island:  # gzip in base64 (the page's loader inflates it in the browser)
                raw = gzip.decompress(base64.b64decode(self.islands[self._island]))
                self.islands[self._island] = raw.decode("utf-8")
            self._island = None
        elif tag == "pre":
            self._pre = None

    def handle_data(self, data):
        if self._key:
            self.meta[self._key] += data
        if self._island:
            self.islands[self._island] += data
        if self._pre:
            self.study_text += data


def chromium_binary():
    for c in ("chromium", "chromium-browser", "google-chrome"):
        p = shutil.which(c)
        if p:
            return p
    return None


def run_chromium(args, url):
    """Headless Chromium as root without a display or HOME: a throw-away profile and HOME."""
    with tempfile.TemporaryDirectory() as home:
        cmd = [chromium_binary(), "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-extensions", "--hide-scrollbars", f"--user-data-dir={home}/profile",
               "--virtual-time-budget=20000", "--enable-logging=stderr", "--v=0", *args, url]
        env = dict(os.environ, HOME=home)
        return subprocess.run(cmd, capture_output=True, text=True, timeout=180, env=env)


class ReportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.h5, cls.html, cls.pages = {}, {}, {}
        for name, text in (("trajectory", TRAJECTORY), ("basins", BASINS), ("optimize", OPTIMIZE),
                           ("sampled", SAMPLED)):
            out = cls.h5[name] = run_study_text(KS, cls.tmp.name, name, text)
            cls.html[name] = cls.report(out)
            with open(cls.html[name], encoding="utf-8") as f:
                cls.pages[name] = Page(f.read())

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @classmethod
    def report(cls, h5, *extra):
        out = os.path.splitext(h5)[0] + "".join(extra).replace("-", "_") + ".html"
        r = subprocess.run(analysis_command("report", h5, "-o", out, *extra), capture_output=True, text=True,
                           env=ANALYSIS_ENV)
        assert r.returncode == 0, r.stderr
        return out

    # --- structure --------------------------------------------------------------------------------
    def test_sections_and_contents(self):
        for name, want in SECTIONS.items():
            p = self.pages[name]
            self.assertEqual(p.sections, want, name)
            self.assertEqual(p.toc, want, name)
            self.assertEqual(len(p.plots), len(set(p.plots)))
            for pid in p.plots:
                self.assertIn(pid + "-data", p.islands)
                spec = json.loads(p.islands[pid + "-data"])
                self.assertTrue(spec["data"], pid)

    def test_fixed_parameters_leave_out_columns_a_block_does_not_have(self):
        # a block of local runs next to a global_spline block: global_spline's columns hold missing
        # values (-1, "") in the local block's rows, which are not parameters of that block
        text = """
[study]
name = "mixed"
histories = "none"
[[block]]
name = "local"
kind = "trajectory"
[[block]]
name = "global"
kind = "trajectory"
method = "global_spline"
knots = 5
max_evaluations = 3
"""
        page = open(self.report(run_study_text(KS, self.tmp.name, "mixed", text)), encoding="utf-8").read()
        captions = re.findall(r"Fixed in this block: ([^<]*)", page)
        self.assertEqual(len(captions), 2, captions)
        local = [c for c in captions if "method = local_weighted" in c]
        self.assertEqual(len(local), 1, captions)
        for name in ("knots", "max_evaluations", "start_seed", "spline", "global_start"):
            self.assertNotIn(name + " =", local[0])
        self.assertTrue(any("knots = 5" in c and "max_evaluations = 3" in c for c in captions), captions)
        self.assertNotIn("opt_tolerance = 1e-10 1", page)  # a dimensionless unit "1" is not written after a value

    def test_no_network_references(self):
        for name, path in self.html.items():
            for src in self.pages[name].sources:
                self.assertFalse(src.lower().startswith(("http:", "https:", "//")), f"{name}: {src}")
            with open(path, encoding="utf-8") as f:
                text = f.read()
            self.assertIn("Plotly.newPlot", text)  # the loader, with plotly's bundle inline (compressed)
            self.assertIn('id="plotly-js"', text)
            self.assertLess(os.path.getsize(path), MAX_PAGE_BYTES)

    def test_metadata_and_study_text(self):
        for name, p in self.pages.items():
            with h5py.File(self.h5[name], "r") as f:
                a = f.attrs
                self.assertEqual(p.meta["engine_version"], s(a["engine_version"]))
                self.assertEqual(p.meta["created"], s(a["created"]))
                self.assertEqual(p.meta["study_sha256"], s(a["study_sha256"]))
                done = f["runs"]["done"][()]
                self.assertEqual(int(p.meta["runs"]), len(done))
                self.assertEqual(int(p.meta["done"]), int(done.sum()))
                self.assertEqual(int(p.meta["histories"]), Histories(f).count())
                self.assertEqual(int(p.meta["optimizations"]),
                                 len(f["optimizations"]) if "optimizations" in f else 0)
                self.assertEqual(p.study_text, s(f["study"]["text"][()]))

    def check_status_table(self, page, h5):
        t = page.tables["status-table"]
        cols = t["columns"]
        with h5py.File(h5, "r") as f:
            block, status = runs_column(f["runs"]["block"]), runs_column(f["runs"]["status"])
            done = f["runs"]["done"][()] == 1
        self.assertEqual([r[0] for r in t["rows"]], list(dict.fromkeys(block.tolist())))
        shown = cols[4:-1]
        self.assertEqual(set(shown), set(status[done].tolist()))
        for row in t["rows"]:
            m = block == row[0]
            self.assertEqual(int(row[2]), int(m.sum()))
            self.assertEqual(int(row[3]), int((m & done).sum()))
            self.assertEqual(int(row[-1]), int((m & ~done).sum()))
            for c, v in zip(shown, row[4:-1]):
                self.assertEqual(int(v), int((m & done & (status == c)).sum()), f"{row[0]} {c}")

    def test_status_counts_equal_h5py(self):
        for name in self.pages:
            self.check_status_table(self.pages[name], self.h5[name])

    def test_verdicts_equal_kinesweep_compare(self):
        # the report's verdict table is the engine's `kinesweep compare` (its JSON), cell for cell
        p = self.pages["trajectory"]
        self.assertIn("verdicts", p.sections)
        t = p.tables["verdict-table"]
        r = subprocess.run([KS, "compare", self.h5["trajectory"], "--format", "json", "--metric", "E", "--metric",
                            "torque_sq_integral"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        want = json.loads(r.stdout)["rows"]
        self.assertEqual(len(t["rows"]), len(want))
        self.assertGreater(len(want), 0)
        for got, row in zip(t["rows"], want):
            for col, cell in zip(t["columns"], got):
                v = row[col]
                if isinstance(v, str):
                    self.assertEqual(cell, v, col)
                elif v is None:
                    self.assertTrue(math.isnan(float(cell)), col)
                else:
                    self.assertEqual(float(cell), float(v), col)

    def test_best_rows_equal_h5py(self):
        for name, p in self.pages.items():
            with h5py.File(self.h5[name], "r") as f:
                g = f["runs"]
                block, status = runs_column(g["block"]), runs_column(g["status"])
                text = {c: runs_column(g[c]) for c in g if is_text(g[c])}
                done = g["done"][()] == 1
                for b in dict.fromkeys(block.tolist()):
                    kind = "ik" if "iterations" in g and np.all(g["iterations"][()][block == b] != -1) else "trajectory"
                    good, keys = GOOD[kind]
                    rows = np.flatnonzero((block == b) & done & (status == good))
                    order = sorted(rows, key=lambda r: tuple(float(g[k][r]) for k in keys) + (r,))[:5]
                    t = p.tables[f"best-{b}"]
                    cols = t["columns"]
                    self.assertEqual([int(r[cols.index("run_id")]) for r in t["rows"]],
                                     [int(g["run_id"][r]) for r in order], f"{name} {b}")
                    for row, r in zip(t["rows"], order):
                        for c, v in zip(cols, row):
                            if c in ("rank", "status") or c not in g:
                                continue
                            if c in text:
                                self.assertEqual(v, text[c][r])
                                continue
                            want = g[c][r]
                            if s(g[c].attrs["unit"]) == "rad":
                                want = want * D
                            if np.isnan(want):
                                self.assertEqual(v, "nan")
                            else:
                                self.assertAlmostEqual(float(v), float(want), delta=1e-12 * max(1.0, abs(want)),
                                                       msg=f"{name} {b} run {r} {c}")
                    # the headers carry the units (angles in degrees)
                    if "alpha1A" in cols:
                        self.assertIn("alpha1A [deg]", self.page_text(name))

    def page_text(self, name):
        with open(self.html[name], encoding="utf-8") as f:
            return f.read()

    def test_landscape_hover_values_equal_h5py(self):
        """The trajectory landscape's first panel (method 0) holds E of the ok cells, rows k, columns alpha1A."""
        spec = json.loads(self.pages["trajectory"].islands["landscape-0-data"])
        heat = [t for t in spec["data"] if t["type"] == "heatmap" and t.get("name") == "E"][0]
        with h5py.File(self.h5["trajectory"], "r") as f:
            g = f["landscapes"]["local"]
            ok = g["status_code"][()][0] == 0
            E = np.where(ok, g["E"][()][0], np.nan).T
            np.testing.assert_allclose(heat["x"], g["alpha1A"][()] * D, rtol=1e-6)
            np.testing.assert_allclose(heat["y"], g["k"][()], rtol=1e-6)
        z = np.array([[np.nan if v is None else v for v in row] for row in heat["z"]], dtype=float)
        if "tickvals" in heat.get("colorbar", {}):  # a log10 colour scale
            z = 10 ** z
        np.testing.assert_allclose(z, E, rtol=1e-5)
        self.assertTrue(np.isnan(E).any(), "the study should have failed cells")
        # one heatmap per failed status, named by it; together they cover the cells without E
        failed = [t for t in spec["data"] if t["type"] == "heatmap" and t.get("name") != "E"
                  and t.get("xaxis", "x") == "x"]  # the first panel's
        self.assertTrue(failed)
        with ksread.open_results(self.h5["trajectory"]) as res:
            statuses = res.landscape("local").statuses
        covered = np.zeros(E.shape, dtype=bool)
        for t in failed:
            self.assertIn(t["name"], statuses[1:])
            fz = np.array([[np.nan if v is None else v for v in row] for row in t["z"]], dtype=float)
            self.assertFalse((covered & np.isfinite(fz)).any())
            covered |= np.isfinite(fz)
        np.testing.assert_array_equal(covered, np.isnan(E))

    # --- files a sweep is writing, caps -----------------------------------------------------------
    def test_partial_file(self):
        """A file with runs not done and no landscapes yet (a sweep still running): done rows only."""
        part = os.path.join(self.tmp.name, "partial.h5")
        shutil.copyfile(self.h5["trajectory"], part)
        with h5py.File(part, "r+") as f:
            done = f["runs"]["done"]
            d = done[()]
            d[1::3] = 0
            done[...] = d
            del f["landscapes"]
            del f["verification"]  # (written when the sweep ends)
        with open(self.report(part), encoding="utf-8") as f:
            p = Page(f.read())
        self.assertEqual(p.sections, ["study", "status", "best", "histories"])
        self.check_status_table(p, part)
        with h5py.File(part, "r") as f:
            self.assertEqual(int(p.meta["not done"]), int((f["runs"]["done"][()] == 0).sum()))
            done = f["runs"]["done"][()] == 1
            shown = [int(r[1]) for r in p.tables["best-local"]["rows"]]
            self.assertTrue(all(done[i] for i in shown))

    def test_grid_cap(self):
        path = self.report(self.h5["basins"], "--max-cells", "100")
        with open(path, encoding="utf-8") as f:
            text = f.read()
        self.assertIn("Capped: every 2nd value", text)
        p = Page(text)
        spec = json.loads(p.islands["basins-0-data"])
        cells = sum(len(t["z"]) * len(t["z"][0]) for t in spec["data"] if t["type"] == "heatmap")
        self.assertLessEqual(cells, 100)
        with h5py.File(self.h5["basins"], "r") as f:
            full = f["landscapes"]["basins"]["status_code"].size
        self.assertLess(cells, full)

    # --- sampled runs and Sobol' indices ---------------------------------------------------------------
    def test_sampled_runs_views_equal_h5py(self):
        """Each sampled block has a slice figure (E against each swept parameter: every done run's
        (run id, value, E) as h5py reads them, good runs and failed runs apart) and parallel
        coordinates (one line per good run, a dimension per parameter and E)."""
        p = self.pages["sampled"]
        with h5py.File(self.h5["sampled"], "r") as f:
            g = f["runs"]
            block, status = runs_column(g["block"]), runs_column(g["status"])
            done = g["done"][()] == 1
            E = g["E"][()]
            order = [c.decode() if isinstance(c, bytes) else c for c in g.attrs["columns"]]
            for i, (b, swept) in enumerate((("lhs", {"method", "alpha1A", "k"}), ("design", {"alpha1A", "k", "K_N"}))):
                params = [c for c in order if c in swept]  # in the file's column order
                values = {c: runs_column(g[c]) if is_text(g[c])
                          else g[c][()] * (D if s(g[c].attrs["unit"]) == "rad" else 1) for c in params}
                rows = np.flatnonzero((block == b) & done)
                good = rows[(status[rows] == "ok") & np.isfinite(E[rows])]
                failed = rows[(status[rows] != "ok") & np.isfinite(E[rows])]
                fig = json.loads(p.islands[f"samples-{i}-data"])
                titles = [fig["layout"]["xaxis" + ("" if j == 0 else str(j + 1))]["title"]["text"].split(" [")[0]
                          for j in range(len(params))]
                self.assertEqual(titles, params, b)
                for j, c in enumerate(params):
                    ax = "x" + ("" if j == 0 else str(j + 1))
                    traces = [t for t in fig["data"] if t["xaxis"] == ax]
                    for t, want in zip(traces, (good, failed)):
                        self.assertEqual(t["customdata"], [int(r) for r in want], f"{b} {c} {t['name']}")
                        for r, x, y in zip(t["customdata"], t["x"], t["y"]):
                            if is_text(g[c]):
                                self.assertEqual(x, values[c][r])
                            else:
                                self.assertAlmostEqual(x, values[c][r], delta=1e-6 * max(1, abs(values[c][r])))
                            self.assertAlmostEqual(y, E[r], delta=1e-6 * abs(E[r]))
                    self.assertEqual(len(traces), 1 + (len(failed) > 0), f"{b} {c}")
                pc = json.loads(p.islands[f"parcoords-{i}-data"])["data"][0]
                self.assertEqual(pc["type"], "parcoords")
                self.assertEqual([d["label"].split(" [")[0] for d in pc["dimensions"]], params + ["E"])
                self.assertEqual(pc["customdata"], [int(r) for r in good])
                for d, c in zip(pc["dimensions"], params + ["E"]):
                    if c == "method":
                        self.assertEqual([d["ticktext"][v] for v in d["values"]], [values[c][r] for r in good])
                    else:
                        want = E[good] if c == "E" else values[c][good]
                        np.testing.assert_allclose(d["values"], want, rtol=1e-6)
        self.assertNotIn("samples-2-data", p.islands)  # no other block is sampled

    def test_sobol_chart_shows_every_index_with_its_number(self):
        """The Sobol' chart: for each of S1 and ST a bar per factor, its number printed above it and a
        marker at its value (small indices stay visible), the numbers those of `kinesweep sensitivity`
        (the engine's own estimator) to the 3 digits printed."""
        r = subprocess.run([KS, "sensitivity", self.h5["sampled"], "--format", "json"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        res = json.loads(r.stdout)["results"][0]
        names = [x["name"] for x in res["factors"]]
        self.assertEqual(names, ["alpha1A", "k", "K_N"])
        fig = json.loads(self.pages["sampled"].islands["sensitivity-0-data"])
        bars = [t for t in fig["data"] if t["type"] == "bar"]
        marks = [t for t in fig["data"] if t["type"] == "scatter"]
        self.assertEqual(len(bars), 2)
        self.assertEqual(len(marks), 2)
        caption = self.page_text("sampled")
        for bar, mark, key in zip(bars, marks, ("first", "total")):
            self.assertEqual(bar["x"], names)
            self.assertEqual(mark["x"], names)
            self.assertEqual(mark["xaxis"], bar["xaxis"])
            numbers = {a["x"]: a for a in fig["layout"]["annotations"] if a.get("xref") == bar["xaxis"]}
            for i, fac in enumerate(res["factors"]):
                v = fac[key]
                self.assertAlmostEqual(float(bar["text"][i]), v, delta=5e-3 * abs(v) + 1e-9, msg=f"{key} {names[i]}")
                shown = numbers[names[i]]  # printed above the bar and its whisker
                self.assertEqual(shown["text"], bar["text"][i])
                self.assertGreaterEqual(shown["y"], bar["y"][i])
                self.assertGreaterEqual(shown["y"], bar["y"][i] + bar["error_y"]["array"][i] - 1e-5)  # 7 digits kept
                self.assertAlmostEqual(mark["y"][i], bar["y"][i], delta=1e-12)
                self.assertIn(bar["text"][i], caption)
            # the value axis shows every bar, whisker and number: from below min(0, lows) to above the highs
            lo, hi = fig["layout"]["yaxis"]["range"]
            self.assertLessEqual(lo, min([0.0] + [fac[key + "_lo"] for fac in res["factors"]]) + 0.01)
            self.assertGreater(hi, max(fac[key + "_hi"] for fac in res["factors"]))

    # --- in a browser -----------------------------------------------------------------------------
    def test_browser(self):
        if chromium_binary() is None:
            self.skipTest("chromium is not installed: the in-browser checks are skipped")
        import matplotlib.image as mpimg
        for name, path in self.html.items():
            url = "file://" + os.path.abspath(path)
            r = run_chromium(["--dump-dom"], url)
            self.assertEqual(r.returncode, 0, r.stderr[-2000:])
            console = [ln for ln in r.stderr.splitlines() if "CONSOLE" in ln]
            bad = [ln for ln in console if "Uncaught" in ln or "rror" in ln]
            self.assertEqual(bad, [], f"{name}: console errors")
            start = r.stdout.find('id="ks-status"')
            self.assertGreater(start, 0, f"{name}: no status element in the DOM")
            body = r.stdout[r.stdout.find(">", start) + 1:r.stdout.find("</pre>", start)]
            self.assertIn('data-ready="1"', r.stdout[start:start + 200], f"{name}: figures not drawn")
            st = json.loads(html.unescape(body))
            self.assertEqual(st["errors"], [], f"{name}: JavaScript errors")
            self.assertEqual(st["plots"], len(self.pages[name].plots), name)
            for sec in self.pages[name].sections:
                png = os.path.join(self.tmp.name, f"{name}_{sec}.png")
                r = run_chromium([f"--screenshot={png}", "--window-size=1200,900"], f"{url}#only={sec}")
                self.assertTrue(os.path.exists(png), f"{name} {sec}: no screenshot ({r.stderr[-500:]})")
                img = mpimg.imread(png)[..., :3]
                ink = np.any(img < 0.9, axis=-1).mean()
                colours = len(np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0))
                self.assertGreater(ink, 0.01, f"{name} {sec}: blank screenshot")
                self.assertGreater(colours, 20, f"{name} {sec}: too few colours")
                if sec not in ("study", "status", "best"):  # figures: coloured pixels (a line at least)
                    vivid = (img.max(axis=-1) - img.min(axis=-1) > 0.25).mean()
                    self.assertGreater(vivid, 0.001, f"{name} {sec}: no figure drawn")


if __name__ == "__main__":
    KS, ROOT = sys.argv[1], sys.argv[2]
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
