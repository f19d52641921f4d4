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
    t = r.runs(columns=list(dict.fromkeys(needed)), where=where)
    ids = np.asarray(t["run_id"], dtype=np.int64)
    row_kind = r.row_kinds(done_only=False)[ids]
    group_text = np.array([_group_text(x) for x in t[by]], dtype=object)
    best = {}
    for i in range(len(ids)):
        kind = row_kind[i]
        if kind not in wanted:
            continue
        if t["status"][i] not in r.kind_meaning(kind).get("good_statuses", []):
            continue
        e = ""
        if kind == "trajectory":
            e = end_condition(t["method"][i] if "method" in t else "", t["spline"][i] if "spline" in t else "",
                              t["end_state"][i] if "end_state" in t else "", t["end"][i] if "end" in t else "")
        if end not in (None, "any") and e != end:
            continue
        if end == "any":
            e = "any"
        for m in wanted[kind]:
            v = float(t[m][i])
            if not math.isfinite(v) or (t[m].dtype.kind in "iu" and v == -1):  # the missing value
                continue
            key, g = (kind, e, m), group_text[i]
            cur = best.setdefault(key, {}).get(g)
            if cur is None or v < cur[0] or (v == cur[0] and ids[i] < cur[1]):
                best[key][g] = (v, int(ids[i]))
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
