#!/usr/bin/python3
"""Which swept parameter matters, for a block of any shape: permutation importance of a random forest.

For a block (grid, random, Latin hypercube, ...), a random forest (scikit-learn's
RandomForestRegressor, fixed random_state: the same numbers on every call) is fitted to the metric
over the block's runs with a good status (ok / converged), from the parameters the block sweeps
(those taking more than one value among its runs): numbers as they are (angles in degrees), text
parameters (method, ...) ordinal-encoded, one column each (codes in sorted order of the values), so
that permuting a column permutes the whole parameter. The runs are split at random into a training
part and a held-out part (a quarter); a parameter's importance is the mean drop of the fit's R² on
the held-out runs when that parameter's column is shuffled (sklearn.inspection.permutation_importance,
10 repeats; std over the repeats). Fractions: each mean importance (negative ones as 0) over their
sum. Runs excluded by status (or without a value of the metric or of a parameter) are counted by
status in the output; a block with more good runs than max_rows is subsampled at random (said too).

This is not a variance decomposition (Saltelli designs have Sobol' indices: kinesweep.sensitivity):
it says how much the forest's held-out predictions rely on each parameter, which is only as good as
the fit. The held-out R² is printed with the numbers; below 0.5 the output says the fit is poor
and the importances are not to be trusted. Correlated parameters share importance unpredictably.

    /usr/bin/python3 -m kinesweep.importance results/examples_lhs.h5 --block local_lhs
    python3 -m kinesweep.importance results/examples_lhs.h5 --metric tau_inf --format json

    from kinesweep.read import open_results
    r = open_results("results/examples_lhs.h5").importance(block="local_lhs")
    r["r2"], [(p["name"], p["mean"], p["std"], p["fraction"]) for p in r["parameters"]]

Needs Debian's python3-sklearn (imported when a fit is asked for; the rest of the package does not
need it). Run with /usr/bin/python3.
"""
import argparse
import json
import sys

import numpy as np

POOR_R2 = 0.5       # held-out R² below this: the output says the importances are not trustworthy
MIN_RUNS = 40       # good runs needed for a fit (a quarter of them, at least 10, held out)
N_ESTIMATORS = 100
N_REPEATS = 10
TEST_FRACTION = 0.25
MAX_ROWS = 5000     # good runs used at most (a random subsample beyond that, fixed seed)
SEED = 0


class ImportanceError(ValueError):
    """No importance can be computed (too few good runs, no swept parameter, a constant metric)."""


def _sklearn():
    try:
        from sklearn.ensemble import RandomForestRegressor
        from sklearn.inspection import permutation_importance as sk_permutation_importance
        from sklearn.model_selection import train_test_split
    except ImportError as e:
        raise ImportError("kinesweep.importance needs scikit-learn: apt-get install python3-sklearn "
                          f"(and run with Debian's /usr/bin/python3); {e}") from e
    return RandomForestRegressor, sk_permutation_importance, train_test_split


def _column(table, name):
    v = table[name]
    return v.to_numpy() if hasattr(v, "to_numpy") else np.asarray(v)


