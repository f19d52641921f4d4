"""IK basins for kinesweep.report: each cell of an IK block's grid of initial guesses coloured by the
solution its run converged to (named as /runs' solution column names them, where the engine names the
solutions; else the converged final iterates named by kinesweep.solutions.cluster_solutions),
failed runs in their status colours; hover with the iterations and status. A solution's name gives the
median of its runs' final joint values: over all of them up to 20000 runs, else over every t-th in
run order (kinesweep.basins_scan.Medians). Run with /usr/bin/python3."""
import numpy as np

from kinesweep import read as ksread
from kinesweep.basins_scan import Source, StreamClusters, any_row, block_rows, joint_clusters, scan
from kinesweep.grid_blocks import blocks, drawn_cells, grid_source, read_block
from kinesweep.report_grids import STATUS_COLOURS, Selection, arrange, axis_values, capped_note, esc, legend_square, \
    value_text

SOLUTION_COLOURS = ["#1f77b4", "#2ca02c", "#ff7f0e", "#17becf", "#bcbd22", "#8c564b", "#e377c2", "#9edae5"]
OTHER_COLOUR = ksread.OTHER_SOLUTION_COLOUR
CLUSTER_TOLERANCE = 1e-3  # max-norm distance [rad or mm] under which two final iterates are one solution
RAD2DEG = 180.0 / np.pi


def final_columns(res, rows):
    """The final-iterate columns (q_final_1, ...), which are angles, and the units shown (the SCARA's
    third joint is d in mm)."""
    g = res.f["runs"]
    qcols = sorted((c for c in res.columns() if c.startswith("q_final_")), key=lambda c: int(c.rsplit("_", 1)[1]))
    scara = any_row(g, "problem", rows, ["scara"])
    stored = {c: ksread._s(g[c].attrs.get("unit", "")) for c in qcols}
    units = [("mm" if scara else "rad") if stored[c].startswith("rad or") else stored[c] for c in qcols]
    return qcols, units


def solution_text(median, qcols, units):
    """A solution named by its joints' median final values (`median`: one per column of qcols)."""
    parts = []
    for v, c, u in zip(median, qcols, units):
        v = float(v)
        n = c.rsplit("_", 1)[1]
        if u == "rad":
            parts.append(f"θ{n} = {(v * RAD2DEG + 180.0) % 360.0 - 180.0:.1f}°")
        else:
            parts.append(f"q{n} = {v:.4g} {u}")
    return ", ".join(parts)


