#!/usr/bin/python3
"""h5py check of the C++ results store (engine/store, FORMAT.md).

usage: check_store.py STORE_WRITER_HELPER WORKDIR

1. Writes a complete file with the C++ helper and checks, with h5py + numpy only, the attributes,
   the /runs table (all columns one length, values recomputed here from the same formulas as
   tests/store_testgen.cpp; labelled text columns HDF5 enums with their CF attributes, fixed-size
   columns chunked + shuffle/deflate, free text variable-length strings), the histories
   (bit-identical, chunked + deflate; in the shared row space of format_version 3 and 4) and a
   landscape.
2. Starts the helper writing slowly and reads the file concurrently, many times, while it grows.
"""
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep.live import stamp  # noqa: E402  FORMAT.md, "Reading while a sweep runs"
from kinesweep.kinds import enum_labels, text_values  # noqa: E402

FORMAT_VERSION = 5
CHUNK_ROWS = 16384  # rows per chunk of the fixed-size /runs columns (FORMAT.md, "/runs")

STATUSES = ["ok", "diverged", "singular", "ok-\u00f1"]
# (name, numpy dtype kind, unit): status is free text (variable-length strings), method is labelled
# (an enum over uint8).
COLUMNS = [("alpha", "f", "rad"), ("E", "f", "Nm"), ("iters", "i", ""), ("status", "O", ""), ("method", "u", "")]
# The labels of the labelled columns, by code (store_testgen.cpp's ColumnSpec choices).
LABELS = {"method": ["pinv", "dls"]}
# The ColumnSpecs of tests/store_testgen.cpp (test_columns) beyond name and unit: description, role, kinds.
SPECS = {
    "alpha": ("first swept angle", "parameter", "trajectory"),
    "E": ("energy-like metric", "metric", "trajectory"),
    "iters": ("iterations used", "metric", "ik"),
    "status": ("outcome word", "bookkeeping", ""),
    "method": ("redundancy resolution", "parameter", "trajectory,ik"),
}
failures = []


def check(cond, msg):
    """Records a failure; printed at the end, since a concurrent read that saw a commit drops its own."""
    if not cond:
        failures.append(msg)


def expected_row(i):
    return {
        "alpha": math.nan if i % 11 == 3 else i / 7.0,
        "E": i * 0.5 - 3.25,
        "iters": -1 if i % 13 == 0 else i * 3 - 5,
        "status": "" if i % 17 == 5 else STATUSES[i % 4],
        "method": "dls" if i % 2 else "pinv",
    }


def expected_history(i):
    """store_testgen.cpp's test_history(i)."""
    if i % 5 == 4:
        return None
    n = 0 if i % 7 == 6 else 10 + (i % 7) * 40
    t = np.array([k / 8.0 + i for k in range(n)], dtype="<f8").reshape(n, 1)
    q = np.array([[i + k * 0.25 - j / 3.0 for j in range(3)] for k in range(n)], dtype="<f8").reshape(n, 3)
    special = [math.nan, math.inf, -0.0, 1e-310 * (i + 1)]
    tau = np.array([[special[2 * k + j] if k < 2 else math.sin(i * 100 + k * 2 + j) for j in range(2)]
                    for k in range(n)], dtype="<f8").reshape(n, 2)
    return {"t": (t, "s"), "q": (q, "rad"), "tau": (tau, "Nm"), "none": (np.zeros((n, 0)), "")}


def as_str(v):
    return v.decode("utf-8") if isinstance(v, bytes) else str(v)


def same_value(got, want):
    if isinstance(want, float):
        return (math.isnan(want) and math.isnan(got)) or float(got) == want
    if isinstance(want, str):
        return as_str(got) == want
    return int(got) == want


def check_table(f, n, require_all_done):
    """Reads /runs like pandas would; done mask first, so that every row seen done is complete."""
    runs = f["runs"]
    done = runs["done"][()]
    # text columns as str (enum codes through their labels), numbers as stored
    table = {k: text_values(runs[k]) if runs[k].dtype.kind == "O" or enum_labels(runs[k]) is not None
             else runs[k][()] for k in runs}
    lengths = {k: len(v) for k, v in table.items()}
    check(len(set(lengths.values())) == 1 and lengths["done"] == n, f"/runs lengths differ or != {n}: {lengths}")
    ok_rows = 0
    for i in np.nonzero(done)[0]:
        want = expected_row(int(i))
        for name, _, _ in COLUMNS:
            if not same_value(table[name][i], want[name]):
                check(False, f"run {i} column {name}: got {table[name][i]!r}, want {want[name]!r}")
        ok_rows += 1
    if require_all_done:
        check(ok_rows == n, f"only {ok_rows} of {n} runs done")
    return int(done.sum())


