"""IK basins for kinesweep.report: each cell of an IK block's grid of initial guesses coloured by the
solution its run converged to (named as /runs' solution column names them, where the engine names the
solutions; else the converged final iterates named by kinesweep.solutions.cluster_solutions),
failed runs in their status colours; hover with the iterations and status. Run with /usr/bin/python3."""
import numpy as np

from kinesweep import read as ksread
from kinesweep.solutions import cluster_solutions
from kinesweep.report_grids import STATUS_COLOURS, Selection, arrange, axis_values, capped_note, esc, legend_square, \
    value_text

SOLUTION_COLOURS = ["#1f77b4", "#2ca02c", "#ff7f0e", "#17becf", "#bcbd22", "#8c564b", "#e377c2", "#9edae5"]
OTHER_COLOUR = ksread.OTHER_SOLUTION_COLOUR
CLUSTER_TOLERANCE = 1e-3  # max-norm distance [rad or mm] under which two final iterates are one solution
RAD2DEG = 180.0 / np.pi


def final_iterates(res, block):
    """The block's rows (run-id order), their final iterates (runs x joints, stored units), which
    columns are angles, and the units shown (the SCARA's third joint is d in mm). Text columns are
    compared by their codes (not decoded row by row)."""
    g = res.f["runs"]
    qcols = sorted((c for c in res.columns() if c.startswith("q_final_")), key=lambda c: int(c.rsplit("_", 1)[1]))
    done = g["done"][()].astype(bool)  # before the columns (a writer may be committing)
    rows = np.flatnonzero(_is_one_of(g["block"], [block]))
    scara = "problem" in g and bool(np.any(_is_one_of(g["problem"], ["scara"])[rows]))
    stored = {c: ksread._s(g[c].attrs.get("unit", "")) for c in qcols}
    units = [("mm" if scara else "rad") if stored[c].startswith("rad or") else stored[c] for c in qcols]
    contiguous = len(rows) and rows[-1] - rows[0] + 1 == len(rows)

    q = np.zeros((len(rows), len(qcols)))
    for j, c in enumerate(qcols if len(rows) else []):  # filled a column at a time (no second copy)
        d = g[c]
        q[:, j] = d[int(rows[0]):int(rows[-1]) + 1] if contiguous else d[()][rows]
    conv = done[rows] & _is_one_of(g["status"], res.kind_meaning("ik")["good_statuses"])[rows]
    q[~conv] = np.nan
    return rows, q, qcols, units


def _codes_present(v):
    """sorted({int(c) for c in v}) of status codes (small non-negative numbers): counted, not a set
    built a row at a time."""
    iv = v.astype(np.int64)
    if iv.size and (iv.min() < 0 or iv.max() > 1 << 16):
        return sorted({int(c) for c in iv})
    return np.flatnonzero(np.bincount(iv)).tolist()


def _is_one_of(d, values):
    """Which rows of the text column `d` hold one of `values` (bool over all rows): an enum's codes
    compared, strings decoded."""
    labels = ksread.enum_labels(d)
    if labels is None:
        return np.isin(ksread.text_values(d), list(values))
    wanted = np.zeros(256 ** d.dtype.itemsize, dtype=bool)
    wanted[[i for i, x in enumerate(labels) if x in values]] = True
    return wanted[d[()]]


def solution_text(q, qcols, units):
    parts = []
    for j, (c, u) in enumerate(zip(qcols, units)):
        v = float(np.median(q[:, j]))
        n = c.rsplit("_", 1)[1]
        if u == "rad":
            parts.append(f"θ{n} = {(v * RAD2DEG + 180.0) % 360.0 - 180.0:.1f}°")
        else:
            parts.append(f"q{n} = {v:.4g} {u}")
    return ", ".join(parts)


