"""Pareto fronts of 2 or 3 metrics over a results file's runs, and their hypervolume indicator: the
same fronts as `kinesweep query FILE --pareto M1,M2[:max][,M3]` (and `--hypervolume R1,R2[,R3]`).

    from kinesweep.pareto import pareto_front, hypervolume
    front = pareto_front("results/redundancy_3r.h5", "torque_sq_integral,min_manipulability:max",
                         where="method=local_weighted")
    front["run_id"], front["torque_sq_integral"], front.pareto_metrics, front.pareto_senses
    hypervolume(front, [6000, 0.05])    # the region the front dominates up to the reference point

A run is on the front when it is done, passes `where`, has a good status of its kind (the file's
/kinds: ok, converged), holds a value of every metric (no NaN), and no other such run dominates it
(at least as good in every metric, better in one; equal runs do not dominate each other, so all
copies of a front point are on it). Each metric is minimised unless written METRIC:max. Values as
the query shows them: angles in degrees unless degrees=False. Run with Debian's /usr/bin/python3.
"""
import numpy as np

from kinesweep import where as kswhere

SENSES = ("min", "max")


class ParetoError(ValueError):
    """A bad metric list (unknown or text column, wrong count, bad direction) or reference point."""


def parse_metrics(metrics):
    """[(name, "min" | "max")] from "E,min_manipulability:max", or a list of "NAME[:min|max]" strings
    or (name, sense) pairs. Raises ParetoError for a bad direction, a repeated name or a count other
    than 2 or 3."""
    spec = metrics if isinstance(metrics, str) else ",".join(m if isinstance(m, str) else ":".join(m) for m in metrics)
    out = []
    for part in (p.strip() for p in spec.split(",")):
        name, _, sense = part.rpartition(":") if ":" in part else (part, "", "min")
        name, sense = name.strip(), sense.strip()
        if not name:
            raise ParetoError(f"--pareto '{spec}': an empty metric name; expected M1,M2[,M3], each COL, COL:min or COL:max")
        if sense not in SENSES:
            close = kswhere.did_you_mean(sense, list(SENSES))
            raise ParetoError(f"--pareto '{spec}': '{part}': expected COL, COL:min or COL:max"
                              + (f"; did you mean '{name}:{close}'?" if close else ""))
        if name in [n for n, _ in out]:
            raise ParetoError(f"--pareto '{spec}': {name} is named twice")
        out.append((name, sense))
    if not 2 <= len(out) <= 3:
        raise ParetoError(f"--pareto '{spec}': {len(out)} metric(s); a front needs 2 or 3 "
                          "(e.g. --pareto E,min_manipulability:max)")
    return out


def _minimised(values, senses):
    v = np.asarray(values, dtype=float).reshape(len(values), len(senses)).copy()
    for k, s in enumerate(senses):
        if s == "max":
            v[:, k] = -v[:, k]
    return v


def front_mask(values, senses, eligible=None):
    """Boolean mask of the non-dominated rows of `values` (n x d, d = 2 or 3) among those with no NaN
    and `eligible` (default all). Sort-based: O(n log n) for 2 metrics; for 3, a lexicographic sort
    and a test of each row against the front so far."""
    senses = list(senses)
    v = _minimised(values, senses)
    n, d = v.shape
    ok = ~np.isnan(v).any(axis=1)
    if eligible is not None:
        ok &= np.asarray(eligible, dtype=bool)
    idx = np.flatnonzero(ok)
    order = idx[np.lexsort(tuple(v[idx, k] for k in reversed(range(d))))]  # first column first
    mask = np.zeros(n, dtype=bool)
    if d == 2:
        best_y, g = np.inf, 0
        while g < len(order):
            end = g
            while end < len(order) and v[order[end], 0] == v[order[g], 0]:
                end += 1
            y0 = v[order[g], 1]
            if y0 < best_y:  # the group's lowest y (and its copies) below every smaller x's
                for j in range(g, end):
                    if v[order[j], 1] == y0:
                        mask[order[j]] = True
                best_y = y0
            g = end
    else:
        kept = np.empty((0, d))
        for i in order:
            p = v[i]
            if len(kept) and np.any(np.all(kept <= p, axis=1) & np.any(kept < p, axis=1)):
                continue
            kept = np.vstack([kept, p])
            mask[i] = True
    return mask


def _area(points, rx, ry):
    total, y_bound = 0.0, ry
    for x, y in sorted(map(tuple, points)):
        if y < y_bound:
            total += (rx - x) * (y_bound - y)
            y_bound = y
    return total


