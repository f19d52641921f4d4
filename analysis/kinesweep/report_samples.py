"""Figures of kinesweep.report for blocks of sampled runs (Latin hypercubes, zipped random draws,
Saltelli designs: a landscape dimension of points that are not grid lines, so no heatmap is drawn):
the metric against each swept parameter (one panel per parameter, as Optuna's slice plot) and
parallel coordinates over the parameters and the metric. Angles in degrees. Run with /usr/bin/python3."""
import numpy as np

from kinesweep.plotting import is_log_spaced
from kinesweep.report_page import esc, figure

MAX_POINTS = 5000       # runs drawn per block (an evenly spaced subset of a bigger block; the caption says so)
PANEL_COLUMNS = 3
GOOD_COLOUR = "#1f77b4"
FAILED_COLOUR = "#7f7f7f"


def _distinct(v):
    if v.dtype == object:
        return set(v.tolist())
    v = np.asarray(v, dtype=float)
    return np.unique(v[~np.isnan(v)])


def swept_parameters(view, block):
    """The parameters of the block's run kind that take more than one value among its done runs."""
    rows = view.rows(block)
    kind = view.kind(block)
    if len(rows) == 0 or not kind:
        return []
    return [p for p in view.res.parameters(kind) if p in view.g and len(_distinct(view.values(p, rows))) > 1]


def _label(name, unit):
    return f"{name} [{unit}]" if unit else name


def block_data(view, block, params):
    """The rows drawn (an evenly spaced subset when the block has more than MAX_POINTS done runs), their
    run ids, statuses, good mask, the metric (the kind's ranking objective) and each parameter's values."""
    meaning = view.res.kind_meaning(view.kind(block))
    metric = next((m for m in meaning.get("ranking", []) if m in view.g), None)
    rows = view.rows(block)
    total = len(rows)
    if total > MAX_POINTS:
        rows = rows[np.linspace(0, total - 1, MAX_POINTS).round().astype(np.int64)]
    status = view.status(rows)
    good = np.isin(status, meaning.get("good_statuses", ["ok"]))
    y = np.asarray(view.values(metric, rows), dtype=float) if metric else np.full(len(rows), np.nan)
    return {"rows": rows, "total": total, "status": status, "good": good, "metric": metric,
            "unit": view.units.get(metric, "") if metric else "", "y": y,
            "x": {p: view.values(p, rows) for p in params}}


def slice_figure(view, params, d):
    """One panel per parameter: the metric of every drawn run against it; good runs blue, failed runs
    with a value grey crosses (failed runs without one are counted in the caption)."""
    n = len(params)
    cols = min(PANEL_COLUMNS, n)
    nrows = (n + cols - 1) // cols
    finite = np.isfinite(d["y"])
    ok, bad = d["good"] & finite, ~d["good"] & finite
    data, layout = [], {"height": 60 + 260 * nrows, "margin": {"t": 30, "b": 50},
                        "grid": {"rows": nrows, "columns": cols, "pattern": "independent"},
                        "legend": {"orientation": "h", "y": -0.5 / nrows}, "hovermode": "closest"}
    for i, p in enumerate(params):
        ax = "" if i == 0 else str(i + 1)
        x = d["x"][p]
        text = x.dtype == object
        for mask, name, marker in ((ok, "good status", {"color": GOOD_COLOUR, "size": 6, "opacity": 0.75}),
                                   (bad, "failed (with a value)", {"color": FAILED_COLOUR, "size": 7,
                                                                   "symbol": "x"})):
            if not mask.any():
                continue
            data.append({"type": "scatter", "mode": "markers", "name": name, "legendgroup": name,
                         "showlegend": i == 0, "xaxis": "x" + ax, "yaxis": "y" + ax,
                         "x": [str(v) for v in x[mask]] if text else np.asarray(x[mask], dtype=float),
                         "y": d["y"][mask], "marker": marker, "customdata": d["rows"][mask],
                         "hovertemplate": f"run %{{customdata}}<br>{esc(p)} = %{{x}}<br>{esc(d['metric'])} = "
                                          "%{y:.6g}<extra></extra>"})
        xaxis = {"title": {"text": _label(p, view.units.get(p, ""))}}
        if not text and is_log_spaced(np.asarray(x, dtype=float)):
            xaxis["type"] = "log"
        layout["xaxis" + ax] = xaxis
        layout["yaxis" + ax] = {"title": {"text": _label(d["metric"], d["unit"])}} if i % cols == 0 else {}
    return {"data": data, "layout": layout}


def parcoords_figure(view, params, d):
    """Parallel coordinates over the parameters and the metric, one line per drawn run of good status
    with a value, coloured by the metric; text parameters on evenly spaced ticks."""
    keep = d["good"] & np.isfinite(d["y"])
    dims = []
    for p in params:
        x = d["x"][p][keep]
        label = _label(p, view.units.get(p, ""))
        if x.dtype == object:
            cats = list(dict.fromkeys(str(v) for v in d["x"][p]))
            dims.append({"label": label, "values": [cats.index(str(v)) for v in x],
                         "tickvals": list(range(len(cats))), "ticktext": cats})
        else:
            dims.append({"label": label, "values": np.asarray(x, dtype=float)})
    y = d["y"][keep]
    dims.append({"label": _label(d["metric"], d["unit"]), "values": y})
    trace = {"type": "parcoords", "dimensions": dims, "customdata": d["rows"][keep],
             "line": {"color": y, "colorscale": "Viridis", "showscale": True,
                      "colorbar": {"title": {"text": esc(d["metric"])}}}}
    left = 70 + 6 * max([len(t) for dim in dims[:1] for t in dim.get("ticktext", [])], default=0)
    return {"data": [trace], "layout": {"height": 420, "margin": {"t": 60, "l": left, "r": 40, "b": 30}}}


def sampled_section(view, blocks):
    """The section's html ("" when none is drawn) for `blocks`, those whose landscape has a dimension of
    sampled points: per block, the slice panels and the parallel coordinates."""
    parts = []
    for i, block in enumerate(blocks):
        params = swept_parameters(view, block)
        d = block_data(view, block, params) if params else {"metric": None}
        if d["metric"] is None:
            continue
        n = len(d["rows"])
        finite = np.isfinite(d["y"])
        failed = ~d["good"]
        counts = {}
        for s in d["status"][failed]:
            counts[s] = counts.get(s, 0) + 1
        fail_text = ", ".join(f"{esc(s)} {c}" for s, c in counts.items())
        missing = int((failed & ~finite).sum())
        shown = (f"{n} of its {d['total']} done runs (evenly spaced by run id)" if n < d["total"]
                 else f"its {n} done runs")
        caption = (f"{esc(d['metric'])} of {shown} against each swept parameter ({esc(', '.join(params))}): "
                   f"{int((d['good'] & finite).sum())} of good status (blue)"
                   + (f", failed: {fail_text} (grey crosses" + (f"; {missing} without a value not drawn)" if missing
                                                                   else ")") if counts else "")
                   + ". Hover a point for its run id.")
        title = f"Block {block} ({view.kind(block)})"
        parts.append(figure(f"samples-{i}", slice_figure(view, params, d), caption, title=title))
        pc_caption = (f"Parallel coordinates: one line per run of good status with a value of {esc(d['metric'])} "
                      f"({int((d['good'] & finite).sum())} lines), coloured by it; drag along an axis to select a "
                      "range." + (" Failed runs are left out." if counts else ""))
        parts.append(figure(f"parcoords-{i}", parcoords_figure(view, params, d), pc_caption))
    return "".join(parts)
