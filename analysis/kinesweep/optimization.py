"""One /optimizations/<name> group of a results file (an [[optimize]] block's evaluations, stages,
local polishes and best point), as kinesweep.read returns it. Run with /usr/bin/python3."""
import numpy as np

from kinesweep.kinds import Table, _s, is_netcdf_dimension

RAD2DEG = 180.0 / np.pi


class Optimization:
    """One /optimizations/<name> group (FORMAT.md). Variables are columns of every n x d array:
    .variables, .units (per variable: "rad", or "deg" with degrees=True), .lower, .upper (d);
    .evaluations: Table of x (n x d), objective, constraint, stage, status, start (n);
    .stages: Table of name, algorithm, result, best_status, wall_time, best_objective, evaluations (s),
    best_x (s x d); .local: Table of from, to (m x d), objective (m);
    .best: dict x (d), objective, status, stage, metrics (dict), history (Table, as Results.history());
    .references: dict (thesis_E, thesis_<variable> in the variable's unit, objective_at_thesis_x, ...);
    .kind, .preset, .objective, .settings, .wall_time [s], .seed, .n_evaluations."""

    def __init__(self, name, g, degrees=False):
        a = g.attrs
        self.name = name
        self.kind, self.preset, self.objective = _s(a.get("kind", "")), _s(a.get("preset", "")), _s(a.get("objective", ""))
        self.settings = _s(a.get("settings", ""))
        self.variables = [_s(v) for v in a.get("variables", [])]
        stored = [_s(u) for u in a.get("units", [""] * len(self.variables))]
        d = len(self.variables)
        # Per-variable scale to the returned units.
        scale = np.array([RAD2DEG if degrees and u == "rad" else 1.0 for u in stored], dtype=float).reshape(d)
        self.units = ["deg" if degrees and u == "rad" else u for u in stored]
        self.stored_units = stored

        def pts(v):
            v = np.array(v, dtype=float).reshape(-1, d) if d else np.zeros((len(v), 0))
            return v * scale

        self.lower = np.array(a.get("lower", []), dtype=float) * scale
        self.upper = np.array(a.get("upper", []), dtype=float) * scale
        self.wall_time = float(a.get("wall_time", np.nan))
        self.seed = int(a.get("seed", 0))
        self.n_evaluations = int(a.get("n_evaluations", len(g["evaluations"]["objective"])))

        def table(grp, point_cols=()):
            t = Table()
            for k in grp:
                if is_netcdf_dimension(grp[k]):
                    continue
                v = grp[k][()]
                if v.dtype.kind in "OSU":
                    v = np.array([_s(x) for x in v], dtype=object)
                unit = _s(grp[k].attrs.get("unit", ""))
                if k in point_cols:
                    v, unit = pts(v), ", ".join(self.units)
                t[k] = v
                t.units[k] = unit
                t.descriptions[k] = _s(grp[k].attrs.get("description", ""))
            return t

        self.evaluations = table(g["evaluations"], ("x",))
        self.stages = table(g["stages"], ("best_x",))
        self.local = table(g["local"], ("from", "to"))
        b = g["best"]
        metrics = {m: float(b.attrs[m]) for m in (_s(x) for x in b.attrs.get("metrics", [])) if m in b.attrs}
        hist = Table()
        if "history" in b:
            h = b["history"]
            order = [_s(x) for x in h.attrs["arrays"]] if "arrays" in h.attrs else list(h)
            for k in order:
                v = np.array(h[k][()], dtype=float)
                v = v[:, None] if v.ndim == 1 else v
                unit = _s(h[k].attrs.get("unit", ""))
                if degrees and unit == "rad":
                    v, unit = v * RAD2DEG, "deg"
                hist[k] = v
                hist.units[k] = unit
        self.best = {"x": np.array(a.get("best_x", []), dtype=float) * scale,
                     "objective": float(a.get("best_objective", np.nan)),
                     "status": _s(a.get("best_status", "")), "stage": _s(a.get("best_stage", "")),
                     "metrics": metrics, "history": hist}
        self.references = {}
        for r in (_s(x) for x in a.get("references", [])):
            v = float(a.get("reference_" + r, np.nan))
            var = r[len("thesis_"):] if r.startswith("thesis_") else None
            if var in self.variables:
                v *= scale[self.variables.index(var)]
            self.references[r] = v

    def variable_index(self, name):
        if name not in self.variables:
            raise KeyError(f"optimization {self.name} has no variable {name!r}; variables: {', '.join(self.variables)}")
        return self.variables.index(name)

    def __repr__(self):
        return (f"Optimization({self.name!r}, {self.objective!r} over {', '.join(self.variables)}, "
                f"{self.n_evaluations} evaluations, best {self.best['objective']:.6g})")
