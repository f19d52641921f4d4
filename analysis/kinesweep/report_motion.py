"""The report's picture of a motion run (kind = "motion"): the arm's links at evenly spaced samples
and the study's [world] obstacles in the plane of largest spread (kinesweep.motion_view, as
plot_motion draws it), as a plain plotly dict. Run with /usr/bin/python3."""
import numpy as np

from kinesweep import motion_view as mv
from kinesweep.report_page import esc, fmt

FRAMES = 12


def motion_figure(res, run_id):
    """(figure dict, caption html) of run `run_id`'s sweep, or None when its history has no points."""
    h = res.history(run_id)
    if "points" not in h or "t" not in h:
        return None
    pts, t = h["points"], h["t"][:, 0]
    obstacles, radii = mv.world_of(res.study_text or "")
    i, j = mv.view_plane(pts, obstacles)
    data = []
    for o in obstacles:  # where it is at the start (a moving one moves on)
        hull = mv.hull(mv.surface_points(o)[:, [i, j]])
        data.append({"type": "scatter", "mode": "lines", "x": hull[:, 0], "y": hull[:, 1], "fill": "toself",
                     "fillcolor": "rgba(127,127,127,0.45)", "line": {"color": "#404040", "width": 1},
                     "name": o["type"], "hoverinfo": "skip"})
    shown = mv.frames(len(pts), FRAMES)
    for rank, s in enumerate(shown):
        p = mv.links_of(pts[s])
        shade = 0.25 + 0.75 * rank / max(1, len(shown) - 1)
        data.append({"type": "scatter", "mode": "lines+markers", "x": p[:, i], "y": p[:, j],
                     "line": {"color": f"rgba(26,51,153,{shade:.3f})", "width": 2}, "marker": {"size": 4},
                     "name": f"t = {t[s]:.3g} s", "showlegend": False,
                     "hovertemplate": f"t = {t[s]:.4g} s<extra></extra>"})
    data.append({"type": "scatter", "mode": "lines", "x": pts[:, -3 + i], "y": pts[:, -3 + j], "name": "tip path",
                 "line": {"color": "#d62728", "dash": "dash", "width": 1}})
    note = ""
    if obstacles and len(radii) == pts.shape[1] // 3 - 1:
        c = np.array([mv.clearance(row, radii, obstacles, ts) for row, ts in zip(pts, t)])
        k = int(np.argmin(c))
        note = f" Least clearance of the stored samples {fmt(c[k], 4)} m at t = {fmt(t[k], 4)} s."
    layout = {"height": 420, "margin": {"l": 60, "r": 20, "t": 30, "b": 50},
              "xaxis": {"title": {"text": f"{mv.AXES[i]} [m]"}},
              "yaxis": {"title": {"text": f"{mv.AXES[j]} [m]"}, "scaleanchor": "x", "scaleratio": 1},
              "legend": {"orientation": "h", "y": 1.08, "x": 0}}
    caption = (f"The arm of run {run_id} at {len(shown)} evenly spaced samples (darker later), its tip path "
               f"and the study's obstacles, seen along the {esc(mv.AXES[3 - i - j])} axis.{note}")
    return {"data": data, "layout": layout}, caption
