"""Comparisons like for like, as `kinesweep compare` makes them: for each group of runs (by method, or
any /runs column), the best run under common conditions (the good status of its kind, as /kinds
records it; the same end condition: at rest or free to move at the last vertex), its grid
convergence index from /verification (the best runs verified against their grid by `kinesweep
run`), and its margin to the next group with the uncertainty of both, per metric.

    from kinesweep.compare import compare, verification
    for row in compare("results/path_global_seed.h5", metrics=["E", "torque_sq_integral"]):
        print(row["end"], row["metric"], row["method"], row["value"], row["gci"], row["verdict"])

The rows are those of `kinesweep compare FILE --format json` (same keys, same order, same values).
Run with Debian's /usr/bin/python3.
"""
import math

import numpy as np

from kinesweep.kinds import _s, enum_labels, text_values

#: The /verification datasets of one value per row (FORMAT.md), and those of one value per grid.
_ROW_FIELDS = ("run", "block", "method", "group", "quantity", "quantity_unit", "refinement", "ratio",
               "status_1", "status_2", "status_3", "convergence", "order", "extrapolated", "gci_fine", "gci_coarse")
_GRID_FIELDS = ("dt", "knots", "value")


def verification(results):
    """The /verification table of an open kinesweep.read.Results (or a path): a list of dicts, one
    per (run, refinement, quantity), with the datasets of FORMAT.md (dt, knots, value: 3 values,
    finest grid first); [] when the file has none."""
    r = _open(results)
    f = r.f
    if "verification" not in f:
        return []
    g = f["verification"]
    cols = {}
    for name in _ROW_FIELDS + _GRID_FIELDS:
        d = g[name]
        cols[name] = text_values(d) if d.dtype.kind in "OSU" else d[()]
    out = []
    for i in range(len(cols["run"])):
        row = {}
        for name in _ROW_FIELDS:
            v = cols[name][i]
            row[name] = int(v) if name == "run" else _s(v) if isinstance(v, (str, bytes)) else float(v)
        for name in _GRID_FIELDS:
            row[name] = [float(x) for x in cols[name][i]]
        out.append(row)
    return out


def end_condition(method, spline, end_state, local_end=""):
    """The end condition of a trajectory run (`kinesweep compare`'s rule, cli/compare_command.hpp):
    rest for vertex_alpha and vertex-quintic splines (a quintic per segment stops the arm at every
    vertex); global_spline's end_state; the local methods' `end` (free unless "rest")."""
    if method == "vertex_alpha":
        return "rest"
    if method == "global_spline" and end_state:
        return "rest" if spline == "vertex_quintic" else end_state
    return "rest" if local_end == "rest" else "free"


def _format_double(v):
    """A number as the CLI's format_double writes it (%.6g; nan, inf)."""
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return "%.6g" % v


def _group_text(x):
    """A group's name as the CLI writes it: text as is, numbers %.6g, the missing value (NaN, -1) ""."""
    if isinstance(x, (str, bytes)):
        return _s(x)
    if isinstance(x, (int, np.integer)):
        return "" if x == -1 else str(int(x))
    return "" if math.isnan(float(x)) else _format_double(float(x))


def _open(results):
    if isinstance(results, str):
        from kinesweep.read import open_results
        return open_results(results)
    return results


def _grid(rows, run, metric):
    """(state, relative GCI) of a run's metric in /verification (see kinesweep compare)."""
    found, gci, worst = False, 0.0, None
    for v in rows:
        if v["run"] != run or v["quantity"] != metric:
            continue
        found = True
        c = v["convergence"]
        if c in ("monotone", "unchanged"):
            gci = max(gci, v["gci_coarse"])
        elif worst is None:
            worst = {"divergent": "diverges", "oscillatory": "oscillates"}.get(c, "not_enough")
    if not found:
        return "none", math.nan
    if worst is not None:
        return worst, math.nan
    return "converged", gci


CHUNK = 1 << 18  # rows read at a time by compare (bounded memory; the result does not depend on it)


