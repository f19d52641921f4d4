#!/usr/bin/python3
"""One self-contained HTML page giving a whole kinesweep results file at a glance.

Sections (those that do not apply are left out; the contents list what is there): the study text
and file metadata, status counts per block, the best runs of each block, interactive landscapes,
IK basins, the runs of sampled blocks (Latin hypercubes, random draws, Saltelli designs) against
each parameter and in parallel coordinates, Sobol' indices of the blocks run as a Saltelli design, the
permutation importance of the other blocks' swept parameters (a random-forest fit; needs
python3-sklearn), the histories of the best runs, and the optimisation traces. Plotly's JavaScript is
embedded (Debian's python3-plotly, minified by esbuild when installed) and, with the figures' data,
gzip-compressed (inflated by the browser), so the page works offline and can be mailed as one file.
Reads files a sweep is still writing (done rows only). Big grids and long traces are subsampled so
that the page stays small (the captions say where).

    python3 -m kinesweep.report results/examples_landscape.h5 -o report.html

With --pareto M1,M2[:max][,M3], a section on the Pareto front of those metrics (kinesweep.pareto;
only when 2 or 3 are asked for and the file has them).

Open a single section with report.html#only=SECTION (study, status, best, verdicts, landscapes, basins,
samples, sensitivity, importance, pareto, histories, optimizations).
"""
import argparse
import datetime
import math
import os
import sys


from kinesweep import read as ksread  # noqa: E402
from kinesweep.report_basins import basins_figure  # noqa: E402
from kinesweep.report_grids import landscape_figure  # noqa: E402
from kinesweep.report_page import esc, figure, page  # noqa: E402
from kinesweep.report_motion import motion_figure  # noqa: E402
from kinesweep.report_pareto import pareto_section  # noqa: E402
from kinesweep.report_samples import sampled_section  # noqa: E402
from kinesweep.report_tables import (RunsView, best_section, metadata_section, status_section,  # noqa: E402
                                     verdicts_section)
from kinesweep.report_traces import best_with_history, history_figure, history_ids, optimization_figure  # noqa: E402

CELL_BUDGET = 40000   # heatmap cells over all landscape and basin figures (about 40 bytes each, compressed)
MAX_HISTORY_FIGURES = 12
MAX_SENSITIVITY_FIGURES = 12
MAX_IMPORTANCE_FIGURES = 12


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.report", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", help="results file (.h5) written by `kinesweep run`")
    p.add_argument("-o", "--output", help="output page (default: FILE's name with _report.html)")
    p.add_argument("--best", type=int, default=5, help="rows per block in the best-runs table (default %(default)s)")
    p.add_argument("--max-cells", type=int, default=CELL_BUDGET,
                   help="heatmap cells drawn over all grid figures (default %(default)s; bigger grids are "
                        "subsampled and the caption says so)")
    p.add_argument("--title", help="page title (default: the study's name)")
    p.add_argument("--importance", action="store_true",
                   help="fit the permutation importance of the swept parameters of each block that sweeps two or more "
                   "(a random forest per block, scikit-learn: a second or more each); without it the importance "
                   "section only names those blocks")
    p.add_argument("--pareto", metavar="M1,M2[,M3]",
                   help="add a section on the Pareto front of these 2 or 3 metrics, each COL, COL:min (default) "
                   "or COL:max (e.g. torque_sq_integral,min_manipulability:max)")
    return p.parse_args(argv)