def fit_importance(table, params, metric, status=None, good=("ok", "converged"), n_estimators=N_ESTIMATORS,
                   n_repeats=N_REPEATS, test_fraction=TEST_FRACTION, max_rows=MAX_ROWS, random_state=SEED,
                   min_runs=MIN_RUNS):
    """Permutation importance of `params` for `metric` over the rows of `table` (a mapping of column
    name -> 1-D array, a runs() Table or a pandas DataFrame). `status`: a column name or an array of
    each row's status (rows whose status is not in `good` are left out and counted), None: every row
    is good. Returns a dict: metric, rows, used, excluded ({status: count}; "no value of M" for rows
    without a finite metric or parameter), subsampled, train, test, r2 (held-out), r2_train,
    trustworthy (r2 >= POOR_R2), note, encoding ({param: "numeric" | "ordinal: a=0, b=1, ..."}),
    model (its settings) and parameters: one dict per parameter, most important first: name, mean,
    std (over the permutation repeats), fraction, fraction_std."""
    _sklearn()
    params = list(params)
    if not params:
        raise ImportanceError("no parameter to rank (the block sweeps none)")
    y_all = _column(table, metric).astype(float)
    n = len(y_all)
    if status is None:
        st = np.full(n, good[0], dtype=object)
    else:
        st = np.asarray(_column(table, status) if isinstance(status, str) else status, dtype=object)
    keep = np.isin(st, list(good))
    excluded = {}
    for s in sorted(set(st[~keep].tolist())):
        excluded[str(s)] = int(np.sum(st[~keep] == s))
    columns, encoding = [], {}
    for p in params:
        v = _column(table, p)
        if v.dtype.kind in "fiub":
            columns.append(v.astype(float))
            encoding[p] = "numeric"
        else:
            v = np.asarray([str(x) for x in v], dtype=object)
            values = sorted(set(v[keep].tolist()))
            code = {x: i for i, x in enumerate(values)}
            columns.append(np.array([code.get(x, np.nan) for x in v], dtype=float))
            encoding[p] = "ordinal: " + ", ".join(f"{x}={i}" for x, i in code.items())
    x_all = np.column_stack(columns) if columns else np.empty((n, 0))
    finite = np.isfinite(y_all) & np.all(np.isfinite(x_all), axis=1)
    missing = int(np.sum(keep & ~finite))
    if missing:
        excluded[f"no value of {metric} or a parameter"] = missing
    keep &= finite
    idx = _subsample(np.flatnonzero(keep), max_rows, random_state)
    out = _summary(metric, n, int(np.sum(keep)), excluded, idx, encoding, n_estimators, random_state,
                   test_fraction, n_repeats)
    return _fit(out, x_all[idx], y_all[idx], params, metric, n_estimators, n_repeats, test_fraction, random_state,
                min_runs)


def _subsample(idx, max_rows, random_state):
    """The rows used: all of `idx`, or a random max_rows of them (ascending; fixed seed)."""
    if len(idx) > max_rows:
        return np.sort(np.random.default_rng(random_state).choice(idx, max_rows, replace=False))
    return idx


def _summary(metric, n, used, excluded, idx, encoding, n_estimators, random_state, test_fraction, n_repeats):
    return {"metric": metric, "rows": int(n), "used": int(used), "excluded": excluded,
            "subsampled": int(len(idx)) if used > len(idx) else None, "encoding": encoding,
            "model": {"estimator": "RandomForestRegressor", "n_estimators": n_estimators,
                      "random_state": random_state, "test_fraction": test_fraction, "n_repeats": n_repeats,
                      "scoring": "R²"}}


def _fit(out, x, y, params, metric, n_estimators, n_repeats, test_fraction, random_state, min_runs):
    """The forest and the permutation importances of the rows chosen (x, y), added to `out`."""
    RandomForestRegressor, sk_permutation_importance, train_test_split = _sklearn()
    used = out["used"]
    if used < min_runs:
        raise ImportanceError(f"{used} runs with a good status and a value of {metric}; a fit needs at least "
                              f"{min_runs}")
    if np.ptp(y) == 0:
        raise ImportanceError(f"{metric} takes one value ({y[0]:g}) over the {len(y)} good runs: nothing to explain")
    x_tr, x_te, y_tr, y_te = train_test_split(x, y, test_size=test_fraction, random_state=random_state)
    rf = RandomForestRegressor(n_estimators=n_estimators, random_state=random_state, n_jobs=1)
    rf.fit(x_tr, y_tr)
    r2, r2_train = float(rf.score(x_te, y_te)), float(rf.score(x_tr, y_tr))
    pi = sk_permutation_importance(rf, x_te, y_te, n_repeats=n_repeats, random_state=random_state, n_jobs=1)
    mean, std = pi.importances_mean, pi.importances_std
    total = float(np.sum(np.clip(mean, 0, None)))
    rows = []
    for j, p in enumerate(params):
        rows.append({"name": p, "mean": float(mean[j]), "std": float(std[j]),
                     "fraction": float(max(mean[j], 0) / total) if total > 0 else float("nan"),
                     "fraction_std": float(std[j] / total) if total > 0 else float("nan")})
    rows.sort(key=lambda r: -r["mean"])
    trustworthy = bool(r2 >= POOR_R2)
    note = (f"held-out R² = {r2:.3f}: " + ("the forest predicts the metric well enough to rank the parameters"
                                           if trustworthy else
                                           f"a poor fit (below {POOR_R2}): these importances are NOT trustworthy "
                                           "(the metric is noisy, heavy-tailed or depends on something not swept)"))
    out.update(train=int(len(y_tr)), test=int(len(y_te)), r2=r2, r2_train=r2_train, trustworthy=trustworthy,
               note=note, parameters=rows)
    return out


