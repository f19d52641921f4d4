"""kinesweep.report's section on the Pareto front of 2 or 3 metrics the report was asked for
(`python3 -m kinesweep.report FILE --pareto M1,M2[:max][,M3]`; kinesweep.pareto): the good runs off
the front faded, the front's runs highlighted (2 metrics: joined by the step line bounding the region
they dominate; 3: a 3-D scatter), and a table of the front's runs. Run with /usr/bin/python3."""
import sys

import numpy as np

from kinesweep import pareto as kspareto
from kinesweep.report_page import esc, figure, table

MAX_POINTS = 5000      # dominated runs drawn (an evenly spaced subset beyond; the caption says so)
MAX_TABLE_ROWS = 50
FRONT_COLOUR = "#d62728"
FADED = "#b8b8b8"


def _axis(runs, name, sense):
    unit = runs.units.get(name, "")
    return f"{runs.display_names.get(name, name)}{f' [{unit}]' if unit else ''} ({sense})"


def pareto_section(res, spec):
    """The section's html for metrics `spec` ("" when the file lacks one of them, a note on stderr)."""
    try:
        runs, rows, good, on, parsed = kspareto.front_of_runs(res, spec)
    except kspareto.ParetoError as e:
        print(f"report: no Pareto section: {str(e).splitlines()[0]}", file=sys.stderr)
        return ""
    names, senses = [n for n, _ in parsed], [s for _, s in parsed]
    values = kspareto.metric_values(runs, names)
    usable = rows & good & ~np.isnan(values).any(axis=1)
    if not on.any():
        return "<p>No good run holds a value of every metric: no front.</p>"
    off = np.flatnonzero(usable & ~on)
    shown = off if len(off) <= MAX_POINTS else off[np.linspace(0, len(off) - 1, MAX_POINTS).round().astype(np.int64)]
    ids = runs["run_id"]
    front = np.flatnonzero(on)
    front = front[np.lexsort([ids[front]] + [(-1 if s == "max" else 1) * values[front, k]
                                             for k, s in reversed(list(enumerate(senses)))])]
    hover = "run %{customdata}<extra></extra>"
    if len(names) == 2:
        line = front[np.argsort(values[front, 0] if senses[0] == "min" else -values[front, 0], kind="stable")]
        data = [{"type": "scatter", "mode": "markers", "name": f"dominated ({len(off)})", "x": values[shown, 0],
                 "y": values[shown, 1], "customdata": ids[shown], "hovertemplate": hover,
                 "marker": {"color": FADED, "size": 6, "opacity": 0.55}},
                {"type": "scatter", "mode": "lines+markers", "name": f"front ({len(front)})", "x": values[line, 0],
                 "y": values[line, 1], "customdata": ids[line], "hovertemplate": hover,
                 "line": {"shape": "hv", "color": FRONT_COLOUR}, "marker": {"color": FRONT_COLOUR, "size": 9}}]
        layout = {"height": 440, "margin": {"t": 20}, "xaxis": {"title": {"text": _axis(runs, names[0], senses[0])}},
                  "yaxis": {"title": {"text": _axis(runs, names[1], senses[1])}}}
    else:
        data = [{"type": "scatter3d", "mode": "markers", "name": f"dominated ({len(off)})",
                 "x": values[shown, 0], "y": values[shown, 1], "z": values[shown, 2], "customdata": ids[shown],
                 "hovertemplate": hover, "marker": {"color": FADED, "size": 3, "opacity": 0.5}},
                {"type": "scatter3d", "mode": "markers", "name": f"front ({len(front)})",
                 "x": values[front, 0], "y": values[front, 1], "z": values[front, 2], "customdata": ids[front],
                 "hovertemplate": hover, "marker": {"color": FRONT_COLOUR, "size": 5}}]
        layout = {"height": 560, "margin": {"t": 20},
                  "scene": {f"{a}axis": {"title": {"text": _axis(runs, n, s)}}
                            for a, n, s in zip("xyz", names, senses)}}
    failed = int((rows & ~good).sum())
    no_value = int((rows & good & np.isnan(values).any(axis=1)).sum())
    caption = (f"{len(front)} of {int(usable.sum())} good runs on the front of "
               f"{esc(', '.join(f'{n} ({s})' for n, s in parsed))}"
               + (f"; {failed} runs of a failed status" if failed else "")
               + (f"; {no_value} good runs without a value" if no_value else "")
               + " left out. A run is on the front when no other good run is at least as good in every metric "
               "and better in one." + (f" {len(shown)} of the {len(off)} dominated runs drawn." if len(shown) < len(off)
                                        else ""))
    head = [("run_id", ""), ("block", "")] + [(n, runs.units.get(n, "")) for n in names]
    body = [[int(ids[i]), str(runs["block"][i])] + [float(values[i, k]) for k in range(len(names))]
            for i in front[:MAX_TABLE_ROWS]]
    more = (f'<p class="caption">{len(front) - MAX_TABLE_ROWS} more front runs (kinesweep query FILE --pareto '
            f'{esc(spec)} lists all).</p>') if len(front) > MAX_TABLE_ROWS else ""
    return figure("pareto-0", {"data": data, "layout": layout}, caption,
                  title="Front of " + ", ".join(names)) + table(head, body, css_id="pareto-front", text_columns=("block",)) + more