def plotly_js():
    """Plotly's bundle (Debian's python3-plotly ships it unminified, 8.7 MB), minified by esbuild when
    the machine has it (Debian's package esbuild; 3.8 MB) and kept in the user's cache directory
    ($XDG_CACHE_HOME or ~/.cache, kinesweep/) under the source's hash. Without esbuild the bundle is
    embedded as shipped (the page is then about 1 MB larger) and a note goes to stderr."""
    import hashlib
    import shutil
    import subprocess
    import tempfile
    import plotly.offline
    src = plotly.offline.get_plotlyjs()
    esbuild = shutil.which("esbuild")
    if esbuild is None:
        print("report: esbuild not found: plotly.js embedded unminified (apt-get install esbuild makes the page "
              "about 1 MB smaller)", file=sys.stderr)
        return src
    digest = hashlib.sha256(src.encode("utf-8")).hexdigest()[:16]
    cache = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
                         "kinesweep")
    cached = os.path.join(cache, f"plotly-{digest}.min.js")
    try:
        with open(cached, encoding="utf-8") as f:
            return f.read()
    except OSError:
        pass
    with tempfile.TemporaryDirectory() as tmp:
        raw, out = os.path.join(tmp, "plotly.js"), os.path.join(tmp, "plotly.min.js")
        with open(raw, "w", encoding="utf-8") as f:
            f.write(src)
        r = subprocess.run([esbuild, "--minify", "--log-level=error", raw, f"--outfile={out}"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            print(f"report: esbuild failed ({r.stderr.strip()[:200]}): plotly.js embedded unminified", file=sys.stderr)
            return src
        with open(out, encoding="utf-8") as f:
            text = f.read()
    try:  # the cache is an optimisation: a read-only home only costs the next report a second
        os.makedirs(cache, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=cache, delete=False) as f:
            f.write(text)
        os.replace(f.name, cached)
    except OSError:
        pass
    return text


def _cache_dir():
    return os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
                        "kinesweep")


def plotly_base64(js):
    """`js` gzip-compressed (level 9) in base64, as the page embeds it: kept in the cache directory of
    plotly_js under the hash of `js` (compressing 3.8 MB takes 0.15 s; reading it back, 2 ms)."""
    import hashlib
    import tempfile
    from kinesweep.report_page import gzip_base64
    digest = hashlib.sha256(js.encode("utf-8")).hexdigest()[:16]
    cached = os.path.join(_cache_dir(), f"plotly-{digest}.js.gz.b64")
    try:
        with open(cached, encoding="ascii") as f:
            return f.read()
    except OSError:
        pass
    data = gzip_base64(js, 9)
    try:
        os.makedirs(_cache_dir(), exist_ok=True)
        with tempfile.NamedTemporaryFile("w", encoding="ascii", dir=_cache_dir(), delete=False) as f:
            f.write(data)
        os.replace(f.name, cached)
    except OSError:
        pass
    return data


DEBIAN_PLOTLY = "/usr/share/python3-plotly/plotly.js"  # what python3-plotly's get_plotlyjs() reads


def plotly_page_js():
    """(plotly_js() or None, plotly_base64 of it) for the page, which embeds the base64 only. With
    Debian's bundle, that is read from the cache under the bundle's size and modification time (and
    whether esbuild minifies it), without importing plotly or reading and hashing its 8.7 MB; else,
    or the first time, through plotly_js and plotly_base64 (and then kept under that key)."""
    import hashlib
    import shutil
    import tempfile
    key = None
    try:
        st = os.stat(DEBIAN_PLOTLY)
        key = hashlib.sha256(f"{DEBIAN_PLOTLY} {st.st_size} {st.st_mtime_ns} {shutil.which('esbuild')}"
                             .encode("utf-8")).hexdigest()[:16]
        with open(os.path.join(_cache_dir(), f"plotly-file-{key}.js.gz.b64"), encoding="ascii") as f:
            return None, f.read()
    except OSError:
        pass
    js = plotly_js()
    data = plotly_base64(js)
    if key:
        try:
            with tempfile.NamedTemporaryFile("w", encoding="ascii", dir=_cache_dir(), delete=False) as f:
                f.write(data)
            os.replace(f.name, os.path.join(_cache_dir(), f"plotly-file-{key}.js.gz.b64"))
        except OSError:
            pass
    return js, data


def grid_sections(res, cap_total):
    """The landscapes and basins sections' html ("" when none), and the blocks whose landscape has a
    dimension of sampled points (drawn as points in the sampled-runs section)."""
    names = res.landscapes()
    lss = [res.landscape(b, degrees=True) for b in names]
    sampled = [ls.block for ls in lss if _sampled_note(ls)]
    ik = [ls for ls in lss if ls.kind == "ik"]
    n_fig = len(lss) + len(ik)
    cap = max(min(500, cap_total), cap_total // max(1, n_fig))
    land = "".join(_landscape_html(i, ls, cap) for i, ls in enumerate(lss))
    basins = []
    for i, ls in enumerate(ik):
        if _sampled_note(ls):
            continue
        out = basins_figure(res, ls, cap)
        if out is not None:
            fig, caption, _ = out
            basins.append(figure(f"basins-{i}", fig, caption, title=f"Block {ls.block}"))
    return land, "".join(basins), sampled


def _sampled_note(ls):
    """For a landscape with a dimension of sampled points (not grid lines): why none is drawn."""
    sampled = [a.name for a in ls.axes if a.sampled]
    if not sampled:
        return ""
    return (f"<h3>Block {esc(ls.block)} ({esc(ls.kind)})</h3><p class=\"caption\">No landscape: its dimension "
            f"{esc(', '.join(sampled))} holds sampled points (a Latin hypercube, zipped random draws or a Saltelli "
            "design), "
            "not grid lines: the section on sampled runs draws them as points (as does "
            "python3 -m kinesweep.plot_runs); "
            "a Saltelli design's indices are in the sensitivity section, the other blocks' parameters are ranked in "
            "the importance section.</p>")


def _landscape_html(i, ls, cap):
    note = _sampled_note(ls)
    if note:
        return note
    out = landscape_figure(ls, cap)
    if out is None:  # a block without swept axes: one run, in the tables
        return ""
    fig, caption, _ = out
    return figure(f"landscape-{i}", fig, caption, title=f"Block {ls.block} ({ls.kind})")


def histories_section(view):
    ids = history_ids(view.res)
    if ids is not None and not ids:
        return ""
    parts, n = [], 0
    for b in view.block_names:
        if n >= MAX_HISTORY_FIGURES:
            parts.append(f'<p class="caption capped">Histories of the first {MAX_HISTORY_FIGURES} blocks shown.</p>')
            break
        row = best_with_history(view, b, ids)
        if row is None:
            continue
        out = history_figure(view, row)
        if out is None:
            continue
        parts.append(figure(f"history-{n}", out[0], out[1], title=f"Block {b} ({view.kind(b)})"))
        sweep = motion_figure(view.res, int(row))
        if sweep is not None:
            parts.append(figure(f"motion-{n}", sweep[0], sweep[1], title=f"Block {b}: the arm's motion"))
        n += 1
    return "".join(parts)


def optimizations_section(res):
    parts = []
    for i, name in enumerate(res.optimizations()):
        fig, caption, stages = optimization_figure(res, name)
        parts.append(figure(f"optimization-{i}", fig, caption, title=f"Optimisation {name}")
                     + (f"<p class=\"caption\">Stages of {esc(name)}:</p>{stages}" if stages else ""))
    return "".join(parts)


def sobol_figure(r):
    """Two panels, first-order S1 and total ST: one bar per factor with its bootstrap interval, its
    number printed above it (an annotation over the whisker) and a marker at its value (a bar of a
    small index is a few pixels high; the marker and the number show it all the same). The value axes
    are shared, from min(0, lowest interval end) to above the highest."""
    data, lows, highs, numbers = [], [0.0], [0.0], []
    panels = (("first", "first order S1", "#1f77b4", "x", "y"), ("total", "total ST", "#ff7f0e", "x2", "y2"))
    for key, name, colour, xa, ya in panels:
        v, lo, hi = (list(map(float, r[k])) for k in (key, key + "_lo", key + "_hi"))
        data.append({"type": "bar", "name": name, "x": r["factors"], "y": v, "xaxis": xa, "yaxis": ya,
                     "marker": {"color": colour, "line": {"color": "#1d2330", "width": 1}},
                     "text": [f"{x:.3g}" for x in v], "textposition": "none",
                     "hovertemplate": f"{name} of %{{x}}: %{{y:.4g}}<extra></extra>",
                     "error_y": {"type": "data", "symmetric": False, "color": "#444",
                                 "array": [h - x for h, x in zip(hi, v)],
                                 "arrayminus": [x - lo_ for x, lo_ in zip(v, lo)]}})
        lows += [x for x in lo + v if math.isfinite(x)]
        highs += [x for x in hi + v if math.isfinite(x)]
        # each number just above the top of its bar's whisker (or of the bar), clear of both
        for f, x, h in zip(r["factors"], v, hi):
            numbers.append({"text": f"{x:.3g}", "x": f, "y": max(x, h) if math.isfinite(h) else x, "xref": xa,
                            "yref": ya, "yanchor": "bottom", "yshift": 3, "showarrow": False,
                            "font": {"size": 13, "color": "#1d2330"}})
    for (key, name, colour, xa, ya), bars in zip(panels, list(data)):
        data.append({"type": "scatter", "mode": "markers", "name": name + " (value)", "showlegend": False,
                     "x": r["factors"], "y": bars["y"], "xaxis": xa, "yaxis": ya, "hoverinfo": "skip",
                     "marker": {"symbol": "diamond", "size": 10, "color": colour,
                                "line": {"color": "#1d2330", "width": 1.5}}})
    top = max(highs)
    span = max(top - min(lows), 0.05)
    rng = [min(lows) - 0.04 * span, top + 0.18 * span]
    title = f"Sobol' index of {r['metric']}"
    layout = {"height": 380, "margin": {"t": 40}, "grid": {"rows": 1, "columns": 2, "pattern": "independent"},
              "showlegend": False, "bargap": 0.35,
              "yaxis": {"title": {"text": title}, "range": rng, "zeroline": True, "zerolinecolor": "#1d2330"},
              "yaxis2": {"range": rng, "zeroline": True, "zerolinecolor": "#1d2330", "matches": "y"},
              "annotations": [{"text": f"<b>{name}</b>", "xref": f"{xa} domain", "yref": "paper", "x": 0.5,
                               "y": 1.0, "yanchor": "bottom", "showarrow": False, "font": {"size": 14}}
                              for _, name, _, xa, _ in panels] + numbers}
    return {"data": data, "layout": layout}


def sensitivity_section(res, limit=MAX_SENSITIVITY_FIGURES):
    """One chart per block run as a Saltelli design (and combination of its other axes): each factor's
    first-order and total Sobol' index of the kind's objective, with bootstrap intervals, side by side."""
    parts = []
    results = res.sensitivity()
    for i, r in enumerate(results[:limit]):
        at = ", ".join(f"{k}={v}" for k, v in r["at"].items())
        failed = ", ".join(f"{s} {c}" for s, c in r["failed_runs"].items())
        numbers = "; ".join(f"{esc(f)} S1 {float(a):.3g}, ST {float(b):.3g}"
                            for f, a, b in zip(r["factors"], r["first"], r["total"]))
        caption = (f"{esc(r['metric'])}{' at ' + esc(at) if at else ''}: {r['samples']} of {r['base_samples']} samples "
                   f"used" + (f" ({r['dropped']} left out: a run failed or is not done; {esc(failed)})" if r["dropped"] else "")
                   + f"; indices: {numbers}. Bars and diamonds: Saltelli 2010 (S1) and Jansen (ST) estimators; "
                   "whiskers: 95 % percentile bootstrap intervals. An index is the share of the metric's variance a "
                   "factor explains alone (S1) or with its interactions (ST).")
        parts.append(figure(f"sensitivity-{i}", sobol_figure(r), caption, title=f"Block {r['block']} ({r['kind']})"))
    if len(results) > limit:
        parts.append(f"<p class=\"caption\">{len(results) - limit} more (kinesweep sensitivity FILE lists all).</p>")
    return "".join(parts)


def _good_runs(view, block):
    """How many of the block's done runs have a good status (ok / converged)."""
    good = view.res.kind_meaning(view.kind(block)).get("good_statuses", [])
    codes = [i for i, s in enumerate(view.status_labels) if s in good]
    return int(view.status_counts()[1][view.block_labels.index(block), codes].sum())


def importance_section(res, limit=MAX_IMPORTANCE_FIGURES, fit=True, view=None):
    """One bar chart per block that sweeps two or more parameters and is not a Saltelli design (those
    have Sobol' indices): each swept parameter's permutation importance in a random-forest fit of the
    kind's objective (kinesweep.importance), whiskers ± one std over the permutation repeats. Blocks
    with too few good runs are named with the reason. Needs python3-sklearn: without it, a note.
    fit=False: no fit, a caption naming those of them with enough good runs (counted in `view`, a
    RunsView) and how to rank their parameters."""
    from kinesweep import importance as ksimp
    from kinesweep.sensitivity import designs
    saltelli = set(designs(res.f))
    swept = {b: ksimp.block_parameters(res, b) for b in res.blocks() if b not in saltelli}
    blocks = [b for b, ps in swept.items() if len(ps) >= 2]
    if not blocks:
        return ""
    if not fit:
        blocks = [b for b in blocks if _good_runs(view, b) >= ksimp.MIN_RUNS] if view is not None else blocks
        if not blocks:
            return ""
        names = "; ".join(f"{esc(b)} ({esc(', '.join(swept[b]))})" for b in blocks)
        return (f'<p class="caption" id="importance-not-fitted">Not fitted (a random forest per block, scikit-learn: '
                f"a second or more each): the report's <code>--importance</code> option adds the permutation "
                f"importance of the swept parameters of the blocks with at least {ksimp.MIN_RUNS} good runs: {names}; "
                f"<code>python3 -m kinesweep.importance FILE</code> prints it.</p>")
    try:
        ksimp._sklearn()
    except ImportError as e:
        print(f"report: no importance section: {e}", file=sys.stderr)
        return ""
    parts, notes, n = [], [], 0
    for b in blocks:
        if n >= limit:
            notes.append(f"{len(blocks) - limit} more blocks not fitted (kinesweep.importance FILE fits them all).")
            break
        try:
            r = ksimp.permutation_importance(res, b, params=swept[b])
        except ksimp.ImportanceError as e:
            notes.append(f"Block {esc(b)}: no importance ({esc(e)}).")
            continue
        ps = r["parameters"]
        good = r["trustworthy"]
        bar = {"type": "bar", "name": "permutation importance", "x": [p["name"] for p in ps],
               "y": [p["mean"] for p in ps], "marker": {"color": "#1f77b4" if good else "#9a9a9a"},
               "customdata": [100 * p["fraction"] for p in ps],
               "hovertemplate": "%{x}: %{y:.4g} (share %{customdata:.1f} %)<extra></extra>",
               "error_y": {"type": "data", "symmetric": True, "array": [p["std"] for p in ps]}}
        fig = {"data": [bar], "layout": {"height": 340, "margin": {"t": 20}, "showlegend": False,
                                         "yaxis": {"title": {"text": f"drop of held-out R² of {r['metric']}"}}}}
        excl = ", ".join(f"{esc(s)} {c}" for s, c in r["excluded"].items())
        shares = ", ".join(f"{esc(p['name'])} {100 * p['fraction']:.0f} %" for p in ps)
        ordinal = [p for p, e in r["encoding"].items() if e != "numeric"]
        caption = (f"{esc(r['metric'])}: permutation importance of a random-forest fit (R² = {r['r2']:.3f} on "
                   f"{r['test']} held-out runs), not a variance decomposition. Bars: the mean drop of the held-out "
                   f"R² when a parameter's values are shuffled ({r['model']['n_repeats']} repeats); whiskers: ± one "
                   f"std over the repeats; shares of the positive drops: {shares}. "
                   f"{r['model']['n_estimators']} trees fitted on {r['train']} of the {r['used']} runs with a good "
                   "status" + (f" (a random {r['subsampled']} used)" if r["subsampled"] else "")
                   + (f"; left out by status: {excl}" if excl else "; none left out")
                   + (f"; {esc(', '.join(ordinal))} ordinal-encoded" if ordinal else "") + ".")
        if not good:
            caption += (f" <span class=\"capped\">A poor fit (R² below {ksimp.POOR_R2}): these numbers are not "
                        "trustworthy.</span>")
        parts.append(figure(f"importance-{n}", fig, caption, title=f"Block {b} ({r['kind']})"))
        n += 1
    if not parts:
        return ""
    return "".join(parts) + "".join(f'<p class="caption">{x}</p>' for x in notes)


def build(path, best=5, max_cells=CELL_BUDGET, title=None, pareto=None, importance=False):
    """The page's html for one results file (`pareto`: the metrics of a Pareto section, or None;
    `importance`: fit the importance section's random forests, else name the blocks it would rank)."""
    with ksread.open_results(path) as res:
        view = RunsView(res)
        sections = [("study", "Study and file", metadata_section(res, view)),
                    ("status", "Status counts per block", status_section(view))]
        b = best_section(view, best)
        if b:
            sections.append(("best", "Best runs per block", b))
        verdicts = verdicts_section(res)
        if verdicts:
            sections.append(("verdicts", "Verdicts, like for like", verdicts))
        land, basins, sampled = grid_sections(res, max_cells)
        if land:
            sections.append(("landscapes", "Landscapes", land))
        if basins:
            sections.append(("basins", "IK basins of attraction", basins))
        samples = sampled_section(view, sampled)
        if samples:
            sections.append(("samples", "Sampled runs", samples))
        sens = sensitivity_section(res)
        if sens:
            sections.append(("sensitivity", "Which parameter matters: Sobol' indices", sens))
        imp = importance_section(res, fit=importance, view=view)
        if imp:
            sections.append(("importance", "Which parameter matters: permutation importance", imp))
        front = pareto_section(res, pareto) if pareto and len([m for m in pareto.split(",") if m.strip()]) >= 2 else ""
        if front:
            sections.append(("pareto", "Pareto front", front))
        hist = histories_section(view)
        if hist:
            sections.append(("histories", "Histories of the best runs", hist))
        opt = optimizations_section(res)
        if opt:
            sections.append(("optimizations", "Optimisation traces", opt))
        name = res.meta.get("study_name", "") or os.path.basename(path)
        done, n = int(view.done.sum()), len(view.done)
        now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        sub = (f"{esc(os.path.basename(path))}: {done} of {n} runs done, written by kinesweep "
               f"{esc(res.meta.get('engine_version', '?'))} on {esc(res.meta.get('created', '?'))}; "
               f"report made {now}. Angles in degrees.")
        js, data = plotly_page_js()
        return page(title or f"kinesweep report: {name}", sub, sections, js, data)


def main(argv=None):
    args = parse_args(argv)
    out = args.output or os.path.splitext(args.file)[0] + "_report.html"
    try:
        text = build(args.file, best=args.best, max_cells=args.max_cells, title=args.title, pareto=args.pareto,
                     importance=args.importance)
    except (FileNotFoundError, ksread.FormatVersionError, ValueError) as e:
        raise SystemExit(f"report: {e}")
    d = os.path.dirname(out)
    if d:
        os.makedirs(d, exist_ok=True)
    with open(out, "w", encoding="utf-8") as f:
        f.write(text)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