CHUNK = 1 << 20  # rows read at a time from a file (bounded memory; the numbers do not depend on it)


def _chunks(d, sel):
    """(start, values of the selected rows) of dataset `d` over the rows where the bool array `sel`
    holds, CHUNK rows read at a time."""
    for a in range(0, len(sel), CHUNK):
        s = sel[a:a + CHUNK]
        if s.any():
            yield a, d[a:a + len(s)][s]


def _take(d, rows):
    """The values of dataset `d` at ascending row indices `rows`, CHUNK rows read at a time."""
    parts = []
    for a in range(0, int(rows[-1]) + 1 if len(rows) else 0, CHUNK):
        lo, hi = np.searchsorted(rows, [a, a + CHUNK])
        if hi > lo:
            parts.append(d[a:min(a + CHUNK, len(d))][rows[lo:hi] - a])
    return np.concatenate(parts) if parts else d[0:0]


def _varies_in(d, sel):
    """Whether dataset `d` takes more than one value over the rows `sel` (NaN is no value; a labelled
    text column compares its codes), read CHUNK rows at a time."""
    from kinesweep.chunks import one_value
    from kinesweep.kinds import enum_labels
    if one_value(d):  # one value in every row of the file: in the rows `sel` too
        return False
    if enum_labels(d) is None and d.dtype.kind not in "fiub":
        return _varies(text_values_of(d)[sel])
    seen = None
    for _, v in _chunks(d, sel):
        if v.dtype.kind == "f":
            v = v[~np.isnan(v)]
        if not len(v):
            continue
        lo, hi = v.min(), v.max()
        if lo != hi or (seen is not None and seen != lo):
            return True
        seen = lo
    return False


def text_values_of(d):
    from kinesweep.kinds import text_values
    return text_values(d)


def _varies(v):
    """Whether a column takes more than one value (NaN, a parameter not applying, is no value)."""
    if v.dtype == object:
        return len(set(v.tolist())) > 1
    if v.dtype.kind == "f":
        v = v[~np.isnan(v)]
    return len(np.unique(v)) > 1


def _block_mask(res, block):
    """Which rows of /runs are `block`'s (bool, all rows, done or not): the block column's codes
    compared, not its decoded text."""
    from kinesweep.kinds import enum_labels, text_values
    d = res.f["runs"]["block"]
    labels = enum_labels(d)
    if labels is None:
        return text_values(d) == block
    if block not in labels:
        return np.zeros(d.shape[0], dtype=bool)
    return d[()] == labels.index(block)


def _block_rows(res, block):
    """The run kind of `block`, which done rows are its (a bool array over runs()' rows) and how many
    of its rows are not done."""
    done = res.f["runs"]["done"][()].astype(bool)
    mine = _block_mask(res, block)
    return res._block_kind(block), mine[done], int(np.sum(mine & ~done))


def block_parameters(res, block, rows=None):
    """The parameters `block` sweeps: those of its run kind taking more than one value among its done
    runs, in file order ([] for a block without done runs). Read one column at a time, in chunks."""
    g = res.f["runs"]
    kind = res._block_kind(block)
    done = g["done"][()].astype(bool)
    if rows is None:  # the block's done rows (a flag per row, no index of them)
        sel = _block_mask(res, block) & done
    else:
        sel = np.zeros(g["done"].shape[0], dtype=bool)
        sel[np.flatnonzero(done)[rows]] = True
    if not sel.any():
        return []
    return [c for c in res.parameters(kind) if _varies_in(g[c], sel)]