def basins_figure(res, ls, cap):
    """Returns (figure dict, caption html, cells drawn), or None when the grid cannot be matched to the
    block's runs."""
    shape = ls.metrics["status_code"].shape
    if len(shape) < 2:
        return None
    rows, q, qcols, units = final_iterates(res, ls.block)
    if len(rows) != int(np.prod(shape)) or not qcols:
        return None
    revolute = [u == "rad" for u in units]
    # The solutions as /runs names them (the engine's index of the known solution reached, as
    # plot_basins shows them); clusters of the final iterates where the engine names none.
    labels, named_by = None, "named by kinesweep.solutions.cluster_solutions"
    if "solution" in ls.metrics:
        s = np.asarray(ls.metrics["solution"], dtype=float).ravel()
        if s.size == len(rows) and np.isfinite(s).any():
            labels = np.where(np.isfinite(s) & np.all(np.isfinite(q), axis=1), s, -1).astype(int)
            named_by = "named as the solution column of /runs names them"
    if labels is None:
        labels = cluster_solutions(q, revolute, CLUSTER_TOLERANCE)
    n_sol = int(labels.max(initial=-1)) + 1
    continuum, n_all = "", n_sol
    if n_sol > len(SOLUTION_COLOURS):
        # A continuum (a redundant problem): name the solutions by the joints whose final values take
        # a few distinct values over the converged runs (e.g. an S-R-S arm's elbow), as plot_basins does.
        few = [j for j in range(q.shape[1]) if cluster_solutions(q[:, [j]], [revolute[j]], CLUSTER_TOLERANCE)
               .max(initial=-1) + 1 <= len(SOLUTION_COLOURS)]
        if few:
            continuum = (f" They form a continuum of postures: the colours name them "
                         f"by the joints that take a few values ({', '.join(qcols[j] for j in few)}).")
            q, qcols, units = q[:, few], [qcols[j] for j in few], [units[j] for j in few]
            labels = cluster_solutions(q, [revolute[j] for j in few], CLUSTER_TOLERANCE)
            n_sol = int(labels.max(initial=-1)) + 1
    counts = np.bincount(labels[labels >= 0], minlength=n_sol)
    # The largest clusters get their own colours (in order of first appearance); the rest share one.
    named = sorted(np.argsort(-counts, kind="stable")[:len(SOLUTION_COLOURS)].tolist()) if n_sol else []
    other = n_sol > len(named)
    classes = [f"solution {s}" for s in named] + (["other solutions"] if other else [])
    colours = SOLUTION_COLOURS[:len(named)] + ([OTHER_COLOUR] if other else [])
    texts = [solution_text(q[labels == s], qcols, units) for s in named]
    code = np.full(len(labels), np.nan)
    for k, s in enumerate(named):
        code[labels == s] = k
    if other:
        code[(labels >= 0) & ~np.isin(labels, named)] = len(named)
    status = ls.metrics["status_code"]
    statuses = ls.statuses
    flat_status = status.reshape(-1)
    failed = _codes_present(flat_status[np.isfinite(flat_status) & (flat_status != 0)])
    for c in failed:
        code[flat_status == c] = len(classes)
        classes.append(statuses[c])
        colours.append(STATUS_COLOURS.get(statuses[c], "#999999"))
    conv_unnamed = (flat_status == 0) & np.isnan(code)
    if conv_unnamed.any():  # converged without a finite final iterate (not expected)
        code[conv_unnamed] = len(classes)
        classes.append("converged (no final iterate)")
        colours.append("#ffffff")
    code = code.reshape(shape)
    names = np.array(classes + ["no run"], dtype=object)
    best = None
    sel = Selection(ls, best)
    for d in sel.held:  # basins: further dims at their first value (the caption says so)
        sel.fixed[d] = 0
    xa, ya = ls.axes[sel.x], ls.axes[sel.y] if sel.y is not None else None
    if ya is None:
        return None
    s = sel.stride(cap)
    xi, yi = np.arange(0, len(xa.values), s), np.arange(0, len(ya.values), s)
    xs, ys = axis_values(xa, xi), axis_values(ya, yi)
    n = max(1, len(classes) - 1)
    scale = []
    for k, col in enumerate(colours):
        scale += [[max(0.0, (k - 0.5) / n), col], [min(1.0, (k + 0.5) / n), col]]
    if len(colours) == 1:
        scale = [[0.0, colours[0]], [1.0, colours[0]]]
    head = (f"{xa.name} = %{{x}}" + (f" {xa.unit}" if xa.unit else "") + f"<br>{ya.name} = %{{y}}"
            + (f" {ya.unit}" if ya.unit else ""))
    frames, cells, used = [], 0, {}
    for flabel, f in sel.frames:
        c = sel.slice(code, f)[np.ix_(yi, xi)]
        its = sel.slice(ls.metrics["iterations"], f)[np.ix_(yi, xi)]
        err = sel.slice(ls.metrics["error"], f)[np.ix_(yi, xi)]
        cls = names[np.where(np.isfinite(c), c, len(classes)).astype(int)]
        for k in np.unique(c[np.isfinite(c)]).astype(int):
            used[k] = used.get(k, 0) + int(np.sum(sel.slice(code, f) == k))
        custom = np.stack([cls, its, err], axis=-1).tolist()
        ctx = (f"<br>{esc(flabel)}" if flabel else "") + "".join(
            f"<br>{esc(value_text(ls.axes[d], sel.fixed[d]))}" for d in sel.held)
        tmpl = (head + ctx + "<br>%{customdata[0]}<br>iterations %{customdata[1]}"
                "<br>final ‖F‖ %{customdata[2]:.3g}<extra></extra>")
        frames.append((flabel, [{"type": "heatmap", "x": xs, "y": ys, "z": c, "customdata": custom,
                                 "hovertemplate": tmpl, "colorscale": scale, "zmin": 0, "zmax": n,
                                 "showscale": False, "hoverongaps": False, "name": "basins"}]))
        cells += c.size
    data, layout = arrange(frames, sel, xa, ya, height=500)
    for k in sorted(used):
        label = classes[k] + (f": {texts[k]}" if k < len(texts) and texts[k] else "") + f" ({used[k]} cells)"
        data.append(legend_square(label, colours[k]))
    layout["legend"] = {"orientation": "h", "y": -0.16, "x": 0, "font": {"size": 11}}
    layout["height"] = 520 + 22 * ((len(used) + 1) // 2)
    cap_text = (f"Basins of attraction of block {esc(ls.block)} over the initial guesses {esc(xa.name)} × "
                f"{esc(ya.name)}: each cell is coloured by the solution its run converged to ("
                + (f"{n_all} solutions reached, {named_by}" if "runs" in named_by else
                   f"{n_all} distinct final iterates within {CLUSTER_TOLERANCE:g} in the max-norm, angles mod 360°, "
                   f"{named_by}") + ")" + (f"; the {len(named)} largest have their own colour, the other "
                                                    f"{n_sol - len(named)} are grey" if other else "")
                + "; failed runs in their status colours." + continuum + " Hover a cell for its iterations and status.")
    more = sel.caption().replace("held at the best cell (not reduced)", "held at their first value")
    if more:
        cap_text += " " + esc(more[0].upper() + more[1:]) + "."
    return {"data": data, "layout": layout}, cap_text + capped_note(sel, s, star=False), cells
