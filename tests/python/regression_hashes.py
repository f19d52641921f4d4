#!/usr/bin/python3
"""Regression manifest: SHA-256 hashes of the results of every shipped study.

usage: /usr/bin/python3 regression_hashes.py KINESWEEP_BINARY STUDIES_DIR MANIFEST [--record]
                                             [--workdir DIR] [--threads N]

Runs every STUDIES_DIR/*.toml with `kinesweep run` and hashes what it stored, in an encoding that does
not depend on how the file stores it:
  float -> little-endian float64 bytes, int -> little-endian int64 bytes,
  text  -> UTF-8 strings joined by b"\\0".
Items (one manifest entry each, with the dtype class f/i/s and the shape or row count):
  runs/<column>                     every /runs column but wall_time, values in run order
  histories/<array>                 per array name, over the runs that have it in run-id order:
                                    run id (int64), shape (2 x int64), values (float64)
  optimizations/<name>/<path>       every dataset under /optimizations/<name>, recursively
  optimizations/<name>/<path>@<attr>  every group attribute there
  Anything whose name contains "wall_time" is skipped (wall clock). Root attributes (dates,
  versions, paths), dataset unit/description attributes and /landscapes (derived from /runs) are not
  hashed.
--record writes MANIFEST; otherwise the hashes are compared with it, every mismatch, missing or extra
item is printed, and the exit status is 1 if there is any. Only the storage-specific reading lives in
decode_text() and history_arrays() (which reads through kinesweep.history, the one reader of the
/histories layouts): adapt those when the file format changes.
"""
import argparse
import glob
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "analysis"))
from kinesweep.history import Histories  # noqa: E402  the /histories layouts of format_version 1 to 3

# --histories per study; every other study runs with "none".
FULL_HISTORIES = {"thesis_table4", "ik_scara", "examples_convergence"}
ABOUT = ("Written by tests/python/regression_hashes.py --record (see its docstring for the encoding). "
         "Results must stay bitwise identical; a change that alters a stored number re-records this "
         "file and says why in its commit message.")


# --- storage-specific reading (adapt these when the file format changes) -----------------------

def decode_text(values, source=None):
    """Text values as a list of str, or None if `values` is not text. `source` is the h5py Dataset
    the values were read from (None for an attribute). Accepts what h5py returns for variable- or
    fixed-length strings (bytes / str, object or S/U arrays, scalars) and HDF5 enums (integer codes +
    the name table in the dtype). Integer codes with a name table elsewhere (an attribute of
    `source`, a dataset next to it) are to be decoded here too."""
    dtype = np.asarray(values).dtype if source is None else source.dtype
    flat = np.asarray(values).reshape(-1)
    enum = h5py.check_enum_dtype(dtype) if dtype.kind != "b" else None
    if enum is not None:
        missing = 256 ** dtype.itemsize - 1  # the missing code (a member of its own since format 5)
        names = {code: name for name, code in enum.items() if code != missing}
        return [names.get(int(v), "") for v in flat]  # a code without a label: the missing value
    if dtype.kind in "SUO":
        return [v.decode("utf-8") if isinstance(v, bytes) else str(v) for v in flat]
    return None


def history_arrays(f):
    """Yield (run_id, array name, 2-D float64 array) for every history in run-id order, whatever the
    layout, so that equal histories hash equal in every format version:
      v1, v2: /histories/<zero-padded run id>/<array name> (a 1-D dataset is one column);
      v3: one row space; run i is rows [start[i], start[i] + rows[i]) of the datasets its layout
          names, each dataset's `array` attribute naming its array (dataset F.2 holds array F)."""
    for run_id, arrays in Histories(f).items():
        for name, a, _unit in arrays:
            yield run_id, name, a


# --- canonical encoding ---------------------------------------------------------------------

def canonical(values, source=None):
    """(class, shape, bytes) of a dataset's or attribute's values in the format-independent encoding."""
    arr = np.asarray(values)
    text = decode_text(values, source)
    if text is not None:
        return "s", list(arr.shape), b"\0".join(s.encode("utf-8") for s in text)
    if arr.dtype.kind in "iub":
        return "i", list(arr.shape), arr.astype("<i8").reshape(-1).tobytes()
    if arr.dtype.kind == "f":
        return "f", list(arr.shape), arr.astype("<f8").reshape(-1).tobytes()
    raise TypeError(f"cannot hash values of dtype {arr.dtype}")


def entry(values, source=None, shape_key="shape"):
    """Manifest entry: dtype class, shape (or row count if shape_key is "rows"), SHA-256."""
    cls, shape, data = canonical(values, source)
    size = shape[0] if shape_key == "rows" else shape
    return {"class": cls, shape_key: size, "sha256": hashlib.sha256(data).hexdigest()}


def hash_results(path):
    """Every item of one results file: {item name: {class, rows or shape or runs, sha256}}."""
    items = {}
    with h5py.File(path, "r") as f:
        for col, ds in f["runs"].items():
            if col != "wall_time":
                items[f"runs/{col}"] = entry(ds[()], ds, "rows")

        hashers, counts = {}, {}
        for run_id, name, a in history_arrays(f):
            h = hashers.setdefault(name, hashlib.sha256())
            h.update(np.int64(run_id).astype("<i8").tobytes())
            h.update(np.asarray(a.shape, dtype="<i8").tobytes())
            h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
            counts[name] = counts.get(name, 0) + 1
        for name, h in hashers.items():
            items[f"histories/{name}"] = {"class": "f", "runs": counts[name], "sha256": h.hexdigest()}

        for opt, group in f.get("optimizations", {}).items():
            def add_attrs(prefix, obj):
                for attr in obj.attrs:
                    if "wall_time" not in attr:
                        items[f"{prefix}@{attr}"] = entry(obj.attrs[attr])

            def visit(rel, obj):
                if "wall_time" in rel:
                    return
                name = f"optimizations/{opt}/{rel}"
                if isinstance(obj, h5py.Dataset) and b"not a netCDF variable" in bytes(obj.attrs.get("NAME", b"")):
                    return  # a netCDF dimension's scale: structure, no values
                if isinstance(obj, h5py.Dataset):
                    items[name] = entry(obj[()], obj)
                else:
                    add_attrs(name, obj)

            add_attrs(f"optimizations/{opt}", group)
            group.visititems(visit)
    return items


