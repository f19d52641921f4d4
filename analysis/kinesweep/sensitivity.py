"""First-order and total Sobol' indices of the blocks a study ran as a Saltelli design (/designs,
FORMAT.md), as `kinesweep sensitivity` computes them: Saltelli 2010's first-order estimator (centred
on the mean over A and B) and Jansen's total one, over the sample rows whose runs all have the
kind's good status; percentile bootstrap intervals (numpy's resampling: the same method as the
command, other draws, so intervals agree to their sampling noise and point estimates exactly).

    from kinesweep.read import open_results
    for r in open_results("results/sensitivity_seed.h5").sensitivity(metric="E"):
        print(r["at"], [(f["name"], f["first"], f["total"]) for f in r["factors"]])

Run with Debian's /usr/bin/python3.
"""
import numpy as np

from kinesweep.kinds import _s, text_values


def designs(f):
    """The /designs groups of an open h5py file: block -> dict of its attributes (FORMAT.md). Raises
    ValueError naming the group when a design does not fit /runs (check_design)."""
    if "designs" not in f:
        return {}
    out = {}
    for block, g in f["designs"].items():
        a = g.attrs
        out[block] = {"kind": _s(a["kind"]), "design": _s(a["design"]), "factors": [_s(x) for x in a["factors"]],
                      "base_samples": int(a["base_samples"]), "first_run": int(a["first_run"]),
                      "dims": [_s(x) for x in a["dims"]], "sizes": [int(x) for x in a["sizes"]], "dim": int(a["dim"])}
        check_design(f, block, out[block])
    return out


def check_design(f, block, d):
    """Raises ValueError ("FILE: /designs/BLOCK: ...") unless design `d` of `block` is consistent and its
    rows [first_run, first_run + prod(sizes)) lie inside /runs and are its block's rows: run_id equal
    to the row at both ends, the block column equal to the block's name at both ends and different
    just outside them (as `kinesweep sensitivity` checks)."""
    where = f"{f.filename}: /designs/{block}"
    sizes, dim, n_rows = d["sizes"], d["dim"], len(f["runs"]["done"])
    if (len(d["dims"]) != len(sizes) or not 0 <= dim < len(sizes) or d["base_samples"] < 1 or min(sizes) < 1
            or sizes[dim] != d["base_samples"] * (len(d["factors"]) + 2)):
        raise ValueError(f"{where} is inconsistent (dims, sizes, dim, base_samples, factors)")
    runs = 1
    for s in sizes:
        runs *= s
    first, last = d["first_run"], d["first_run"] + runs - 1
    if first < 0 or last >= n_rows:
        raise ValueError(f"{where}: rows {first}..{last} (first_run, sizes) lie outside the {n_rows} rows of /runs")
    runs_g = f["runs"]
    if "run_id" in runs_g:
        for row in (first, last):
            if int(runs_g["run_id"][row]) != row:
                raise ValueError(f"{where}: /runs/run_id of row {row} is not {row}")
    if "block" not in runs_g:
        return
    col = runs_g["block"]

    def block_at(row):
        return str(text_values(col, col[row:row + 1])[0])

    for row in (first, last):
        if block_at(row) != block:
            raise ValueError(f"{where}: row {row} of /runs belongs to block {block_at(row)!r}, not to the design's "
                             f"block (first_run {first})")
    for row in (first - 1, last + 1):
        if 0 <= row < n_rows and block_at(row) == block:
            raise ValueError(f"{where}: row {row} of /runs also belongs to block {block!r}: the design (first_run "
                             f"{first}, {runs} rows) does not cover its block's rows")


