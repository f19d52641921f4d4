#!/usr/bin/python3
"""Point-to-point motions (kind = "motion") as seed 002's Figures 7.34-7.37: for each chosen run a
row of three panels, the joint paths q(t), the joint torques τ(t), and the arm's sweep past the
study's [world] obstacles — the links (joint origins to the tip, the history's `points`) at evenly
spaced samples, darker as time goes on, the tip's path, the obstacles' outlines, and the links'
capsules drawn at the sample of least clearance. The sweep is drawn in the plane of the two base axes
along which arm and obstacles spread most (--view to choose).

    python3 -m kinesweep.plot_motion results/motion_elbow.h5 --where "block=controls" --best 2
    python3 -m kinesweep.plot_motion results/motion_elbow.h5 --runs 0,4 --view xz
"""
import argparse
import sys

import numpy as np

from kinesweep import motion_view as mv
from kinesweep import plotting as ksplot
from kinesweep import read as ksread

MAX_ROWS = 6
JOINT_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"]


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_motion", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size="1300x420")
    p.add_argument("--runs", help="run ids, comma-separated (default: the best ok runs)")
    p.add_argument("--where", help="select runs as `kinesweep query --where` does (with --best)")
    p.add_argument("--best", type=int, default=1,
                   help="without --runs: this many ok motion runs of lowest objective (default %(default)s)")
    p.add_argument("--frames", type=int, default=12, help="arm poses drawn per run (default %(default)s)")
    p.add_argument("--view", choices=["auto", "xy", "xz", "yz"], default="auto",
                   help="the sweep's plane (default: the two base axes of largest spread)")
    p.add_argument("--radians", action="store_true", help="joint angles in radians (default degrees)")
    return p.parse_args(sys.argv[1:] if argv is None else argv)


def fail(msg, code=2):
    print(f"kinesweep.plot_motion: {msg}", file=sys.stderr)
    raise SystemExit(code)


def choose_runs(res, args):
    """The run ids to draw: --runs, else the --best ok motion runs (lowest objective) among --where."""
    if args.runs:
        try:
            ids = [int(x) for x in args.runs.split(",") if x.strip()]
        except ValueError:
            fail(f"--runs {args.runs!r}: expected run ids separated by commas")
        for r in ids:
            if not res.has_history(r) or "points" not in res.history_arrays(r):
                fail(f"run {r} has no motion history (points) in {args.file}; run the study with histories")
        return ids
    runs = res.runs(where=args.where)
    if "objective" not in runs or "status" not in runs:
        fail(f"{args.file}: no motion runs{' matching --where' if args.where else ''}")
    kind = np.array([res.row_kind(int(r)) for r in runs["run_id"]])
    ok = np.nonzero((kind == "motion") & (runs["status"] == "ok"))[0]
    ok = [i for i in ok[np.argsort(runs["objective"][ok], kind="stable")]
          if res.has_history(int(runs["run_id"][i]))]
    if not ok:
        fail(f"{args.file}: no ok motion run with a history{' matching --where' if args.where else ''}")
    return [int(runs["run_id"][i]) for i in ok[:max(1, args.best)]]


def sweep_panel(ax, pts, t, obstacles, radii, plane, count):
    """Draws one run's sweep in `plane` (two axis indices); returns what was drawn (for --print-data)."""
    i, j = plane
    shown = mv.frames(len(pts), count)
    for o in obstacles:  # a moving one: where it starts (light) and ends (dark)
        for when, alpha in ((0.0, 0.2), (t[-1], 0.45)) if mv.moving([o]) else ((0.0, 0.45),):
            h = mv.hull(mv.surface_points(mv.at_time(o, when))[:, [i, j]])
            ax.fill(h[:, 0], h[:, 1], color="#7f7f7f", alpha=alpha, lw=1, ec="#404040")
    for rank, s in enumerate(shown):
        p = mv.links_of(pts[s])
        shade = 0.25 + 0.75 * rank / max(1, len(shown) - 1)
        ax.plot(p[:, i], p[:, j], "-o", color=(0.1, 0.2, 0.6, shade), ms=3, lw=2)
    tips = pts[:, -3:]
    ax.plot(tips[:, i], tips[:, j], "--", color="#d62728", lw=1, label="tip path")
    closest = None
    if obstacles and radii:
        c = np.array([mv.clearance(row, radii, obstacles, ts) for row, ts in zip(pts, t)])
        closest = int(np.argmin(c))
        p = mv.links_of(pts[closest])
        for k in range(len(p) - 1):
            ring = np.linspace(0, 2 * np.pi, 32)
            disc = np.stack([np.cos(ring), np.sin(ring)], 1) * radii[k]
            h = mv.hull(np.vstack([p[k, [i, j]] + disc, p[k + 1, [i, j]] + disc]))
            ax.plot(h[:, 0], h[:, 1], color="#d62728", lw=1)
        ax.set_title(f"least clearance {c[closest]:.4g} m at t = {t[closest]:.3g} s", fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{mv.AXES[i]} [m]")
    ax.set_ylabel(f"{mv.AXES[j]} [m]")
    return {"frames": shown.tolist(), "closest_sample": closest}


def main(argv=None):
    args = parse_args(argv)
    try:
        res = ksread.open_results(args.file)
    except (OSError, ksread.FormatVersionError) as e:
        why = "no such file" if isinstance(e, FileNotFoundError) else (getattr(e, "strerror", None) or str(e))
        fail(f"{args.file}: cannot read it as a results file: {why}", 1)
    ids = choose_runs(res, args)[:MAX_ROWS]
    obstacles, radii = mv.world_of(res.study_text or "")
    hist = {r: res.history(r, degrees=not args.radians) for r in ids}
    plane = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}.get(args.view) or \
        mv.view_plane(np.vstack([hist[r]["points"] for r in ids]), obstacles)
    plt, (w, h) = ksplot.figure(args)
    fig, axes = plt.subplots(len(ids), 3, figsize=(w, h * len(ids)), squeeze=False,
                             gridspec_kw={"width_ratios": [1, 1, 1.2]})
    data = {"runs": ids, "plane": [mv.AXES[plane[0]], mv.AXES[plane[1]]], "rows": []}
    for row, r in zip(axes, ids):
        hr = hist[r]
        t = hr["t"][:, 0]
        for j in range(hr["q"].shape[1]):
            c = JOINT_COLOURS[j % len(JOINT_COLOURS)]
            row[0].plot(t, hr["q"][:, j], color=c, label=f"q{j + 1}")
            row[1].plot(t, hr["tau"][:, j], color=c, label=f"τ{j + 1}")
        qu = hr.units["q"].split(",")[0].strip()
        tu = hr.units["tau"].split(",")[0].strip()
        row[0].set_ylabel(f"q [{qu}]")
        row[1].set_ylabel(f"τ [{tu}]")
        for a in row[:2]:
            a.set_xlabel("t [s]")
            a.grid(alpha=0.3)
            a.legend(fontsize=8, loc="best")
        row[0].set_title(f"run {r}", fontsize=9, loc="left")
        drawn = sweep_panel(row[2], hr["points"], t, obstacles, radii, plane, args.frames)
        data["rows"].append({"run": r, "t_end": float(t[-1]), **drawn})
    fig.suptitle(args.title or f"Motions of {args.file}")
    fig.tight_layout()
    return ksplot.finish(fig, args, "motion", data)


if __name__ == "__main__":
    sys.exit(main())