def _text_codes(d, v):
    """(codes, labels) of a text column's values `v` read from dataset `d`: enum codes and their labels
    (a code without one, the missing value, decodes to ""), or, for stored strings, the indices of
    their decoded texts in a list."""
    labels = enum_labels(d)
    if labels is not None:
        return v.astype(np.int64), labels + [""] * (256 ** d.dtype.itemsize - len(labels))
    texts, codes = np.unique(text_values(d, v).astype(str), return_inverse=True)
    return codes, list(texts)


def _small_unique(key):
    """(the distinct values, ascending, and each element's index among them) of non-negative int64
    codes: by counting when their range is small, else np.unique."""
    top = int(key.max()) + 1 if len(key) else 1
    if top > 4 * len(key) + 65536:
        u, inv = np.unique(key, return_inverse=True)
        return u, inv.reshape(-1)
    present = np.flatnonzero(np.bincount(key, minlength=top))
    lut = np.zeros(top, dtype=np.int64)
    lut[present] = np.arange(len(present))
    return present, lut[key]


def _best_per_group(r, names, by, wanted, end, where):
    """{(kind, end condition, metric): {group text: (value, run id)}}: the lowest value (then lowest
    run id) of each group among the done rows (meeting `where`) of a good status, read CHUNK rows at
    a time; text is decoded per distinct combination of codes, not per row."""
    g = r.f["runs"]
    done = g["done"][()].astype(bool)
    mask = r._where_rows(where, done, True)
    kinds = r.run_kinds()
    row_kinds = None if len(kinds) == 1 else r.row_kinds(done_only=False)
    good = {k: set(r.kind_meaning(k).get("good_statuses", [])) for k in kinds}
    text = [c for c in ("status", "method", "spline", "end_state", "end") if c in names]
    by_text = enum_labels(g[by]) is not None or g[by].dtype.kind in "OSU"
    best = {}
    for a in range(0, len(mask), CHUNK):
        sel = mask[a:a + CHUNK]
        if not sel.any():
            continue
        ids = g["run_id"][a:a + len(sel)][sel].astype(np.int64)
        kind_names = [kinds[0]] if row_kinds is None else sorted(set(row_kinds[ids].tolist()))
        kind_code = (np.zeros(len(ids), dtype=np.int64) if row_kinds is None
                     else np.searchsorted(np.array(kind_names, dtype=object), row_kinds[ids]).astype(np.int64))
        codes, labels = [kind_code], [kind_names]
        for c in text:
            cc, lab = _text_codes(g[c], g[c][a:a + len(sel)][sel])
            codes.append(cc)
            labels.append(lab)
        key = np.zeros(len(ids), dtype=np.int64)
        sizes = [len(lab) for lab in labels]
        for cc, size in zip(codes, sizes):
            key = key * size + cc
        present, which = _small_unique(key)
        combos = []
        for k in present.tolist():
            combo = []
            for size in reversed(sizes):
                k, c = divmod(k, size)
                combo.append(c)
            combos.append(combo[::-1])
        # Each combination of kind and text codes: its end condition, or None when its rows are left out.
        ends = []
        for combo in combos:
            vals = {c: labels[j + 1][combo[j + 1]] for j, c in enumerate(text)}
            kind = labels[0][combo[0]]
            if kind not in wanted or vals["status"] not in good.get(kind, ()):
                ends.append(None)
                continue
            e = ""
            if kind == "trajectory":
                e = end_condition(vals.get("method", ""), vals.get("spline", ""), vals.get("end_state", ""),
                                  vals.get("end", ""))
            if end not in (None, "any") and e != end:
                ends.append(None)
                continue
            ends.append((kind, "any" if end == "any" else e))
        # The groups: by their text as the CLI writes it (numbers that print alike are one group).
        raw = g[by][a:a + len(sel)][sel]
        if by_text:
            gc, glab = _text_codes(g[by], raw)
            present = _small_unique(gc)[0]
            gtext = {int(c): _s(glab[c]) for c in present}
        else:
            present, gc = np.unique(raw, return_inverse=True)
            gtext = {i: _group_text(x) for i, x in enumerate(present)}
        gnames = sorted(set(gtext.values()))
        gmap = np.zeros(max(gtext) + 1 if gtext else 1, dtype=np.int64)
        for c, tx in gtext.items():
            gmap[c] = gnames.index(tx)
        group = gmap[gc.reshape(-1)]
        for (kind, e) in sorted({x for x in ends if x is not None}):
            rows_ke = np.isin(which, [i for i, x in enumerate(ends) if x == (kind, e)])
            for m in wanted[kind]:
                col = g[m][a:a + len(sel)][sel]
                v = col.astype(float)
                ok = rows_ke & np.isfinite(v)
                if col.dtype.kind in "iu":
                    ok &= col != -1  # the missing value
                if not ok.any():
                    continue
                vi, ii, gi = v[ok], ids[ok], group[ok]
                order = np.lexsort((ii, vi, gi))
                first = order[np.r_[True, gi[order][1:] != gi[order][:-1]]]
                cur = best.setdefault((kind, e, m), {})
                for j in first:
                    name, val, run = gnames[gi[j]], float(vi[j]), int(ii[j])
                    old = cur.get(name)
                    if old is None or val < old[0] or (val == old[0] and run < old[1]):
                        cur[name] = (val, run)
    return best