def indices(a, b, ab, bootstrap=1000, confidence=0.95, seed=1):
    """The indices of the factors from the outputs of the sample rows (a: f(A), b: f(B), ab: d x N
    f(AB_i)); rows with a non-finite value are left out. Returns a dict: first, total (arrays of d),
    first_lo/first_hi/total_lo/total_hi, variance, samples, dropped."""
    a, b, ab = np.asarray(a, float), np.asarray(b, float), np.atleast_2d(np.asarray(ab, float))
    keep = np.isfinite(a) & np.isfinite(b) & np.all(np.isfinite(ab), axis=0)
    a, b, ab = a[keep], b[keep], ab[:, keep]
    d, n = ab.shape[0], a.size
    out = {"samples": int(n), "dropped": int(keep.size - n)}

    def estimate(rows):
        ra, rb, rab = a[rows], b[rows], ab[:, rows]
        y = np.concatenate([ra, rb])
        v = y.var(ddof=1)
        if not v > 0:
            return np.full(d, np.nan), np.full(d, np.nan), v
        return np.mean((rb - y.mean()) * (rab - ra), axis=1) / v, np.mean((ra - rab) ** 2, axis=1) / 2 / v, v

    nan = np.full(d, np.nan)
    if n < 2:
        out.update(first=nan, total=nan, variance=np.nan, first_lo=nan, first_hi=nan, total_lo=nan, total_hi=nan)
        return out
    out["first"], out["total"], out["variance"] = estimate(np.arange(n))
    q = (1 - confidence) / 2
    if bootstrap:
        rng = np.random.default_rng(seed)
        s1, st = np.empty((bootstrap, d)), np.empty((bootstrap, d))
        for r in range(bootstrap):
            s1[r], st[r], _ = estimate(rng.integers(0, n, n))
        out["first_lo"], out["first_hi"] = np.nanquantile(s1, q, axis=0), np.nanquantile(s1, 1 - q, axis=0)
        out["total_lo"], out["total_hi"] = np.nanquantile(st, q, axis=0), np.nanquantile(st, 1 - q, axis=0)
    else:
        out.update(first_lo=nan, first_hi=nan, total_lo=nan, total_hi=nan)
    return out


def sensitivity(res, block=None, metric=None, bootstrap=1000, confidence=0.95, seed=1):
    """Indices of every block with a design (or `block`) for `metric` (default: the kind's ranking
    objective), one dict per combination of the block's other dimensions: block, kind, metric, unit,
    at ({axis: value} of the other dimensions), base_samples, factors (names), failed_runs ({status:
    count}), not_done, not_done_samples (sample rows with a run not done), failed_samples (the other
    sample rows with a failed run: the indices are conditional on success, good_status), and
    indices()'s entries."""
    f = res.f
    out = []
    for name, d in designs(f).items():
        if block is not None and name != block:
            continue
        meaning = res.kind_meaning(d["kind"])
        m = metric or meaning["ranking"][0]
        good = meaning["good_statuses"][0]
        sizes, dim, n, k = d["sizes"], d["dim"], d["base_samples"], len(d["factors"])
        ids = slice(d["first_run"], d["first_run"] + int(np.prod(sizes)))
        done = f["runs"]["done"][ids].astype(bool).reshape(sizes)
        status = text_values(f["runs"]["status"])[ids].reshape(sizes)
        y = np.array(f["runs"][m][ids], dtype=float).reshape(sizes)
        others = [j for j in range(len(sizes)) if j != dim]
        for combo in np.ndindex(*[sizes[j] for j in others]):
            index = [slice(None)] * len(sizes)
            for j, c in zip(others, combo):
                index[j] = c
            yy, st, dn = y[tuple(index)], status[tuple(index)], done[tuple(index)]
            failed = dn & (st != good)
            values = np.where(dn & ~failed, yy, np.nan)
            at = {}
            full = [0] * len(sizes)  # the combination's first run: design point 0
            for j, c in zip(others, combo):
                full[j] = c
            first = d["first_run"] + int(np.ravel_multi_index(tuple(full), sizes))
            for j in others:
                for axis in d["dims"][j].split("+"):
                    col = f["runs"][axis]
                    v = text_values(col)[first] if col.dtype.kind not in "fiu" or "flag_meanings" in col.attrs else col[first]
                    at[axis] = v.item() if hasattr(v, "item") else v
            r = {"block": name, "kind": d["kind"], "metric": m, "unit": _s(f["runs"][m].attrs.get("unit", "")), "at": at,
                 "base_samples": n, "factors": d["factors"], "not_done": int((~dn).sum()),
                 "failed_runs": {s: int(c) for s, c in zip(*np.unique(st[failed], return_counts=True))},
                 "good_status": good}
            rows_not_done = (~dn).reshape(k + 2, n).any(axis=0)  # points A, B, AB_0.. of each sample row
            r["not_done_samples"] = int(rows_not_done.sum())
            r["failed_samples"] = int((failed.reshape(k + 2, n).any(axis=0) & ~rows_not_done).sum())
            r.update(indices(values[:n], values[n:2 * n], values[2 * n:].reshape(k, n), bootstrap, confidence, seed))
            out.append(r)
    return out

