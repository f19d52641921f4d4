"""kinesweep's Python side: read results files (HDF5, engine/store/FORMAT.md), select runs, plot, report.

    import kinesweep
    r = kinesweep.open_results("results/thesis_table4.h5")   # kinesweep.read.Results
    r.runs()["E"], r.to_pandas(), r.landscape("table4"), r.history(3)

Submodules (each importable alone):
    read        the reader (Results, open_results, read_runs, ...)
    history     the /histories layouts of every format version
    live        reading a file while a sweep writes it (the journal's public stamp)
    kinds       run kinds' statuses, good statuses, ranking, colours (fallback for older files)
    where       `kinesweep query --where` expressions on numpy columns
    solutions   clustering joint vectors into named IK solutions
    compare     `kinesweep compare`'s verdict table (compare) and the /verification table (verification)
    pareto      Pareto fronts of 2 or 3 metrics (pareto_front, as `kinesweep query --pareto`) and hypervolume
    plotting    shared matplotlib helpers of the plot commands
    motion_view a motion run's picture: link poses, [world] obstacles, the view plane, clearance
Commands (`python3 -m kinesweep.NAME --help`; in a source tree with analysis/ on PYTHONPATH):
    plot_landscape, plot_histories, plot_cases, plot_basins, plot_convergence, plot_runs, plot_pareto,
    plot_trade_off, plot_motion, compare_landscapes, importance, report, make_examples
`python3 -m kinesweep` lists them. Old scripts that import the former flat names (ksread, kswhere,
kshistory, kslive, kstypes, kssolutions, ksplot, plot_landscape, ...) run after `import kinesweep.compat`.
"""
COMMANDS = ("plot_landscape", "plot_histories", "plot_cases", "plot_basins", "plot_convergence", "plot_runs",
            "plot_pareto", "plot_trade_off", "plot_motion", "compare_landscapes", "importance", "report", "make_examples")
_READ_API = ("open_results", "read_runs", "read_history", "read_landscape", "read_optimization", "Results",
             "FormatVersionError", "THESIS_TABLE4")


def __getattr__(name):
    """The reader's main names at the top level, imported on first use (h5py only when needed)."""
    if name in _READ_API:
        from kinesweep import read
        return getattr(read, name)
    raise AttributeError(f"module 'kinesweep' has no attribute {name!r}")