def check_history(f, i):
    if int(f.attrs["format_version"]) >= 3:
        check_history_v3(f, i)
        return
    want = expected_history(i)
    name = f"{i:06d}"
    if want is None:
        check(name not in f["histories"], f"run {i} should have no history")
        return
    g = f["histories"][name]
    check(sorted(g.keys()) == sorted(want.keys()), f"run {i} arrays {list(g.keys())}")
    for a, (arr, unit) in want.items():
        d = g[a]
        check(d.shape == arr.shape, f"run {i} {a} shape {d.shape} != {arr.shape}")
        check(as_str(d.attrs["unit"]) == unit, f"run {i} {a} unit {d.attrs['unit']!r}")
        got = d[()]
        check(got.dtype == np.dtype("<f8"), f"run {i} {a} dtype {got.dtype}")
        check(got.tobytes() == arr.astype("<f8").tobytes(), f"run {i} {a} not bit-identical")
        if arr.size:
            check(d.chunks == arr.shape and d.compression == "gzip", f"run {i} {a}: chunks {d.chunks} {d.compression}")


def check_history_v3(f, i):
    """format_version 3 and 4: run i is rows [start[i], start[i] + rows[i]) of the datasets named by
    layouts[layout[i]], starting on a chunk boundary, NaN from its end to the next chunk boundary."""
    want = expected_history(i)
    g = f["histories"]
    start, rows, layout = (int(g[k][i]) for k in ("start", "rows", "layout"))
    if want is None:
        check((start, rows, layout) == (-1, 0, -1), f"run {i} should have no history: start, rows, layout = "
                                                    f"{start}, {rows}, {layout}")
        return
    c, used = int(g.attrs["chunk_rows"]), int(g.attrs["used_rows"])
    check(start >= 0 and layout >= 0 and start % c == 0, f"run {i}: start {start}, layout {layout}, chunk rows {c}")
    check(rows == 0 or start + rows <= used, f"run {i}: rows [{start}, {start + rows}) beyond used_rows {used}")
    if start < 0 or layout < 0:
        return
    datasets = {as_str(g[d].attrs.get("array", d)): g[d] for d in as_str(g.attrs["layouts"][layout]).split(",")}
    check(sorted(datasets) == sorted(want), f"run {i} arrays {sorted(datasets)}")
    for a, (arr, unit) in want.items():
        if a not in datasets:
            continue
        d = datasets[a]
        if arr.shape[1] == 0:  # an array of no columns: a fixed (0 x 0) dataset (FORMAT.md)
            check(d.shape == (0, 0) and as_str(d.attrs["unit"]) == unit, f"run {i} {a}: shape {d.shape}")
            continue
        check(d.shape[0] >= used and d.maxshape[0] is None, f"run {i} {a}: shape {d.shape}, maxshape {d.maxshape}")
        check(d.chunks == (c, d.shape[1]) and d.compression == "gzip", f"run {i} {a}: chunks {d.chunks} {d.compression}")
        check(as_str(d.attrs["unit"]) == unit, f"run {i} {a} unit {d.attrs['unit']!r}")
        got = d[start:start + rows]
        check(got.shape == arr.shape, f"run {i} {a} shape {got.shape} != {arr.shape}")
        check(got.dtype == np.dtype("<f8"), f"run {i} {a} dtype {got.dtype}")
        check(got.tobytes() == arr.astype("<f8").tobytes(), f"run {i} {a} not bit-identical")
        if rows:
            pad = d[start + rows:min(-(-(start + rows) // c) * c, d.shape[0])]
            check(bool(np.all(np.isnan(pad))), f"run {i} {a}: padding after its rows is not NaN")


def check_complete(path, n):
    with h5py.File(path, "r") as f:
        a = f.attrs
        check(as_str(a["format"]) == "kinesweep-results", "format attribute")
        check(int(a["format_version"]) == FORMAT_VERSION, f"format_version attribute {a['format_version']!r}")
        check(len(as_str(a["engine_version"])) > 0, "engine_version attribute")
        check(re.fullmatch(r"[0-9a-f]{64}", as_str(a["study_sha256"])) is not None, "study_sha256 is 64 hex digits")
        check(re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", as_str(a["created"])) is not None, "created ISO 8601")
        check(as_str(a["study_name"]) == "store-test", "study_name")
        text = as_str(f["study/text"][()])
        check(text.startswith("# a study\n") and 'name = "store-test"' in text, "study/text verbatim")
        check(as_str(f["study"].attrs["path"]) == "studies/store-test.toml", "study path attribute")
        runs = f["runs"]
        check([as_str(c) for c in runs.attrs["columns"]] == [c[0] for c in COLUMNS], "/runs columns attribute order")
        for name, kind, unit in COLUMNS + [("done", "u", "")]:
            d = runs[name]
            check("unit" in d.attrs and "description" in d.attrs, f"/runs/{name} unit/description attributes")
            check(as_str(d.attrs["unit"]) == unit, f"/runs/{name} unit {d.attrs['unit']!r}")
            check(d.dtype.kind == kind, f"/runs/{name} dtype {d.dtype}")
        check_column_layout(runs, n)
        check_column_specs(runs)
        check(check_table(f, n, True) == n, "all done")
        for i in range(n):
            check_history(f, i)
        e = f["landscapes/A/E"]
        check([as_str(x) for x in e.attrs["axes"]] == ["alpha1A", "alpha2A"], "landscape axes attribute")
        check(e.shape == (3, 2) and math.isnan(e[1, 0]) and e[2, 1] == 21.0, "landscape grid")
        check(list(f["landscapes/A/alpha1A"][()]) == [0.0, 0.5, 1.0], "landscape axis values")
        check(as_str(f["landscapes/A/alpha1A"].attrs["unit"]) == "rad", "landscape axis unit")
        try:
            import pandas  # optional here

            df = pandas.DataFrame({k: f["runs"][k][()] for k in f["runs"]})
            check(len(df) == n, "pandas DataFrame rows")
        except ImportError:
            pass


def check_column_layout(runs, n):
    """FORMAT.md, "/runs": a labelled text column is an enum over uint8 (label = code 0..L-1) with
    flag_values, flag_meanings and _FillValue (255, the member `_missing`) attributes, its type
    committed at the root as runs_<name>_t, and reads as its codes;
    free text is variable-length UTF-8 strings, contiguous; numbers and labels are chunked (C rows,
    N when N is smaller) through shuffle then deflate, with fill values the missing values."""
    for name, kind, _ in COLUMNS + [("done", "u", "")]:
        d = runs[name]
        labels = LABELS.get(name)
        if labels is not None:
            check(d.dtype == np.dtype("uint8"), f"/runs/{name} base type {d.dtype}")
            check(h5py.check_enum_dtype(d.dtype) == {**{lab: code for code, lab in enumerate(labels)}, "_missing": 255},
                  f"/runs/{name} enum members {h5py.check_enum_dtype(d.dtype)}")
            named = runs.file.get(f"runs_{name}_t")
            check(isinstance(named, h5py.Datatype) and named.dtype == d.dtype, f"/runs_{name}_t: {named!r}")
            check(enum_labels(d) == labels, f"/runs/{name} labels by code {enum_labels(d)}")
            fv = d.attrs.get("flag_values")
            check(fv is not None and np.asarray(fv).dtype == np.dtype("uint8")
                  and np.asarray(fv).tolist() == list(range(len(labels))), f"/runs/{name} flag_values {fv!r}")
            check(as_str(d.attrs.get("flag_meanings", "?")) == " ".join(x.replace(" ", "_") for x in labels),
                  f"/runs/{name} flag_meanings {d.attrs.get('flag_meanings')!r}")
            fill = d.attrs.get("_FillValue")
            check(fill is not None and np.asarray(fill).dtype == np.dtype("uint8")
                  and np.asarray(fill).ravel().tolist() == [255], f"/runs/{name} _FillValue {fill!r}")
            check(int(d.fillvalue) == 255, f"/runs/{name} fill value {d.fillvalue!r}")
            check(as_str(d.attrs.get("type", "?")) == "str", f"/runs/{name} type {d.attrs.get('type')!r}")
            check(set(d[()].tolist()) <= set(range(len(labels))) | {255}, f"/runs/{name} codes {set(d[()].tolist())}")
        else:
            check(h5py.check_enum_dtype(d.dtype) is None, f"/runs/{name} is not an enum")
            for a in ("flag_values", "flag_meanings"):
                check(a not in d.attrs, f"/runs/{name} has no {a} attribute")
            if d.dtype.kind == "i":  # integers: -1 is the missing value, and CF readers learn it here
                fill = d.attrs.get("_FillValue")
                check(fill is not None and int(np.asarray(fill).ravel()[0]) == -1 and int(d.fillvalue) == -1,
                      f"/runs/{name} _FillValue {fill!r}")
            else:
                check("_FillValue" not in d.attrs, f"/runs/{name} has no _FillValue attribute")
        if kind == "O":
            info = h5py.check_string_dtype(d.dtype)
            check(info is not None and info.length is None and info.encoding == "utf-8",
                  f"/runs/{name} is a variable-length UTF-8 string: {info}")
            check(d.chunks is None, f"/runs/{name} is contiguous: chunks {d.chunks}")
        else:
            check(d.chunks == (min(n, CHUNK_ROWS),), f"/runs/{name} chunks {d.chunks}")
            check(d.shuffle and d.compression == "gzip", f"/runs/{name} filters: shuffle {d.shuffle}, {d.compression}")
            if d.id.get_num_chunks():
                masks = [d.id.get_chunk_info(k).filter_mask for k in range(d.id.get_num_chunks())]
                check(all(m == 0 for m in masks), f"/runs/{name} chunk filter masks {masks}")
    for name, want in (("alpha", math.nan), ("E", math.nan), ("iters", -1), ("done", 0)):
        fv = runs[name].fillvalue
        check((math.isnan(want) and math.isnan(fv)) or fv == want, f"/runs/{name} fill value {fv!r}")


def check_column_specs(runs):
    """Every /runs dataset's unit, description, role and kinds, as h5py reads them, equal the
    ColumnSpecs the file was written with (done: bookkeeping, every kind)."""
    for name in list(runs):
        d = runs[name]
        for attr in ("unit", "description", "role", "kinds"):
            check(attr in d.attrs and isinstance(d.attrs[attr], str), f"/runs/{name} has a string attribute {attr}")
    for name, _, unit in COLUMNS:
        desc, role, kinds = SPECS[name]
        got = tuple(as_str(runs[name].attrs.get(k, "?")) for k in ("unit", "description", "role", "kinds"))
        check(got == (unit, desc, role, kinds), f"/runs/{name} unit/description/role/kinds {got}")
    got = tuple(as_str(runs["done"].attrs.get(k, "?")) for k in ("role", "kinds"))
    check(got == ("bookkeeping", ""), f"/runs/done role/kinds {got}")
    check(sorted(runs) == sorted([c[0] for c in COLUMNS] + ["done"]), f"/runs datasets {sorted(runs)}")


def stopped(proc):
    """True while the writer has stopped itself (SIGSTOP after a flush, --stop-after-runs)."""
    try:
        with open(f"/proc/{proc.pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] == "T"
    except (FileNotFoundError, IndexError):
        return False


def concurrent_read(helper, path, n, pauses=(250, 500, 750, 1000, 1250)):
    """Reads the file many times while the helper writes it. The helper commits every ~0.25 s (a real
    sweep: every 64 runs or 10 s) and also stops itself after each of `pauses` runs, just after a
    commit, until a read has been made: so that reads in the middle of the sweep happen however loaded
    the machine is, besides the ones racing the writer."""
    proc = subprocess.Popen([helper, path, str(n), "--delay-us", "1000", "--flush-every", "100000",
                             "--flush-seconds", "0.25", "--stop-after-runs", ",".join(map(str, pauses))],
                            stdout=subprocess.DEVNULL)
    snapshots, mid, paused, errors, stale, stale_bad, seen = 0, 0, 0, 0, 0, 0, []
    try:
        while proc.poll() is None:
            time.sleep(0.02)
            if not os.path.exists(path):
                continue
            was_stopped = stopped(proc)
            before = stamp(path)
            if before is None:
                if was_stopped:  # stopped after its flush, so no commit can be under way
                    check(False, "a commit seemed under way while the writer was stopped")
                    os.kill(proc.pid, signal.SIGCONT)
                continue
            mark = len(failures)
            try:
                with h5py.File(path, "r") as f:
                    done = check_table(f, n, False)
                    ids = np.nonzero(f["runs/done"][()])[0]
                    for i in list(ids[::9]) + list(ids[-5:]):
                        check_history(f, int(i))
                raised = None
            except (OSError, KeyError, RuntimeError) as e:  # metadata changed under this read
                raised = e
            after = stamp(path)
            if was_stopped:
                os.kill(proc.pid, signal.SIGCONT)
            if raised is not None:
                del failures[mark:]
                check(not was_stopped, f"a read while the writer was stopped raised: {raised}")
                errors += 1
                if os.environ.get("KS_DEBUG"):
                    print("raised:", raised, "stamp unchanged:", after == before)
                continue
            if after != before:  # a commit happened during the read: not one snapshot, discard
                stale += 1
                stale_bad += len(failures) > mark
                del failures[mark:]
                check(not was_stopped, "the stamp moved while the writer was stopped")
                continue
            snapshots += 1
            paused += was_stopped
            seen.append(done)
            if 0 < done < n:
                mid += 1
    finally:
        if proc.poll() is None:
            os.kill(proc.pid, signal.SIGCONT)
        rc = proc.wait(timeout=120)
    check(rc == 0, f"writer exited with {rc}")
    print(f"concurrent reads: {snapshots} consistent snapshots ({mid} mid-sweep, {paused} with the writer stopped "
          f"after a commit); discarded: {errors} raised, {stale} saw a commit ({stale_bad} of them with odd newest "
          f"runs); done counts: {seen[:3]} ... {seen[-3:]}")
    check(paused >= len(pauses), f"{paused} reads with the writer stopped, not {len(pauses)}")
    check(mid >= len(pauses), f"only {mid} consistent reads happened while the sweep was running")
    check(all(b >= a for a, b in zip(seen, seen[1:])), "done count went backwards between snapshots")
    check_complete_table(path, n)


def killed_writer_file(helper, work, iterations=8):
    """kill -9 the writer at random moments; h5py must open the file as the writer left it (no
    recovery step) and every run marked done must be right."""
    import random

    rng = random.Random(4)
    opened, pending = 0, 0
    for it in range(iterations):
        path = os.path.join(work, f"killed{it}.h5")
        proc = subprocess.Popen([helper, path, "600", "--delay-us", "200", "--flush-every", str(rng.choice([1, 4, 16]))],
                                stdout=subprocess.DEVNULL)
        # The random moment counts from the file's appearance (its creation is renamed into place), so a
        # loaded machine that starts the writer late still kills it while it writes.
        deadline = time.monotonic() + 30
        while not os.path.exists(path) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.002)
        time.sleep(rng.uniform(0.0, 0.17))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        if not os.path.exists(path):
            continue
        try:
            with open(path + ".journal", "rb") as fh:
                j = fh.read()
        except FileNotFoundError:
            j = b""
        if len(j) > 56 and j[-32:-24] == b"KSJCMT01":
            pending += 1  # died between journal commit and apply: a writer (--resume) applies it first (FORMAT.md)
            continue
        with h5py.File(path, "r") as f:
            done = check_table(f, 600, False)
            for i in np.nonzero(f["runs/done"][()])[0]:
                check_history(f, int(i))
        opened += 1
        print(f"killed writer {it}: h5py opened it as left, {done} done runs verified")
    print(f"killed writers: {opened} files opened as left by h5py, {pending} needed a journal replay first")
    check(opened >= iterations // 2, f"only {opened} killed files checked")


def check_complete_table(path, n):
    with h5py.File(path, "r") as f:
        check(check_table(f, n, True) == n, "all done after the concurrent run")


def main():
    helper, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    full = os.path.join(work, "full.h5")
    subprocess.run([helper, full, "60", "--landscape"], check=True, stdout=subprocess.DEVNULL)
    check_complete(full, 60)
    concurrent_read(helper, os.path.join(work, "growing.h5"), 1500)
    killed_writer_file(helper, work)
    if failures:
        for msg in failures:
            print("FAIL:", msg)
        print(f"{len(failures)} failures")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
