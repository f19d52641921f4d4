"""Line figures of kinesweep.report: the history of each block's best run (joint torques against
time; IK: ‖F‖ against iteration) and the optimisation traces (objective against evaluation number by
stage, best so far). Plain plotly dicts. Run with /usr/bin/python3."""
import numpy as np

from kinesweep import read as ksread
from kinesweep.report_grids import ordinal
from kinesweep.report_page import esc, fmt, table
from kinesweep.report_tables import varying_parameters

MAX_LINE_POINTS = 4000   # per history line: longer ones are drawn every n-th sample (said in the caption)
MAX_EVALUATIONS = 20000  # optimisation evaluations drawn (every n-th beyond; the best so far is exact)
STAGE_COLOURS = {"sweep": "#8c8c8c", "global": "#1f77b4", "local": "#d62728"}
JOINT_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"]


def history_ids(res):
    """The run ids that have a history (a set), or None when there are too many to list cheaply."""
    if res.history_count() > 200000:
        return None
    return set(res.history_ids().tolist())


def best_with_history(view, block, ids):
    """The block's best good run (report_tables ranking) that has a history, or None."""
    ranked, _, _ = view.ranked(block)
    for r in ranked:
        if (int(r) in ids) if ids is not None else view.res.has_history(int(r)):
            return r
    return None


def history_figure(view, row):
    """Returns (figure dict, caption html) for one run's history."""
    res = view.res
    rid = int(row)  # a row's run id is its index
    h = res.history(rid, degrees=True)
    capped = ""
    if "t" in h and "tau" in h:
        x, y, xname, yname = h["t"][:, 0], h["tau"], "t [s]", f"τ [{h.units['tau'].split(',')[0].strip()}]"
        names = [f"τ{j + 1}" for j in range(y.shape[1])]
        log = False
        what = "Joint torques against time"
    elif "norm_F" in h:
        x = h["k"][:, 0] if "k" in h else np.arange(len(h["norm_F"]))
        unit = h.units.get("norm_F", "")
        y, xname, names, log = h["norm_F"], "iteration k", ["‖F‖"], True
        yname = f"‖F‖ [{unit}]" if unit else "‖F‖ (problem units: mm for the SCARA)"
        what = "Residual norm ‖F‖ against iteration"
    else:
        return None
    step = max(1, int(np.ceil(len(x) / MAX_LINE_POINTS)))
    if step > 1:
        keep = np.unique(np.r_[np.arange(0, len(x), step), len(x) - 1])
        x, y = x[keep], y[keep]
        capped = (f' <span class="capped">Capped: every {ordinal(step)} of {len(h[list(h)[0]])} samples drawn.</span>')
    data = []
    for j in range(y.shape[1]):
        yy = y[:, j].astype(float)
        if log:
            yy = np.where(yy > 0, yy, np.nan)
        data.append({"type": "scatter", "mode": "lines+markers" if len(x) < 60 else "lines", "x": x, "y": yy,
                     "name": names[j], "line": {"color": JOINT_COLOURS[j % len(JOINT_COLOURS)], "width": 1.6},
                     "hovertemplate": f"{names[j]} = %{{y:.5g}}<br>{xname} = %{{x}}<extra></extra>"})
    layout = {"height": 380, "margin": {"l": 70, "r": 30, "t": 30, "b": 50},
              "xaxis": {"title": {"text": xname}}, "yaxis": {"title": {"text": yname},
                                                             **({"type": "log"} if log else {})},
              "legend": {"orientation": "h", "y": 1.08, "x": 0}}
    block = view.block_labels[view.block_codes[row]]
    varying, _ = varying_parameters(view, block, view.rows(block))
    shown = ", ".join(f"{c} = {fmt(view.value(c, row), 5)}{(' ' + view.units[c]) if view.units[c] else ''}"
                      for c in varying)
    metric = view.res.kind_meaning(view.row_kind(row)).get("ranking", ["E"])[0]
    status = view.status([row])[0]
    caption = (f"{what} of run {rid} (status {esc(status)}; {esc(shown)}), the block's best "
               f"{esc(status)} run with a history: {metric} = {fmt(view.value(metric, row), 6)}"
               f"{(' ' + view.units[metric]) if view.units.get(metric) else ''}." + capped)
    return {"data": data, "layout": layout}, caption


