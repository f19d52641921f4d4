"""What a /runs column's stored chunks show without decoding them all. Run with /usr/bin/python3."""
import numpy as np


def one_value(d):
    """Whether the 1-D dataset `d` holds one value in every row (NaN equal to NaN), decided from its
    stored chunks: True when every chunk but the last is stored as the same bytes as the first
    (equal stored bytes decode to equal values) and the rows of the first and the last chunk hold one
    value; False when those rows hold two values; None when the stored chunks do not show it (they
    differ, some are not written yet, the dataset is not chunked or holds variable-length strings):
    the caller then reads the values. Reads the first and last chunk's values and every chunk's
    stored bytes (a constant column's chunks compress to a few hundred bytes each)."""
    if d.ndim != 1 or d.chunks is None or d.shape[0] == 0 or d.dtype.kind == "O":
        return None
    n, c = d.shape[0], d.chunks[0]
    k = -(-n // c)
    dsid = d.id
    try:
        if dsid.get_num_chunks() != k:
            return None
        first = dsid.read_direct_chunk((0,))
        for i in range(1, k - 1):
            if dsid.read_direct_chunk((i * c,)) != first:
                return None
    except (AttributeError, KeyError, OSError, ValueError):  # an older h5py / HDF5, or a chunk not stored
        return None
    head, tail = d[0:min(c, n)], d[(k - 1) * c:n]
    v = np.concatenate([head, tail])
    if v.dtype.kind == "f":
        nan = np.isnan(v)
        return bool(nan.all() or (not nan.any() and np.all(v == v[0])))
    return bool(np.all(v == v[0]))