def _file_rows(res, sel, params, metric, good, max_rows, random_state):
    """fit_importance's preparation read from the file: the rows `sel` (bool over /runs) of a good
    status (compared by code) with a finite metric and parameters, counted, and only the subsample
    used read in full (angles in degrees, as runs(degrees=True)). Returns (out without the fit, x, y),
    or None when a column is stored as strings (then the caller decodes every row)."""
    from kinesweep.kinds import _s, enum_labels
    from kinesweep.read import RAD2DEG
    g = res.f["runs"]

    def scale(c):
        return RAD2DEG if _s(g[c].attrs.get("unit", "")) == "rad" else None

    st_d = g["status"]
    st_labels = enum_labels(st_d)
    if st_labels is None or any(enum_labels(g[p]) is None and g[p].dtype.kind not in "fiub" for p in params):
        return None
    if enum_labels(g[metric]) is not None or g[metric].dtype.kind not in "fiub":
        raise KeyError(f"{metric!r} is a text column: no importance of it")
    table = np.array(st_labels + [""] * (256 ** st_d.dtype.itemsize - len(st_labels)), dtype=object)
    st = np.concatenate([v for _, v in _chunks(st_d, sel)] or [np.zeros(0, dtype=st_d.dtype)]).astype(np.int64)
    n = len(st)
    good_code = np.array([x in good for x in table.tolist()])
    keep = good_code[st]
    counts = np.bincount(st[~keep], minlength=len(table))
    excluded = {}
    for label in sorted({table[c] for c in np.flatnonzero(counts)}):
        excluded[str(label)] = int(sum(counts[c] for c in np.flatnonzero(counts) if table[c] == label))
    finite = np.ones(n, dtype=bool)
    encoding, codes = {}, {}
    for c in [metric] + list(params):
        labels = enum_labels(g[c])
        if labels is not None:  # a text parameter: its codes in sorted order of the values among good rows
            table_c = labels + [""] * (256 ** g[c].dtype.itemsize - len(labels))
            v = np.concatenate([x for _, x in _chunks(g[c], sel)]).astype(np.int64)
            present = np.flatnonzero(np.bincount(v[keep], minlength=len(table_c)))
            values = sorted({table_c[k] for k in present})
            code = {x: i for i, x in enumerate(values)}
            codes[c] = np.array([code.get(x, np.nan) for x in table_c], dtype=float)
            encoding[c] = "ordinal: " + ", ".join(f"{x}={i}" for x, i in code.items())
            finite &= np.isfinite(codes[c][v])
            continue
        if c != metric:
            encoding[c] = "numeric"
        pos = 0
        for _, v in _chunks(g[c], sel):
            if v.dtype.kind == "f":
                finite[pos:pos + len(v)] &= np.isfinite(v)
            pos += len(v)
    missing = int(np.sum(keep & ~finite))
    if missing:
        excluded[f"no value of {metric} or a parameter"] = missing
    keep &= finite
    used = int(np.sum(keep))
    idx = _subsample(np.flatnonzero(keep), max_rows, random_state)
    rows = np.flatnonzero(sel)[idx]

    def read(c):
        v = _take(g[c], rows)
        if c in codes:
            return codes[c][v.astype(np.int64)]
        k = scale(c)
        return (v * k if k is not None else v).astype(float)

    x = np.column_stack([read(p) for p in params]) if params else np.empty((len(idx), 0))
    return {"n": n, "used": used, "excluded": excluded, "idx": idx, "encoding": encoding}, x, read(metric)