def basins_figure(res, ls, cap):
    """Returns (figure dict, caption html, cells drawn), or None when the grid cannot be matched to the
    block's runs. The runs are read a block of cells at a time (kinesweep.basins_scan): memory holds
    the drawn cells, not the grids or the final-iterate columns."""
    status = grid_source(ls, "status_code")
    shape = status.shape
    if len(shape) < 2:
        return None
    rows = block_rows(res.f["runs"], ls.block)
    qcols, units = final_columns(res, rows)
    if len(rows) != int(np.prod(shape)) or not qcols:
        return None
    sel = Selection(ls, None)
    for d in sel.held:  # basins: further dims at their first value (the caption says so)
        sel.fixed[d] = 0
    xa, ya = ls.axes[sel.x], ls.axes[sel.y] if sel.y is not None else None
    if ya is None:
        return None
    s = sel.stride(cap)
    xi, yi = np.arange(0, len(xa.values), s), np.arange(0, len(ya.values), s)
    drawn = (len(yi), len(xi))
    xs, ys = axis_values(xa, xi), axis_values(ya, yi)
    revolute = [u == "rad" for u in units]
    src = Source(res, ls, rows, qcols)
    joints = list(range(len(qcols)))
    # The solutions as /runs names them (the engine's index of the known solution reached, as
    # plot_basins shows them); clusters of the final iterates where the engine names none.
    named_by = "named by kinesweep.solutions.cluster_solutions"
    solution = grid_source(ls, "solution") if "solution" in ls.metrics else None
    if solution is not None and any(np.isfinite(read_block(solution, lo, hi)).any() for lo, hi in blocks(shape)):
        named_by = "named as the solution column of /runs names them"

        def labeler(lo, hi, q):
            v = read_block(solution, lo, hi).ravel()
            return np.where(np.isfinite(v) & np.all(np.isfinite(q), axis=1), v, -1).astype(np.int64)
    else:
        labeler = _clusters(revolute)
    out = scan(src, sel, s, drawn, joints, labeler)
    n_sol = len(out["counts"])
    continuum, n_all = "", n_sol
    if n_sol > len(SOLUTION_COLOURS):
        # A continuum (a redundant problem): name the solutions by the joints whose final values take
        # a few distinct values over the converged runs (e.g. an S-R-S arm's elbow), as plot_basins does.
        few = joint_clusters(src, revolute, CLUSTER_TOLERANCE, len(SOLUTION_COLOURS))
        if few:
            continuum = (f" They form a continuum of postures: the colours name them "
                         f"by the joints that take a few values ({', '.join(qcols[j] for j in few)}).")
            joints = few
            out = scan(src, sel, s, drawn, joints, _clusters([revolute[j] for j in few]))
            n_sol = len(out["counts"])
    qcols, units = [qcols[j] for j in joints], [units[j] for j in joints]
    counts = out["counts"]
    # The largest clusters get their own colours (in order of first appearance); the rest share one.
    named = sorted(np.argsort(-counts, kind="stable")[:len(SOLUTION_COLOURS)].tolist()) if n_sol else []
    other = n_sol > len(named)
    classes = [f"solution {s}" for s in named] + (["other solutions"] if other else [])
    colours = SOLUTION_COLOURS[:len(named)] + ([OTHER_COLOUR] if other else [])
    texts = [solution_text(out["medians"].median(s), qcols, units) for s in named]
    lab2code = np.full(n_sol + 1, np.nan)  # the last: no solution
    lab2code[:n_sol] = len(named) if other else np.nan
    lab2code[named] = np.arange(len(named))
    statuses = ls.statuses
    status_class = {}
    for c in sorted(out["failed"]):
        status_class[c] = len(classes)
        classes.append(statuses[c])
        colours.append(STATUS_COLOURS.get(statuses[c], "#999999"))
    unnamed = None
    if out["unnamed"]:  # converged without a finite final iterate (not expected)
        unnamed = len(classes)
        classes.append("converged (no final iterate)")
        colours.append("#ffffff")
    names = np.array(classes + ["no run"], dtype=object)
    n = max(1, len(classes) - 1)
    scale = []
    for k, col in enumerate(colours):
        scale += [[max(0.0, (k - 0.5) / n), col], [min(1.0, (k + 0.5) / n), col]]
    if len(colours) == 1:
        scale = [[0.0, colours[0]], [1.0, colours[0]]]
    head = (f"{xa.name} = %{{x}}" + (f" {xa.unit}" if xa.unit else "") + f"<br>{ya.name} = %{{y}}"
            + (f" {ya.unit}" if ya.unit else ""))
    frames, cells, used = [], 0, {}
    for k_frame, (flabel, f) in enumerate(sel.frames):
        lab, st = out["labels"][k_frame], out["status"][k_frame]
        c = lab2code[np.where(lab >= 0, lab, n_sol)]
        failed = np.isfinite(st) & (st != 0)
        for code, k in status_class.items():
            c[failed & (st == code)] = k
        if unnamed is not None:
            c[(st == 0) & (lab < 0)] = unnamed
        its = drawn_cells(grid_source(ls, "iterations"), sel, f, s)
        err = drawn_cells(grid_source(ls, "error"), sel, f, s)
        cls = names[np.where(np.isfinite(c), c, len(classes)).astype(int)]
        frame_labels = out["frame_labels"][k_frame]
        for k in np.unique(c[np.isfinite(c)]).astype(int):
            used[k] = used.get(k, 0) + _frame_count(k, named, other, frame_labels, out["frame_status"][k_frame],
                                                     out["frame_unnamed"][k_frame], status_class, unnamed)
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


def _clusters(revolute):
    """A labeler for scan: the final iterates clustered as they come (StreamClusters)."""
    cl = StreamClusters(revolute, CLUSTER_TOLERANCE)
    return lambda lo, hi, q: cl.label(q)


def _frame_count(k, named, other, labels, status, unnamed_count, status_class, unnamed):
    """How many cells of a frame have class k (the frame's counts of labels, failed codes, converged
    runs without a solution)."""
    if k < len(named):
        return int(labels[named[k]]) if named[k] < len(labels) else 0
    if other and k == len(named):
        keep = np.ones(len(labels), dtype=bool)
        keep[[n for n in named if n < len(labels)]] = False
        return int(labels[keep].sum())
    for code, kk in status_class.items():
        if kk == k:
            return int(status[code]) if code < len(status) else 0
    return unnamed_count if k == unnamed else 0