# --- running, recording, comparing ------------------------------------------------------------

def run_study(exe, toml, out, threads):
    name = os.path.splitext(os.path.basename(toml))[0]
    hist = "full" if name in FULL_HISTORIES else "none"
    # --no-verify-best: the hashes cover /runs and /optimizations only; the best runs' grid verification
    # (/verification) would re-run every global study's best runs at 2 and 4 times their resolution
    cmd = [exe, "run", toml, "-o", out, "--overwrite", "-q", "--threads", str(threads), "--histories", hist,
           "--no-verify-best"]
    start = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.monotonic() - start
    if r.returncode != 0:
        print(f"{name}: kinesweep exited {r.returncode}\n{r.stdout}{r.stderr}", file=sys.stderr)
        return hist, seconds, 0.0, None
    start = time.monotonic()
    items = hash_results(out)
    return hist, seconds, time.monotonic() - start, items


def compare(expected, got, new_items=None):
    """Print every difference; return (passed, failed) item counts. With `new_items` (a dict), items
    the manifest lacks (a new column) are collected there per study instead of failing."""
    passed = failed = 0
    for study in sorted(set(expected) | set(got)):
        exp = expected.get(study, {}).get("items", {})
        new = got.get(study, {}).get("items", {})
        for item in sorted(set(exp) | set(new)):
            if new_items is not None and item not in exp:
                new_items.setdefault(study, {})[item] = new[item]
                continue
            e, g = exp.get(item, "(missing from manifest)"), new.get(item, "(not produced)")
            if e == g:
                passed += 1
            else:
                failed += 1
                print(f"MISMATCH {study} {item}\n  expected {json.dumps(e, sort_keys=True)}\n"
                      f"  got      {json.dumps(g, sort_keys=True)}")
    return passed, failed


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("kinesweep")
    p.add_argument("studies_dir")
    p.add_argument("manifest")
    p.add_argument("--record", action="store_true", help="write MANIFEST instead of comparing")
    p.add_argument("--add-new", action="store_true",
                   help="compare every item MANIFEST holds; add the studies and items (new columns) it does not hold")
    p.add_argument("--workdir", help="where the results files go (kept); default: a temporary dir")
    p.add_argument("--threads", type=int, default=int(os.environ.get("KS_REGRESSION_THREADS", "2")),
                   help="kinesweep worker threads (default 2, or $KS_REGRESSION_THREADS)")
    args = p.parse_args()

    studies = sorted(glob.glob(os.path.join(os.path.abspath(args.studies_dir), "*.toml")))
    if not studies:
        sys.exit(f"no studies in {args.studies_dir}")
    workdir = args.workdir or tempfile.mkdtemp(prefix="ks_regression_")
    os.makedirs(workdir, exist_ok=True)
    exe = os.path.abspath(args.kinesweep)

    got, run_total, hash_total = {}, 0.0, 0.0
    for toml in studies:
        name = os.path.splitext(os.path.basename(toml))[0]
        hist, run_s, hash_s, items = run_study(exe, toml, os.path.join(workdir, name + ".h5"), args.threads)
        run_total, hash_total = run_total + run_s, hash_total + hash_s
        print(f"{name:22s} run {run_s:7.2f} s  hash {hash_s:6.2f} s  histories={hist:4s} "
              f"{'FAILED' if items is None else str(len(items)) + ' items'}", flush=True)
        got[name] = {"histories": hist, "items": items or {}}
    print(f"{'total':22s} run {run_total:7.2f} s  hash {hash_total:6.2f} s  ({args.threads} threads)")
    if not args.workdir:
        shutil.rmtree(workdir, ignore_errors=True)

    if args.record:
        if any(not s["items"] for s in got.values()):
            sys.exit("not recording: a study failed")
        manifest = {"about": ABOUT, "studies": got}
        with open(args.manifest, "w") as f:
            json.dump(manifest, f, indent=1, sort_keys=True)
            f.write("\n")
        print(f"recorded {sum(len(s['items']) for s in got.values())} items of {len(got)} studies "
              f"in {args.manifest}")
        return 0
    with open(args.manifest) as f:
        manifest = json.load(f)
    expected = manifest["studies"]
    if args.add_new:
        added = {n: s for n, s in got.items() if n not in expected}
        if any(not s["items"] for s in added.values()):
            sys.exit("not adding: a new study failed")
        got = {n: s for n, s in got.items() if n in expected}
    new_items = {} if args.add_new else None
    passed, failed = compare(expected, got, new_items)
    if args.add_new and not failed:
        manifest["studies"].update(added)
        for study, items in (new_items or {}).items():
            manifest["studies"][study]["items"].update(items)
            print(f"added {len(items)} new items to {study}: {', '.join(sorted(items))}")
        with open(args.manifest, "w") as f:
            json.dump(manifest, f, indent=1, sort_keys=True)
            f.write("\n")
        print(f"added {', '.join(sorted(added)) or 'no study'} to {args.manifest}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
