"""What the plot scripts share: output arguments, the figure, saving, printing the plotted data.
Run with Debian's /usr/bin/python3 (numpy, matplotlib)."""
import os

import numpy as np


def add_output_args(p, default_size="800x600"):
    p.add_argument("file", help="results file (.h5) written by `kinesweep run`")
    p.add_argument("-o", "--output", help="output picture (default: FILE's name + a suffix, .png); "
                   "a .svg name writes SVG")
    p.add_argument("--svg", action="store_true", help="write SVG instead of PNG")
    p.add_argument("--size", default=default_size, help="picture size in pixels WxH (default %(default)s)")
    p.add_argument("--dpi", type=float, default=100.0, help="dots per inch (default %(default)s)")
    p.add_argument("--title", help="replace the title")
    p.add_argument("--print-data", action="store_true",
                   help="also print the plotted numbers as JSON on stdout (for tests and checking)")


def figure(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt, figure_size(args)


def figure_size(args):
    """--size in inches at --dpi."""
    try:
        w, h = (int(x) for x in args.size.lower().split("x"))
    except ValueError:
        raise SystemExit(f"--size {args.size!r}: expected WxH in pixels, e.g. 800x600")
    return w / args.dpi, h / args.dpi


def agg_figure(size, **kw):
    """A matplotlib Figure on an Agg canvas, without pyplot (whose import and figure manager a
    script that saves one picture does not need): Figure(figsize=size, **kw)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, **kw)
    FigureCanvasAgg(fig)
    return fig


def cells(ax, xedges, yedges, z, image, **kw):
    """Draw the rectangular cells of z (rows along y, columns along x) between the 1-D edges with the
    colour keywords kw; returns the mappable. image: as a picture resampled to the output's pixels
    (pcolorfast: one image, however many cells; linear axes only), else one quadrilateral per cell
    (pcolormesh: vector cells in SVG, any axis scale)."""
    if image:
        return ax.pcolorfast(xedges, yedges, z, **kw)
    X, Y = np.meshgrid(xedges, yedges)
    return ax.pcolormesh(X, Y, z, shading="flat", **kw)


def output_path(args, suffix):
    out = args.output
    if not out:
        base = os.path.splitext(args.file)[0]
        out = f"{base}_{suffix}." + ("svg" if args.svg else "png")
    elif args.svg and not out.lower().endswith(".svg"):
        out = os.path.splitext(out)[0] + ".svg"
    return out


def save(fig, args, suffix, layout_once=False):
    """Save the figure to its output path (output_path) and return that. layout_once (PNG): a figure
    with a layout engine (constrained layout) is laid out once here, at the saving's dpi, and drawn
    once: savefig would first draw it with rendering disabled to lay it out (the same layout)."""
    out = output_path(args, suffix)
    d = os.path.dirname(out)
    if d:
        os.makedirs(d, exist_ok=True)
    fmt = "svg" if out.lower().endswith(".svg") else "png"
    if layout_once and fmt == "png" and fig.get_layout_engine() is not None:
        fig.set_dpi(args.dpi)
        fig.get_layout_engine().execute(fig)
        fig.set_layout_engine("none")
    fig.savefig(out, dpi=args.dpi, format=fmt)
    return out


def finish(fig, args, suffix, data):
    """Save the figure (see save); with --print-data print `data` plus the output path as JSON,
    else print the path. Returns 0, the scripts' exit code."""
    out = save(fig, args, suffix)
    if args.print_data:
        print_json({**data, "output": out})
    else:
        print(out)
    return 0


def print_json(obj):
    import json

    def clean(o):
        if isinstance(o, dict):
            return {str(k): clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, np.ndarray):
            return clean(o.tolist())
        if isinstance(o, (np.floating, float)):
            return None if not np.isfinite(o) else float(o)
        if isinstance(o, np.integer):
            return int(o)
        return o

    print(json.dumps(clean(obj)))


def axis_label(name, unit):
    pretty = {"alpha1A": "α1A", "q0_1": "θ1 initial guess (q0_1)", "q0_2": "θ2 initial guess (q0_2)",
              "k": "k (gravity weight)", "lambda": "λ"}.get(name, name)
    if name.startswith("q0_") and name[3:].isdigit() and unit:  # an initial guess, named by its joint's unit
        pretty = f"{joint_symbol(name, unit)} initial guess ({name})"
    return f"{pretty} [{unit}]" if unit else pretty


def fit_title(text, fig, fontsize):
    """text with each line longer than the figure is wide broken at spaces (a character taken as
    0.6 of the font size): a title set on one line is clipped at the picture's edges."""
    import textwrap
    width = max(20, int(fig.get_figwidth() * 72.0 / (0.6 * fontsize)))
    return "\n".join(textwrap.fill(line, width) if len(line) > width else line for line in text.split("\n"))


def fmt_num(v):
    return f"{v:.4g}"


def is_log_spaced(values) -> bool:
    """True when `values` read better on a log axis: all finite values positive, spread over at least
    2 decades, and their distinct values closer to evenly spaced in log10 than linearly (mean distance
    of the sorted, min-max scaled values from an even sequence). E.g. λ = 1e-3 .. 100 by decades: True;
    uniform draws in [1e-3, 100] or a linear grid: False. Fewer than 2 distinct values: False."""
    v = np.asarray(values, dtype=float).ravel()
    v = np.unique(v[np.isfinite(v)])
    if len(v) < 2 or v[0] <= 0 or np.log10(v[-1] / v[0]) < 2:
        return False
    if len(v) == 2:
        return True
    even = np.linspace(0.0, 1.0, len(v))

    def unevenness(u):
        return float(np.mean(np.abs((u - u[0]) / (u[-1] - u[0]) - even)))

    return unevenness(np.log10(v)) < unevenness(v)


def cell_edges(values, log=False):
    """Edges of the cells centred on sorted `values` (len + 1): arithmetic midpoints, or geometric
    midpoints with log=True (cells of equal width on a log axis)."""
    v = np.asarray(values, dtype=float)
    if log:
        return np.exp(cell_edges(np.log(v)))
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def round_levels(vmin, vmax, n, log=False, integer=False):
    """About n contour levels on round values strictly inside (vmin, vmax): 1-2-5 steps (MaxNLocator),
    integers for integer metrics, or 1-2-5 times powers of ten on a log scale."""
    from matplotlib.ticker import LogLocator, MaxNLocator
    if not (np.isfinite(vmin) and np.isfinite(vmax)) or vmax <= vmin or n <= 0:
        return np.array([])
    if log:
        lv = np.array([])
        for subs in ((1.0,), (1.0, 2.0, 5.0), tuple(range(1, 10))):
            lv = LogLocator(base=10, subs=subs, numticks=1000).tick_values(vmin, vmax)
            lv = lv[(lv > vmin) & (lv < vmax)]
            if len(lv) >= max(3, (2 * n) // 3):
                break
        if len(lv) > n:  # thin out, keeping round values
            lv = lv[np.linspace(0, len(lv) - 1, n).round().astype(int)]
        return np.unique(lv)
    lv = MaxNLocator(nbins=n + 1, steps=[1, 2, 2.5, 5, 10], integer=integer).tick_values(vmin, vmax)
    return lv[(lv > vmin) & (lv < vmax)]


def log_colorbar_ticks(cb, vmin, vmax):
    """Label a log colour bar at round values (1-2-5, or 1..9 times powers of ten when the range is short),
    written as plain numbers rather than powers of ten."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter
    ticks = round_levels(vmin * 0.999999, vmax * 1.000001, 8, log=True)
    if len(ticks) < 2:
        return
    cb.ax.yaxis.set_major_locator(FixedLocator(ticks))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: plain_number(v)))
    cb.ax.yaxis.set_minor_formatter(NullFormatter())


def log_axis(ax, which):
    """A log-scale x or y axis labelled with plain numbers (0.001, 1, 100)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    axis = ax.xaxis if which == "x" else ax.yaxis
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    axis.set_major_locator(LogLocator(base=10, numticks=20))
    axis.set_major_formatter(FuncFormatter(lambda v, _: plain_number(v)))
    axis.set_minor_formatter(NullFormatter())


def joint_symbol(column, unit):
    """How a joint column (q_final_3, q0_2) is named by its unit: θj for an angle, dj for a length."""
    j = column.rsplit("_", 1)[1]
    return f"θ{j}" if unit in ("rad", "deg") else f"d{j}" if unit in ("m", "mm") else f"q{j}"


def plain_number(v):
    """A tick label without powers of ten where that stays short: 0.001, 20, 10000 (1e+06 beyond)."""
    return f"{v:.10g}" if 1e-4 <= abs(v) < 1e6 or v == 0 else f"{v:.3g}"
