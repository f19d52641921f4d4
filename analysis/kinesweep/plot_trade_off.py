#!/usr/bin/python3
"""The front a trade_off sweep traces: the best point of each weight k of an [[optimize]] block whose
objective is k f_a + (1 - k) f_b normalised at a reference (seed 002 Eqs. 7.1, 7.6), drawn as each
criterion over its value at the reference (f_a / f_a0 against f_b / f_b0; the reference is (1, 1)),
each point labelled with its k, the points that no other weight's point dominates joined. Points of a
published study can be marked beside them (--mark), normalised the same way.

    python3 -m kinesweep.plot_trade_off results/placement_scara1.h5 --name scara1 \
        --mark "1.612,0.8155:Santos 2007 Table 7.5 (k = 0.9)"

Which criterion is better up or down comes from the objective: a term "1/metric" is maximised.
"""
import argparse
import re
import sys

import numpy as np

from kinesweep import plotting as ksplot
from kinesweep import read as ksread

FRONT_COLOUR = "#d62728"
MARK_COLOUR = "#1f77b4"


def parse_args(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m kinesweep.plot_trade_off", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    ksplot.add_output_args(p, default_size="800x600")
    p.add_argument("--name", help="the [[optimize]] block's name (its optimisations are NAME_k<k>); "
                   "default: the only trade_off sweep in the file")
    p.add_argument("--mark", action="append", default=[], metavar="X,Y[:LABEL]",
                   help="a published point, already normalised (f_a / f_a0, f_b / f_b0); repeatable")
    return p.parse_args(sys.argv[1:] if argv is None else argv)


def fail(msg, code=2):
    print(f"kinesweep.plot_trade_off: {msg}", file=sys.stderr)
    raise SystemExit(code)


TERM = re.compile(r"^(?:(?P<w>[-+0-9.eE]+)\*)?(?:(?P<num>\w+)_0/(?P<den>\w+)|(?P<m>\w+)/(?P=m)_0)$")


def terms_of(objective):
    """[(metric, reciprocal)] of a normalised objective text, e.g.
    "0.9*min_manipulability_0/min_manipulability + 0.1*power_sq_integral/power_sq_integral_0"."""
    out = []
    for part in objective.split(" + "):
        m = TERM.match(part.strip())
        if not m:
            raise ValueError(f"objective {objective!r} is not a normalised two-term objective")
        if m.group("num"):
            if m.group("num") != m.group("den"):
                raise ValueError(f"objective term {part!r} divides two metrics")
            out.append((m.group("num"), True))
        else:
            out.append((m.group("m"), False))
    return out


def sweep(res, name=None):
    """The trade_off sweep NAME of an open results file: (name, [(metric, reciprocal)] of its two terms,
    k (n), normalised best values (n x 2: each metric over its reference), raw best values (n x 2),
    references (2), best statuses (n)), ordered by k."""
    opts = {}
    for o in res.optimizations():
        opt = res.optimization(o)
        if "trade_off_k" in opt.references:
            opts.setdefault(o[: o.rfind("_k")], []).append(opt)
    if not opts:
        raise ValueError("the file holds no trade_off sweep (no optimisation with a trade_off_k)")
    if name is None:
        if len(opts) > 1:
            raise ValueError(f"the file holds several trade_off sweeps: {', '.join(sorted(opts))}; choose one with --name")
        name = next(iter(opts))
    if name not in opts:
        raise ValueError(f"no trade_off sweep {name!r}; sweeps: {', '.join(sorted(opts))}")
    group = sorted(opts[name], key=lambda o: o.references["trade_off_k"])
    terms = terms_of(group[0].objective)
    if len(terms) != 2:
        raise ValueError(f"sweep {name}: {len(terms)} terms; expected 2")
    k = np.array([o.references["trade_off_k"] for o in group])
    refs = np.array([group[0].references[m + "_0"] for m, _ in terms])
    raw = np.array([[o.best["metrics"].get(m, np.nan) for m, _ in terms] for o in group])
    status = [o.best["status"] for o in group]
    return name, terms, k, raw / refs, raw, refs, status


def nondominated(points, senses):
    """Mask of the points no other point dominates (senses: "max" or "min" per column)."""
    s = np.where(np.array(senses) == "max", -1.0, 1.0)
    v = points * s
    keep = np.ones(len(v), dtype=bool)
    for i in range(len(v)):
        if np.isnan(v[i]).any():
            keep[i] = False
            continue
        others = np.delete(v, i, axis=0)
        others = others[~np.isnan(others).any(axis=1)]
        keep[i] = not np.any(np.all(others <= v[i], axis=1) & np.any(others < v[i], axis=1))
    return keep


def parse_mark(text):
    xy, _, label = text.partition(":")
    try:
        x, y = (float(v) for v in xy.split(","))
    except ValueError:
        fail(f"--mark {text!r}: expected X,Y[:LABEL] (two numbers, normalised)")
    return x, y, label or f"({x:g}, {y:g})"


def main(argv=None):
    args = parse_args(argv)
    marks = [parse_mark(m) for m in args.mark]
    try:
        res = ksread.open_results(args.file)
    except (OSError, ValueError) as e:
        fail(f"{args.file}: {e}")
    try:
        name, terms, k, norm, raw, refs, status = sweep(res, args.name)
    except (ValueError, KeyError) as e:
        fail(f"{args.file}: {e}")
    senses = ["max" if rec else "min" for _, rec in terms]
    good = np.array([s == "ok" for s in status])
    front = nondominated(np.where(good[:, None], norm, np.nan), senses)
    plt, size = ksplot.figure(args)
    fig = plt.figure(figsize=size)
    ax = fig.add_subplot(1, 1, 1)
    order = np.argsort(norm[front, 0])
    ax.plot(norm[front, 0][order], norm[front, 1][order], color=FRONT_COLOUR, lw=1.2, zorder=2)
    ax.scatter(norm[good, 0], norm[good, 1], s=30, color=FRONT_COLOUR, zorder=3, label="kinesweep, best of each k")
    for i in np.flatnonzero(good):
        ax.annotate(f"k={k[i]:g}", (norm[i, 0], norm[i, 1]), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.scatter([1.0], [1.0], marker="s", s=40, color="black", zorder=3, label="reference (initial design)")
    for x, y, label in marks:
        ax.scatter([x], [y], marker="*", s=140, color=MARK_COLOUR, zorder=4, label=label)
    (a, _), (b, _) = terms
    ax.set_xlabel(f"{a} / {a}_0 ({senses[0]}; {a}_0 = {refs[0]:.4g})")
    ax.set_ylabel(f"{b} / {b}_0 ({senses[1]}; {b}_0 = {refs[1]:.4g})")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    bad = int((~good).sum())
    fig.suptitle(args.title or f"trade-off {name}: {len(k)} weights k, {int(front.sum())} on the front"
                 + (f", {bad} not ok" if bad else "") + f"\n{args.file.split('/')[-1]}", fontsize=10)
    fig.tight_layout()
    return ksplot.finish(fig, args, "trade_off_" + name,
                         {"file": args.file, "name": name, "metrics": [m for m, _ in terms], "senses": senses,
                          "k": k, "normalised": norm, "best": raw, "references": refs, "status": status,
                          "front": front, "marks": [[x, y] for x, y, _ in marks]})


if __name__ == "__main__":
    sys.exit(main())