def permutation_importance(results, block=None, metric=None, params=None, **kw):
    """Permutation importance of the swept parameters of `block` (default: the file's first; or of
    `params`) for `metric` (default: the block's run kind's ranking objective: E, IK iterations) over
    its runs with a good status. `results`: a kinesweep.read.Results or a path. Keyword arguments go
    to fit_importance (n_estimators, n_repeats, test_fraction, max_rows, random_state, min_runs).
    Returns fit_importance's dict with block, kind, unit (of the metric), units (of the parameters,
    angles in degrees), not_done (the block's rows not run yet) added. ImportanceError when nothing
    can be computed, KeyError for an unknown block or metric."""
    from kinesweep import read as ksread
    from kinesweep import where as kswhere
    if isinstance(results, str):
        with ksread.open_results(results) as res:
            return permutation_importance(res, block, metric, params, **kw)
    res = results
    blocks = res.blocks()
    if block is None:
        if not blocks:
            raise ImportanceError(f"{res.path}: no runs")
        block = blocks[0]
    if block not in blocks:
        close = kswhere.did_you_mean(block, blocks)
        raise KeyError(f"no block {block!r}" + (f"; did you mean '{close}'?" if close else "")
                       + f"; blocks: {', '.join(blocks)}")
    kind, inblock, not_done = _block_rows(res, block)
    meaning = res.kind_meaning(kind)
    metrics = res.metrics(kind)
    metric = metric or next(iter(meaning.get("ranking", [])), None)
    if metric not in metrics:
        close = kswhere.did_you_mean(str(metric), metrics)
        raise KeyError(f"{metric!r} is not a metric of {kind} runs" + (f"; did you mean '{close}'?" if close else "")
                       + f"; metrics: {', '.join(metrics)}")
    params = block_parameters(res, block, inblock) if params is None else list(params)
    good = tuple(meaning.get("good_statuses", ["ok"]))
    g = res.f["runs"]
    units = {}
    for c in [metric] + params:
        u = kswhere_unit(g[c])
        units[c] = "deg" if u == "rad" else u
    prepared = None
    if params and "status" in g:
        _sklearn()
        sel = np.zeros(g["done"].shape[0], dtype=bool)
        sel[np.flatnonzero(g["done"][()].astype(bool))[inblock]] = True
        prepared = _file_rows(res, sel, params, metric, good, kw.get("max_rows", MAX_ROWS), kw.get("random_state", SEED))
    if prepared is None:  # strings stored as such (older files): every row decoded
        names = list(dict.fromkeys(["status", metric] + params))
        runs = res.runs(columns=names, degrees=True)
        if runs[metric].dtype == object:
            raise KeyError(f"{metric!r} is a text column: no importance of it")
        sub = {c: runs[c][inblock] for c in names}
        out = fit_importance(sub, params, metric, status="status", good=good, **kw)
    else:
        p, x, y = prepared
        f = dict(n_estimators=N_ESTIMATORS, n_repeats=N_REPEATS, test_fraction=TEST_FRACTION, random_state=SEED,
                 min_runs=MIN_RUNS)
        f.update({k: v for k, v in kw.items() if k != "max_rows"})
        out = _summary(metric, p["n"], p["used"], p["excluded"], p["idx"], p["encoding"], f["n_estimators"],
                       f["random_state"], f["test_fraction"], f["n_repeats"])
        out = _fit(out, x, y, params, metric, f["n_estimators"], f["n_repeats"], f["test_fraction"],
                   f["random_state"], f["min_runs"])
    out.update(block=block, kind=kind, unit=units[metric], units={p: units[p] for p in params}, not_done=not_done)
    return out


def kswhere_unit(d):
    from kinesweep.kinds import _s
    return _s(d.attrs.get("unit", ""))