def compare(results, by="method", metrics=None, end=None, where=None):
    """The verdict table (list of dicts, keys: kind, end, metric, unit, rank, <by>, run, value, grid,
    gci [%], uncertainty, next, margin, margin_uncertainty, verdict) of a results file (path or
    open Results). `metrics`: metric names (default: each kind's ranking objective); `end`: "rest"
    or "free" (only runs that end so), "any" (mixed), None (each end condition on its own); `where`:
    `kinesweep query --where` expressions (str or list; angles in degrees) the rows must all meet."""
    r = _open(results)
    columns = r.columns()
    if by not in columns:
        raise KeyError(f"no /runs column {by!r}; columns: {', '.join(columns)}")
    units = r.units()
    kinds = r.run_kinds()
    wanted = {}
    for kind in kinds:
        numeric = [c for c in r.metrics(kind) if r.f["runs"][c].dtype.kind in "fiu" and enum_labels(r.f["runs"][c]) is None]
        ms = list(metrics) if metrics else r.kind_meaning(kind).get("ranking", [])[:1]
        for m in ms:
            if m in numeric:
                wanted.setdefault(kind, []).append(m)
            elif len(kinds) == 1 or not metrics:
                raise KeyError(f"{m!r} is not a numeric metric of {kind} runs; expected one of {', '.join(numeric)}")
    needed = ["run_id", "status", by] + [c for c in ("method", "spline", "end_state", "end") if c in columns]
    needed += sorted({m for ms in wanted.values() for m in ms})
    best = _best_per_group(r, list(dict.fromkeys(needed)), by, wanted, end, where)
    rows = verification(r)
    out = []
    for key in sorted(best):
        kind, e, m = key
        ranked = sorted(best[key].items(), key=lambda kv: (kv[1][0], kv[1][1]))
        grids = [_grid(rows, run, m) for _, (_, run) in ranked]
        for i, (g, (v, run)) in enumerate(ranked):
            state, gci = grids[i]
            u = gci * abs(v)
            row = {"kind": kind, "end": e, "metric": m, "unit": units.get(m, ""), "rank": i + 1, by: g, "run": run,
                   "value": v, "grid": state, "gci": 100.0 * gci, "uncertainty": u}
            if i + 1 < len(ranked):
                ng, (nv, _) = ranked[i + 1]
                margin = nv - v
                mu = u + grids[i + 1][1] * abs(nv)
                verdict = "unverified" if not math.isfinite(mu) else "ahead" if margin > mu else "within uncertainty"
                row.update({"next": ng, "margin": margin, "margin_uncertainty": mu, "verdict": verdict})
            else:
                row.update({"next": None, "margin": None, "margin_uncertainty": None, "verdict": "last"})
            out.append(row)
    return out
