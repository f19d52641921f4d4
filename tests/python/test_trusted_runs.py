"""Every `ok` run of every shipped study is a run a researcher can publish: read with h5py from the
results files the regression test wrote (its work dir), each `ok` trajectory run stays within its
own tracking bound (and orientation bound where the task has one) and within its robot's joint
limits (every limit ratio <= 1 where the robot has limits); seed 000's Table 4 runs all stay `ok`;
with closed-loop gains the 5R study keeps >= 90 % of its runs `ok` within 1 mm of the path; no `ok`
global_spline run of any shipped study departs between its samples: its dense E (dt/16) within
verify_tolerance of its stored E, its dense peak torque not above its stored one by more, and every
run that does depart is `undersampled`.

usage: /usr/bin/python3 test_trusted_runs.py RESULTS_DIR
"""
import os
import sys
import unittest

import h5py
import numpy as np

from e2e_common import runs_column, shipped_results

RESULTS = None


def trajectory_runs(path):
    """The /runs columns of the trajectory runs of a results file, as numpy arrays (None if none)."""
    with h5py.File(path, "r") as f:
        runs = f["runs"]
        cols = {name: runs_column(runs[name]) for name in runs}
    if "tracking_bound" not in cols:
        return None
    keep = ~np.isnan(cols["tracking_bound"].astype(float))
    return {k: v[keep] for k, v in cols.items()} if keep.any() else None


class TrustedRuns(unittest.TestCase):
    def files(self):
        return shipped_results(self, RESULTS)

    def test_every_ok_run_is_on_its_path_and_within_its_limits(self):
        checked = 0
        for path in self.files():
            runs = trajectory_runs(path)
            if runs is None:
                continue
            name = os.path.basename(path)
            ok = runs["status"] == "ok"
            with self.subTest(study=name):
                err = runs["max_tracking_error"][ok]
                self.assertTrue(np.all(err <= runs["tracking_bound"][ok]), name)
                if "max_orientation_error" in runs:
                    o = runs["max_orientation_error"][ok]
                    has = ~np.isnan(o)
                    self.assertTrue(np.all(o[has] <= runs["orientation_bound"][ok][has]), name)
                for ratio in ("max_q_limit_ratio", "max_qd_limit_ratio", "max_tau_limit_ratio"):
                    if ratio in runs:
                        r = runs[ratio][ok]
                        r = r[~np.isnan(r)]
                        self.assertTrue(np.all(r <= 1.0), f"{name} {ratio} max {r.max() if r.size else 0}")
                # a run marked off the path is beyond its bound, one out of limits beyond a limit
                off = runs["status"] == "off_path"
                if off.any() and "max_orientation_error" not in runs:
                    self.assertTrue(np.all(runs["max_tracking_error"][off] > runs["tracking_bound"][off]), name)
                checked += int(ok.sum())
        self.assertGreater(checked, 1000)

    def test_no_ok_global_run_departs_between_its_samples(self):
        checked = 0
        for path in self.files():
            runs = trajectory_runs(path)
            if runs is None or "dense_E" not in runs:
                continue
            name = os.path.basename(path)
            glob = runs["method"] == "global_spline"
            dense = glob & ~np.isnan(runs["dense_E"].astype(float))
            ok = dense & (runs["status"] == "ok")
            tol = runs["verify_tolerance"].astype(float)
            with self.subTest(study=name):
                E, dE = runs["E"][ok], runs["dense_E"][ok]
                self.assertTrue(np.all(np.abs(dE - E) <= tol[ok] * E), name)
                tau, dtau = runs["tau_inf"][ok], runs["dense_tau_inf"][ok]
                self.assertTrue(np.all(dtau <= tau * (1 + tol[ok])), name)
                departs = dense & (runs["dense_departure"] > tol)
                self.assertTrue(np.all(runs["status"][departs] != "ok"), name)
                checked += int(ok.sum())
        self.assertGreater(checked, 20)

    def test_table4_runs_stay_ok(self):
        runs = trajectory_runs(os.path.join(RESULTS, "thesis_table4.h5"))
        self.assertEqual(len(runs["status"]), 21)
        self.assertEqual(list(runs["status"]), ["ok"] * 21)

    def test_closed_loop_keeps_the_5r_on_its_path(self):
        runs = trajectory_runs(os.path.join(RESULTS, "redundancy_5r_clik.h5"))
        closed = runs["K_P"] > 0
        good = (runs["status"] == "ok") & (runs["max_tracking_error"] < 1e-3)
        share = good[closed].mean()
        self.assertGreaterEqual(share, 0.90, f"{share:.3f} of the closed-loop runs ok within 1 mm")


if __name__ == "__main__":
    RESULTS = sys.argv.pop(1)
    unittest.main()
