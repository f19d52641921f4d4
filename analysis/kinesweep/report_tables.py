"""The tables of analysis/report.py: the file's metadata and run counts, status counts per block, and
the best runs of each block (parameters and metrics, units in the headers, angles in degrees).
Run with /usr/bin/python3."""
import numpy as np

from kinesweep import read as ksread
from kinesweep.report_page import esc, fmt, table


class RunsView:
    """Every row of /runs (done or not, angles in degrees) with each row's kind and block order."""

    def __init__(self, res):
        self.res = res
        self.t = res.runs(done_only=False, degrees=True)
        self.done = np.asarray(self.t["done"], dtype=bool)
        self.kinds = res.row_kinds(done_only=False)
        blocks = self.t["block"] if "block" in self.t else np.full(len(self.done), "", dtype=object)
        self.blocks = blocks
        self.block_names = list(dict.fromkeys(blocks.tolist()))

    def rows(self, block, done=True):
        m = self.blocks == block
        return np.flatnonzero(m & self.done) if done else np.flatnonzero(m)

    def kind(self, block):
        k = [x for x in self.kinds[self.rows(block)] if x]
        if k:
            return k[0]
        k = self.res.run_kinds()
        return k[0] if len(k) == 1 else ""

    def ranked(self, block):
        """The block's done rows of good status, best first by the kind's ranking (the file's /kinds:
        trajectory by E, IK by iterations then error); ties by run id. Returns (row indices, the
        ranking metric names)."""
        meaning = self.res.kind_meaning(self.kind(block))
        keys = [k for k in meaning.get("ranking", []) if k in self.t]
        rows = self.rows(block)
        rows = rows[np.isin(self.t["status"][rows], meaning.get("good_statuses", []))]
        cols = [self.t["run_id"][rows]] + [np.nan_to_num(np.asarray(self.t[k][rows], dtype=float), nan=np.inf)
                                            for k in reversed(keys)]
        return rows[np.lexsort(cols)], keys


def metadata_section(res, view):
    m = res.meta
    n = len(view.done)
    done = int(view.done.sum())
    n_hist = res.history_count()
    items = [("study_name", m.get("study_name", "")), ("study file", res.f["study"].attrs.get("path", "")),
             ("engine_version", m.get("engine_version", "")), ("created", m.get("created", "")),
             ("format_version", m.get("format_version", "")), ("study_sha256", m.get("study_sha256", "")),
             ("runs", n), ("done", done), ("not done", n - done), ("blocks", len(view.block_names)),
             ("histories", n_hist), ("landscapes", len(res.landscapes())),
             ("optimizations", len(res.optimizations()))]
    items = [(k, v.decode() if isinstance(v, bytes) else v) for k, v in items]
    rows = "".join(f'<tr><th class="s">{esc(k)}</th><td class="s" data-key="{esc(k)}">{esc(fmt(v))}</td></tr>'
                   for k, v in items)
    note = ("" if done == n else f'<p class="caption capped">{n - done} of {n} runs are not done yet (a sweep still '
            "writing, or one that stopped): the report shows the done rows only.</p>")
    return (f'<div class="scroll"><table id="meta-table"><tbody>{rows}</tbody></table></div>{note}'
            f'<h3>Study file</h3><pre class="study" id="study-text">{esc(res.study_text)}</pre>')


def status_section(view):
    """Runs per block and status (done rows), plus the rows not done yet."""
    statuses = []
    for kind in view.res.run_kinds():
        statuses += [s for s in view.res.kind_meaning(kind).get("statuses", []) if s not in statuses]
    present = set(view.t["status"][view.done].tolist())
    extra = sorted(s for s in present if s not in statuses and s)
    shown = [s for s in statuses if s in present] + extra
    columns = [("block", ""), ("kind", ""), ("runs", ""), ("done", "")] + [(s, "") for s in shown] + [("not done", "")]
    rows = []
    for b in view.block_names:
        all_rows, done_rows = view.rows(b, done=False), view.rows(b)
        st = view.t["status"][done_rows]
        rows.append([b, view.kind(b), len(all_rows), len(done_rows)] + [int(np.sum(st == s)) for s in shown]
                    + [len(all_rows) - len(done_rows)])
    good = " and ".join(f"{'/'.join(view.res.kind_meaning(k).get('good_statuses', []))} ({k})"
                        for k in view.res.run_kinds())
    good = f"{good} are the successful statuses." if good else ""
    return table(columns, rows, "status-table", text_columns=("block", "kind")) + \
        f'<p class="caption">Runs per block and status, counted over the done rows. {good}</p>'


def varying_parameters(view, block, rows):
    """The block's parameters (of its kind) that take more than one value over its done rows, and the
    fixed ones with their value."""
    kind = view.kind(block)
    varying, fixed = [], []
    for c in view.res.parameters(kind or None):
        v = view.t[c][rows]
        if v.dtype.kind == "f":
            n = np.unique(np.round(v[np.isfinite(v)], 12)).size
        else:
            n = len(set(v.tolist()))
        (varying if n > 1 else fixed).append(c)
    return varying, fixed


def shown_metrics(view, block, rows):
    kind = view.kind(block)
    out = []
    for c in view.res.metrics(kind or None):
        v = view.t[c][rows]
        held = np.isfinite(v) if v.dtype.kind == "f" else (v != -1) if v.dtype.kind in "iu" else \
            np.array([len(str(x)) > 0 for x in v], dtype=bool)
        if held.any():
            out.append(c)
    return out


def best_section(view, n_best):
    parts = []
    for b in view.block_names:
        ranked, keys = view.ranked(b)
        rows_done = view.rows(b)
        if not len(rows_done):
            continue
        kind = view.kind(b)
        good = "/".join(view.res.kind_meaning(kind).get("good_statuses", []))
        top = ranked[:n_best]
        varying, fixed = varying_parameters(view, b, rows_done)
        metrics = shown_metrics(view, b, rows_done)
        t = view.t
        columns = [("rank", ""), ("run_id", ""), ("status", "")] + [(c, t.units[c]) for c in varying] + \
                  [(c, t.units[c]) for c in metrics]
        rows = [[i + 1, int(t["run_id"][r]), t["status"][r]] + [t[c][r] for c in varying] + [t[c][r] for c in metrics]
                for i, r in enumerate(top)]
        fixed_text = ", ".join(f"{c} = {fmt(t[c][rows_done[0]])}{(' ' + t.units[c]) if t.units[c] else ''}"
                               for c in fixed if fmt(t[c][rows_done[0]]) not in ("", "–"))
        order = " then ".join(keys) if keys else "run id"
        cap = (f"The {len(top)} best of the block's {len(ranked)} {good} runs ({len(rows_done)} done), "
               f"smallest {order} first. " if len(top) else f"No {good} run among the block's {len(rows_done)} "
               "done runs. ")
        if fixed_text:
            cap += f"Fixed in this block: {esc(fixed_text)}."
        parts.append(f'<h3>Block {esc(b)} ({esc(kind)})</h3>'
                     + (table(columns, rows, f"best-{b}", text_columns=("status",) + tuple(
                         c for c in varying if t[c].dtype.kind == "O")) if len(top) else "")
                     + f'<p class="caption">{cap}</p>')
    return "".join(parts)