def optimization_figure(res, name):
    """Returns (figure dict, caption html, stages table html) for one /optimizations group."""
    o = res.optimization(name, degrees=True)
    ev = o.evaluations
    obj = np.asarray(ev["objective"], dtype=float)
    n = len(obj)
    number = np.arange(1, n + 1)
    stage = np.asarray(ev["stage"], dtype=object)
    status = np.asarray(ev["status"], dtype=object) if "status" in ev else np.full(n, "", dtype=object)
    x = np.asarray(ev["x"], dtype=float).reshape(n, -1)
    good = np.isin(status, ksread.GOOD_STATUSES) | (status == "")
    best_so_far = np.fmin.accumulate(np.where(good & np.isfinite(obj), obj, np.inf)) if n else obj
    step = max(1, int(np.ceil(n / MAX_EVALUATIONS)))
    keep = np.arange(0, n, step)
    if n and step > 1:
        keep = np.unique(np.r_[keep, int(np.argmin(np.where(good, obj, np.inf)))])
    # Failed runs carry a penalty far above every real value: drawn along the top edge, above the
    # good evaluations (the hover gives the penalty).
    gv = obj[good & np.isfinite(obj)]
    pos = gv[gv > 0]
    log = bool(pos.size) and pos.size == gv.size and pos.max() / pos.min() > 100
    if gv.size:
        lo, hi = float(gv.min()), float(gv.max())
        top = 10 ** (np.log10(hi) + 0.08 * max(np.log10(hi / lo), 0.1)) if log else hi + 0.08 * max(hi - lo, abs(hi) * 0.01, 1e-12)
    else:
        top = np.nan
    drawn = np.where(good, obj, top if np.isfinite(top) else obj)
    data = []
    var_text = "".join(f"<br>{v} = %{{customdata[{k + 1}]:.5g}}" + (f" {u}" if u else "")
                       for k, (v, u) in enumerate(zip(o.variables, o.units)))
    for st in dict.fromkeys(stage.tolist()):
        for ok in (True, False):
            m = keep[(stage[keep] == st) & (good[keep] == ok)]
            if not len(m):
                continue
            custom = np.column_stack([status[m], x[m], obj[m]]).tolist()
            data.append({"type": "scattergl" if len(m) > 5000 else "scatter", "mode": "markers",
                         "x": number[m], "y": drawn[m], "customdata": custom,
                         "name": f"{st}" + ("" if ok else " (failed run: penalty)") + f" ({len(m)})",
                         "marker": {"color": STAGE_COLOURS.get(st, "#9467bd"), "size": 6 if ok else 8,
                                    "symbol": "circle" if ok else "x", "opacity": 0.8},
                         "hovertemplate": f"evaluation %{{x}} ({st})<br>{esc(o.objective)} = "
                                          f"%{{customdata[{len(o.variables) + 1}]:.6g}}"
                                          f"<br>status %{{customdata[0]}}{var_text}<extra></extra>"})
    change = np.flatnonzero(np.r_[True, np.diff(best_so_far) != 0]) if n else np.array([], dtype=int)
    change = change[np.isfinite(best_so_far[change])]
    if len(change):
        bx = np.r_[number[change], number[-1]]
        by = np.r_[best_so_far[change], best_so_far[-1]]
        data.append({"type": "scatter", "mode": "lines", "x": bx, "y": by, "name": "best so far",
                     "line": {"shape": "hv", "color": "#111111", "width": 2},
                     "hovertemplate": "best so far %{y:.6g} after %{x} evaluations<extra></extra>"})
    layout = {"height": 420, "margin": {"l": 70, "r": 30, "t": 30, "b": 50},
              "xaxis": {"title": {"text": "evaluation number"}},
              "yaxis": {"title": {"text": f"objective {o.objective}"}, **({"type": "log"} if log else {})},
              "legend": {"orientation": "h", "y": 1.1, "x": 0}}
    b = o.best
    bx_text = ", ".join(f"{v} = {fmt(val, 6)}{(' ' + u) if u else ''}" for v, u, val in zip(o.variables, o.units, b["x"]))
    refs = ", ".join(f"{k} = {fmt(v, 6)}" for k, v in o.references.items())
    caption = (f"Optimisation {esc(name)} ({esc(o.kind)}{', preset ' + esc(o.preset) if o.preset else ''}): "
               f"objective {esc(o.objective)} against evaluation number, coloured by stage"
               f"{', log scale' if log else ''}; crosses along the top edge are failed runs (their penalty "
               "values are in the hover); the black line is the best so far. "
               f"{n} evaluations; best {fmt(b['objective'], 8)} at {esc(bx_text)} (stage {esc(b['stage'])}, "
               f"status {esc(b['status'])})." + (f" References: {esc(refs)}." if refs else ""))
    if step > 1:
        caption += (f' <span class="capped">Capped: every {ordinal(step)} evaluation drawn ({len(keep)} of {n}, the best '
                    "included); the best-so-far line uses all of them.</span>")
    stg = o.stages
    cols = [c for c in ("name", "algorithm", "result", "evaluations", "best_objective", "best_status", "wall_time")
            if c in stg]
    stage_rows = [[stg[c][i] for c in cols] for i in range(len(stg[cols[0]]))] if cols else []
    stages_html = table([(c, stg.units.get(c, "")) for c in cols], stage_rows, f"stages-{name}",
                        text_columns=("name", "algorithm", "result", "best_status")) if stage_rows else ""
    return {"data": data, "layout": layout}, caption, stages_html

