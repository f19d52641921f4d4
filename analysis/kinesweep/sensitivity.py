"""First-order and total Sobol' indices of the blocks a study ran as a Saltelli design (/designs,
FORMAT.md), as `kinesweep run` stored them in /sensitivity: the engine's one estimator
(sensitivity/design_indices.cpp; Saltelli 2010's first-order estimator centred on the mean over A
and B, Jansen's total one, over the sample rows whose runs all have the kind's good status;
percentile bootstrap intervals at the group's bootstrap, confidence and seed). `kinesweep
sensitivity FILE` prints the same numbers, or others for other bootstrap settings.

    from kinesweep.read import open_results
    for r in open_results("results/sensitivity_seed.h5").sensitivity(metric="E"):
        print(r["at"], list(zip(r["factors"], r["first"], r["total"])))

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


def stored_indices(f):
    """/sensitivity of an open h5py file as {(block, metric, combination): {first, first_lo, first_hi,
    total, total_lo, total_hi (arrays in the design's factor order), variance, samples, dropped}} and
    its attributes (bootstrap, confidence, seed). Raises ValueError when the file has none (written
    before the engine stored it: `kinesweep run STUDY --resume -o FILE` adds it)."""
    if "sensitivity" not in f:
        raise ValueError(f"{f.filename}: no /sensitivity (written by an engine before it stored the indices); "
                         "`kinesweep run STUDY --resume -o FILE` adds it, `kinesweep sensitivity FILE` prints them")
    g = f["sensitivity"]
    block, metric = text_values(g["block"]), text_values(g["metric"])
    combination, index = g["combination"][()], g["factor_index"][()]
    cols = {k: g[k][()] for k in ("first", "first_lo", "first_hi", "total", "total_lo", "total_hi", "variance",
                                   "samples", "dropped")}
    out = {}
    for i in range(len(block)):
        key = (str(block[i]), str(metric[i]), int(combination[i]))
        e = out.setdefault(key, {"rows": []})
        e["rows"].append((int(index[i]), i))
    for e in out.values():
        rows = [i for _, i in sorted(e.pop("rows"))]
        for k in ("first", "first_lo", "first_hi", "total", "total_lo", "total_hi"):
            e[k] = cols[k][rows].astype(float)
        e["variance"] = float(cols["variance"][rows[0]])
        e["samples"], e["dropped"] = int(cols["samples"][rows[0]]), int(cols["dropped"][rows[0]])
    attrs = {k: g.attrs[k].item() for k in ("bootstrap", "confidence", "seed") if k in g.attrs}
    return out, attrs


def sensitivity(res, block=None, metric=None):
    """Indices of every block with a design (or `block`) for `metric` (default: the kind's ranking
    objective), one dict per combination of the block's other dimensions: block, kind, metric, unit,
    at ({axis: value} of the other dimensions), base_samples, factors (names), failed_runs ({status:
    count}), not_done, not_done_samples (sample rows with a run not done), failed_samples (the other
    sample rows with a failed run: the indices are conditional on success, good_status), the stored
    indices (first, total and their intervals first_lo, first_hi, total_lo, total_hi, in the order of
    factors; variance, samples, dropped) and the intervals' bootstrap, confidence and seed. Raises
    ValueError when the file has no /sensitivity or `metric` is not one of its metrics."""
    f = res.f
    out = []
    found = designs(f)
    stored, attrs = stored_indices(f) if found else ({}, {})
    for name, d in found.items():
        if block is not None and name != block:
            continue
        meaning = res.kind_meaning(d["kind"])
        m = metric or meaning["ranking"][0]
        good = meaning["good_statuses"][0]
        sizes, dim, n, k = d["sizes"], d["dim"], d["base_samples"], len(d["factors"])
        ids = slice(d["first_run"], d["first_run"] + int(np.prod(sizes)))
        done = f["runs"]["done"][ids].astype(bool).reshape(sizes)
        status = text_values(f["runs"]["status"])[ids].reshape(sizes)
        others = [j for j in range(len(sizes)) if j != dim]
        for combination, combo in enumerate(np.ndindex(*[sizes[j] for j in others])):
            index = [slice(None)] * len(sizes)
            for j, c in zip(others, combo):
                index[j] = c
            st, dn = status[tuple(index)], done[tuple(index)]
            failed = dn & (st != good)
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
            key = (name, m, combination)  # the engine's order of the combinations: run order
            if key not in stored:
                metrics = sorted({key[1] for key in stored if key[0] == name})
                raise ValueError(f"{f.filename}: /sensitivity holds no indices of {m!r} for block {name!r}; "
                                 f"expected one of {', '.join(metrics)}")
            r.update(stored[key])
            r.update(attrs)
            out.append(r)
    return out