def format_table(r):
    """The human-readable text of one result."""
    unit = f" [{r['unit']}]" if r.get("unit") else ""
    excl = ", ".join(f"{s} {c}" for s, c in r["excluded"].items())
    lines = [f"block {r['block']} ({r['kind']}), metric {r['metric']}{unit}: {r['used']} of {r['rows']} runs used"
             + (f" (excluded: {excl})" if excl else " (none excluded)")
             + (f", {r['not_done']} not done" if r.get("not_done") else ""),
             f"  random forest ({r['model']['n_estimators']} trees, random_state {r['model']['random_state']}) on "
             f"{r['train']} runs" + (f" (a random {r['subsampled']} of the {r['used']})" if r.get("subsampled") else "")
             + f"; permutation importance on {r['test']} held-out runs, {r['model']['n_repeats']} repeats",
             f"  {r['note']}",
             "  encoding: " + "; ".join(f"{p} {e}" for p, e in r["encoding"].items())]
    w = max([9] + [len(p["name"]) for p in r["parameters"]])
    lines.append(f"  {'parameter':<{w}}  {'importance':>10}  {'std':>8}  {'fraction':>8}")
    for p in r["parameters"]:
        u = r.get("units", {}).get(p["name"], "")
        lines.append(f"  {p['name']:<{w}}  {p['mean']:>10.4f}  {p['std']:>8.4f}  {p['fraction']:>8.3f}"
                     + (f"   ({u})" if u else ""))
    lines.append("  importance: mean drop of the held-out R² when the parameter is shuffled; fraction: its share "
                 "of the positive drops. Not a variance decomposition.")
    if not r["trustworthy"]:
        lines.append("  WARNING: poor fit; do not read these numbers as the parameters' influence.")
    return "\n".join(lines)


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.importance", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", help="results file (.h5) written by `kinesweep run`")
    p.add_argument("--block", help="one block (default: every block that sweeps a parameter)")
    p.add_argument("--metric", help="metric column (default: the run kind's objective: E, IK iterations)")
    p.add_argument("--format", choices=("table", "json"), default="table", help="default %(default)s")
    p.add_argument("--trees", type=int, default=N_ESTIMATORS, help="trees in the forest (default %(default)s)")
    p.add_argument("--repeats", type=int, default=N_REPEATS, help="permutations per parameter (default %(default)s)")
    p.add_argument("--test-fraction", type=float, default=TEST_FRACTION,
                   help="share of the good runs held out (default %(default)s)")
    p.add_argument("--max-rows", type=int, default=MAX_ROWS,
                   help="good runs used at most, a random subsample beyond (default %(default)s)")
    p.add_argument("--seed", type=int, default=SEED, help="random_state of the split, forest and permutations")
    return p.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    from kinesweep import read as ksread
    try:
        _sklearn()
    except ImportError as e:
        print(f"importance: {e}", file=sys.stderr)
        return 1
    try:
        res = ksread.open_results(args.file)
    except (OSError, ValueError) as e:
        print(f"importance: {args.file}: {e}", file=sys.stderr)
        return 2
    kw = dict(n_estimators=args.trees, n_repeats=args.repeats, test_fraction=args.test_fraction,
              max_rows=args.max_rows, random_state=args.seed)
    results, skipped, unknown = [], [], []
    with res:
        blocks = [args.block] if args.block else res.blocks()
        for b in blocks:
            try:
                results.append(permutation_importance(res, b, args.metric, **kw))
            except KeyError as e:  # an unknown block, or a metric the block's run kind lacks
                if args.block:
                    print(f"importance: {e.args[0]}", file=sys.stderr)
                    return 2
                unknown.append(str(e.args[0]))
                skipped.append({"block": b, "reason": str(e.args[0])})
            except ImportanceError as e:
                skipped.append({"block": b, "reason": str(e)})
    if unknown and len(unknown) == len(blocks):
        print(f"importance: {unknown[0]}", file=sys.stderr)
        return 2
    if args.format == "json":
        def clean(o):
            if isinstance(o, dict):
                return {k: clean(v) for k, v in o.items()}
            if isinstance(o, list):
                return [clean(v) for v in o]
            return None if isinstance(o, float) and not np.isfinite(o) else o
        json.dump(clean({"file": args.file, "results": results, "skipped": skipped}), sys.stdout, indent=1,
                  ensure_ascii=False, allow_nan=False)
        print()
    else:
        if results:
            print("\n\n".join(format_table(r) for r in results))
        for s in skipped:
            print(f"block {s['block']}: no importance: {s['reason']}")
    if not results:
        why = f" ({skipped[0]['reason']})" if skipped else ""
        print(f"importance: {args.file}: no block with an importance{why}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
