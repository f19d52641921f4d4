"""A landscape's grids read a block of cells at a time, for figures that draw a subsample of a big grid
and reduce the rest (minimum, counts, which metrics hold values): memory is a few blocks of cells,
not whole grids, whatever the run count. Run with /usr/bin/python3.

    for lo, hi in blocks(shape):            # hyperslabs in C order (each one contiguous in the grid)
        st = read_block(grid_source(ls, "status_code"), lo, hi)
        for k, part, y0, x0 in frame_parts(sel, lo, hi, st):   # a frame's cells in the block, (y, x)
            cells, rows, cols = take_drawn(part, y0, x0, s)    # its cells drawn (every s-th of x and y)
"""
import math

import numpy as np

BLOCK_CELLS = 1 << 18  # cells per block (2 MB of float64)


def blocks(shape, cells=BLOCK_CELLS):
    """The grid of `shape` cut into hyperslabs of about `cells` cells (at least one line along the
    axis it is cut on), in C order: yields (lo, hi), per dim lo[d] <= index < hi[d]. Each block's
    cells are consecutive in the grid's C order (the dims before the cut axis have one index), so
    block k's cells are the flat indices [flat_start(lo, shape), that + size)."""
    shape = tuple(int(n) for n in shape)
    if not shape or math.prod(shape) == 0:
        if not shape:
            yield (), ()
        return
    a = 0
    while a < len(shape) - 1 and math.prod(shape[a + 1:]) > cells:
        a += 1
    inner = math.prod(shape[a + 1:])
    step = max(1, cells // max(1, inner))
    for prefix in np.ndindex(*shape[:a]):
        for j in range(0, shape[a], step):
            lo = tuple(prefix) + (j,) + (0,) * (len(shape) - a - 1)
            hi = tuple(p + 1 for p in prefix) + (min(j + step, shape[a]),) + shape[a + 1:]
            yield lo, hi


def flat_start(lo, shape):
    """The flat (C-order) index of the cell `lo` of a grid of `shape`."""
    return int(np.ravel_multi_index(lo, shape)) if len(shape) else 0


def as_grid(v, dtype):
    """Stored grid values as float64, a grid of codes (integer, format 5) with -1 (no run) as NaN:
    kinesweep.kinds._grid's reading, for a piece of the grid."""
    v = np.asarray(v)
    v = v if v.dtype == np.float64 else v.astype(float)
    if np.dtype(dtype).kind in "iu":
        v[v == -1] = np.nan
    return v


def grid_source(ls, name):
    """Where the grid `name` of the landscape `ls` is read from: its h5py dataset when the landscape's
    grids are read lazily from an open file (kinesweep.read) and this one was not read yet, else the
    array."""
    m = ls.metrics
    if hasattr(m, "dataset") and not m.is_read(name):
        return m.dataset(name)
    return np.asarray(m[name])


def read_block(source, lo, hi):
    """The cells lo <= index < hi of a grid (an h5py dataset or an array), as float64 with no run NaN."""
    key = tuple(slice(a, b) for a, b in zip(lo, hi))
    return as_grid(source[key] if key else source[()], source.dtype)


def frame_parts(sel, lo, hi, block):
    """The cells of each frame of `sel` (a report_grids.Selection) that lie in the block lo..hi of the
    grid (`block`: that block's values): yields (frame number, part, y0, x0), part a 2-D array with
    rows along y and columns along x (a 1-D landscape: one row), its first cell at (y0, x0) of the frame."""
    x, y = sel.x, sel.y
    for k, (_, f) in enumerate(sel.frames):
        idx = {**sel.fixed, **f}
        local = []
        for d in range(len(lo)):
            if d == x or d == y:
                local.append(slice(None))
            elif lo[d] <= idx.get(d, 0) < hi[d]:
                local.append(idx.get(d, 0) - lo[d])
            else:
                break
        else:
            part = block[tuple(local)]
            if y is None:
                yield k, part[None, :], 0, lo[x]
            elif x < y:
                yield k, part.T, lo[y], lo[x]
            else:
                yield k, part, lo[y], lo[x]


def take_drawn(part, y0, x0, s):
    """The cells of `part` (its first cell at (y0, x0) of the frame) on every s-th row and column of
    the frame, and where they go in the drawn array (rows yi = 0, s, 2s, ...): (cells, row slice,
    column slice)."""
    ry, rx = (-y0) % s, (-x0) % s
    cells = part[ry::s, rx::s]
    r0, c0 = (y0 + ry) // s, (x0 + rx) // s
    return cells, slice(r0, r0 + cells.shape[0]), slice(c0, c0 + cells.shape[1])


def first_min(part, y0=0, x0=0):
    """(value, i, j) of the smallest value of `part` (NaN ignored), the first in row-major order, at
    (i, j) = its position plus (y0, x0); None without a finite value. The smallest of such tuples
    over a frame's parts is np.nanargmin's cell of the whole frame."""
    finite = np.isfinite(part)
    if not finite.any():
        return None
    m = np.nanmin(part)
    i, j = np.unravel_index(int(np.argmax(part == m)), part.shape)
    return (float(m), int(i) + y0, int(j) + x0)


def drawn_cells(source, sel, f, s):
    """A frame's drawn cells of a grid (every s-th value of x and y), rows along y: as
    sel.slice(grid, f)[np.ix_(yi, xi)], read from the file by a strided selection."""
    nd = len(source.shape)
    idx = [0] * nd
    for d, i in {**sel.fixed, **f}.items():
        idx[d] = i
    idx[sel.x] = slice(0, None, s)
    if sel.y is not None:
        idx[sel.y] = slice(0, None, s)
    g = as_grid(source[tuple(idx)], source.dtype)
    if sel.y is None:
        return g[None, :]
    return g.T if sel.x < sel.y else g
