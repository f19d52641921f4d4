"""Naming IK solutions where no closed form is known (chain robots): the engine's cluster_solutions
(engine/ik/chain_ik.hpp), for the analysis scripts; re-exported by kinesweep.read. Run with /usr/bin/python3."""
import numpy as np


def cluster_solutions(q, revolute, tolerance=1e-3):
    """Name distinct IK solutions where no closed form is known (the engine's cluster_solutions):
    greedy and in input order. q[0] opens cluster 0; each later row joins the first cluster (lowest
    label) whose FIRST member is within `tolerance` in the max-norm, revolute components compared
    mod 2 pi (wrapped to (-pi, pi]); else it opens the next cluster. Rows with a non-finite entry get -1.
    q: (runs x joints) array [rad or m]; revolute: per joint, True for an angle. Returns int labels."""
    q = np.asarray(q, dtype=float)
    rev = np.asarray(revolute, dtype=bool)
    labels = np.full(len(q), -1, dtype=int)
    if q.ndim != 2 or not len(q):
        return labels
    # Cluster by cluster: the earliest row not yet named opens the next cluster and takes every later
    # row not yet named within tolerance of it. A row so named is within tolerance of its cluster's
    # first member and of no earlier cluster's (those took their rows first): the row-by-row rule,
    # in time linear in the rows per cluster.
    rest = np.flatnonzero(np.all(np.isfinite(q), axis=1))  # rows not named yet, ascending
    count = 0
    while rest.size:
        first = rest[0]
        d = q[rest[1:]] - q[first]
        d[:, rev] = np.remainder(d[:, rev] + np.pi, 2 * np.pi) - np.pi
        near = np.max(np.abs(d), axis=1) <= tolerance if d.shape[1] else np.ones(len(d), dtype=bool)
        labels[first] = count
        labels[rest[1:][near]] = count
        rest = rest[1:][~near]
        count += 1
    return labels
