"""Naming IK solutions where no closed form is known (chain robots): the engine's cluster_solutions
(engine/ik/chain_ik.hpp), for the analysis scripts; re-exported by ksread. Run with /usr/bin/python3."""
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
    firsts = np.empty((len(q), q.shape[1] if q.ndim == 2 else 0))  # the clusters' first members, in order
    count = 0
    for i, row in enumerate(q):
        if not np.all(np.isfinite(row)):
            continue
        if count:
            d = row - firsts[:count]
            d[:, rev] = np.remainder(d[:, rev] + np.pi, 2 * np.pi) - np.pi
            near = np.flatnonzero(np.max(np.abs(d), axis=1) <= tolerance)
            if near.size:
                labels[i] = near[0]  # the first cluster (lowest label) within tolerance
                continue
        labels[i] = count
        firsts[count] = row
        count += 1
    return labels