def hypervolume(points, reference, senses=None):
    """The hypervolume indicator of `points` against `reference`: the measure of the union of the
    boxes between each point and the reference point (an area for 2 metrics, a volume for 3, in the
    metrics' units multiplied). `points`: an n x d array, or the Table pareto_front returns (its
    metrics and senses are then used). `senses`: "min"/"max" per metric (default all "min"). Points
    not strictly better than the reference in every metric, and NaN ones, add nothing. Exact: a sweep
    in 2-D, slices along the third metric in 3-D."""
    if hasattr(points, "pareto_metrics"):
        senses = senses or points.pareto_senses
        points = np.column_stack([np.asarray(points[m], dtype=float) for m in points.pareto_metrics]) \
            if len(points) else np.empty((0, len(points.pareto_metrics)))
    ref = np.asarray(reference, dtype=float)
    d = len(ref)
    senses = list(senses) if senses is not None else ["min"] * d
    if d not in (2, 3) or len(senses) != d:
        raise ParetoError(f"hypervolume: 2 or 3 metrics with one reference value and sense each, not {d}")
    if np.isnan(ref).any():
        raise ParetoError("hypervolume: the reference point holds NaN")
    v = _minimised(np.asarray(points, dtype=float).reshape(-1, d), senses)
    r = _minimised(ref.reshape(1, d), senses)[0]
    v = v[~np.isnan(v).any(axis=1) & np.all(v < r, axis=1)]
    if d == 2:
        return _area(v, r[0], r[1])
    v = v[np.argsort(v[:, 2], kind="stable")]
    total = 0.0
    for i in range(len(v)):
        top = v[i + 1, 2] if i + 1 < len(v) else r[2]
        if top > v[i, 2]:
            total += _area(v[:i + 1, :2], r[0], r[1]) * (top - v[i, 2])
    return total


def _open(results):
    if isinstance(results, str):
        from kinesweep.read import open_results
        return open_results(results)
    return results


def metric_values(runs, names):
    """The columns `names` of `runs` as an n x len(names) float array; an integer column's missing
    value (-1) as NaN."""
    cols = []
    for n in names:
        v = np.asarray(runs[n])
        f = v.astype(float)
        if v.dtype.kind in "iu":
            f[v == -1] = np.nan
        cols.append(f)
    return np.column_stack(cols) if cols and len(cols[0]) else np.empty((0, len(names)))


def front_of_runs(results, metrics, where=None, degrees=True):
    """(runs, rows, good, on_front, metrics): the done runs (kinesweep Table), the mask of those passing
    `where`, the mask of those with a good status of their kind, the mask of those on the front, and
    the parsed metrics.
    Raises ParetoError (kinesweep.where.WhereError for a bad `where`)."""
    res = _open(results)
    parsed = parse_metrics(metrics)
    runs = res.runs(degrees=degrees)
    columns = list(runs.keys())
    spec = metrics if isinstance(metrics, str) else ",".join(f"{n}:{s}" for n, s in parsed)
    for name, _ in parsed:
        if name not in columns:
            raise ParetoError(kswhere.unknown_column_message(name, columns, f" in --pareto '{spec}'"))
        if np.asarray(runs[name]).dtype.kind in "OSU":
            raise ParetoError(f"--pareto '{spec}': column {name} holds text; a front needs numeric columns")
    rows = kswhere.select(runs, [where] if isinstance(where, str) else list(where or []), degrees=degrees)
    kinds = res.row_kinds()
    good_of = {k: set(res.kind_meaning(k).get("good_statuses", [])) for k in set(kinds.tolist())}
    good = np.array([s in good_of.get(k, ()) for s, k in zip(runs["status"], kinds)], dtype=bool)
    values = metric_values(runs, [n for n, _ in parsed])
    on = np.zeros(len(good), dtype=bool)
    sel = np.flatnonzero(rows)
    on[sel] = front_mask(values[sel], [s for _, s in parsed], good[sel])
    return runs, rows, good, on, parsed


def pareto_front(results, metrics, where=None, degrees=True):
    """The runs on the Pareto front of 2 or 3 `metrics` ("E,min_manipulability:max", or a list):
    a kinesweep Table of every /runs column holding the front's rows, ordered as `kinesweep query
    --pareto` prints them (by the first metric, best first, then the next, then run id), with
    .pareto_metrics (names), .pareto_senses ("min"/"max"), .good_runs (the good runs passing `where`
    with a value of every metric), .left_out ({"status": n, "no_value": n}). `results`: a path or
    an open kinesweep.read.Results; `where`: `kinesweep query --where` expressions (str or list)."""
    runs, rows, good, on, parsed = front_of_runs(results, metrics, where, degrees)
    names = [n for n, _ in parsed]
    idx = np.flatnonzero(on)
    keys = [runs["run_id"][idx]] + [(-1 if s == "max" else 1) * np.asarray(runs[n], dtype=float)[idx]
                                    for n, s in reversed(parsed)]
    idx = idx[np.lexsort(keys)]
    out = type(runs)()
    for c in runs.keys():
        out[c] = runs[c][idx]
    for attr in ("units", "descriptions", "display_names", "roles", "kinds"):
        setattr(out, attr, dict(getattr(runs, attr)))
    has_value = ~np.isnan(metric_values(runs, names)).any(axis=1)
    out.pareto_metrics, out.pareto_senses = names, [s for _, s in parsed]
    out.good_runs = int((rows & good & has_value).sum())
    out.left_out = {"status": int((rows & ~good).sum()), "no_value": int((rows & good & ~has_value).sum())}
    return out
