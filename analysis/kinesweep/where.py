"""Row filters with the syntax of `kinesweep query --where` (engine/cli/query_where.cpp), for the plot
scripts. Run with Debian's /usr/bin/python3 (numpy).

    from kinesweep import where as kswhere
    mask = kswhere.select(table, ["method=lm,newton", "1e-3<=lambda<1", "E<40 | status=diverged"])

One expression is one or more alternatives separated by `|` (a row matches when any holds); several
expressions must all hold. An alternative is

    COL OP VALUE          OP: = == != < <= > >=   (VALUE OP COL too, except = and !=)
    COL=V1,V2,...         any of the values (!=: none of them)
    COL=LO..HI            LO <= COL <= HI (numeric columns; != : below LO or above HI)
    LO<COL<=HI            chained range (two of < <=, or two of > >=)

Text columns compare as text (< > lexicographically), numeric ones as numbers (= within 1e-9
relative, `nan` matches NaN); with degrees=True an angle column (unit "rad") is compared in degrees.
A bad expression raises WhereError, whose message names the expression (and, for an unknown column,
the closest column name and the valid ones).
"""
import numpy as np

RAD2DEG = 180.0 / np.pi
OP_CHARS = "<>=!"
OPS = {"=": "eq", "==": "eq", "!=": "ne", "<": "lt", "<=": "le", ">": "gt", ">=": "ge"}
FLIP = {"lt": "gt", "le": "ge", "gt": "lt", "ge": "le", "eq": "eq", "ne": "ne"}
SYNTAX = "; expected COL OP VALUE (OP one of = != < <= > >=), COL=A,B,C, COL=LO..HI or LO<=COL<=HI"


class WhereError(ValueError):
    """A --where expression that cannot be parsed or names an unknown column."""


def edit_distance(a, b):
    """Levenshtein distance: insertions, deletions and substitutions of one character."""
    prev = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        cur = [i] + [0] * len(b)
        for j in range(1, len(b) + 1):
            cur[j] = min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1]))
        prev = cur
    return prev[len(b)]


def did_you_mean(word, candidates):
    """The engine's one "did you mean" rule (engine/common/did_you_mean.hpp): the candidate nearest to
    `word` by case-insensitive edit distance when within max(2, len(word) // 2) edits (the first of
    equals), else the one candidate the word begins (3 characters or more); None otherwise."""
    w = word.lower()
    best, pick = None, None
    for c in candidates:
        d = edit_distance(w, c.lower())
        if best is None or d < best:
            best, pick = d, c
    if pick is not None and pick != word and best <= max(2, len(w) // 2):
        return pick
    starts = [c for c in candidates if len(w) >= 3 and len(c) > len(w) and c.lower().startswith(w)]
    return starts[0] if len(starts) == 1 else None


def unknown_column_message(name, columns, where):
    m = f"unknown column '{name}'{where}"
    close = did_you_mean(name, columns)
    if close:
        m += f"; did you mean '{close}'?"
    return m + "\nvalid columns: " + ", ".join(columns)


def _is_text(v):
    return np.asarray(v).dtype.kind in "OSU"


def _column(table, name, degrees):
    v = np.asarray(table[name])
    if _is_text(v):
        return np.array([x.decode() if isinstance(x, bytes) else str(x) for x in v], dtype=object)
    units = getattr(table, "units", {}) or {}
    v = v.astype(float)
    return v * RAD2DEG if degrees and units.get(name) == "rad" else v


def _number(s, col, expr):
    t = s.strip()
    try:
        if not t or "_" in t:
            raise ValueError
        return float(t)
    except ValueError:
        raise WhereError(f"--where '{expr}': column {col} is numeric; '{t}' is not a number") from None


def _num_eq(x, v):
    if np.isnan(v):
        return np.isnan(x)
    with np.errstate(invalid="ignore"):
        return (x == v) | (np.abs(x - v) <= 1e-9 * np.maximum(np.abs(x), abs(v)))


def _test(x, op, values):
    """Boolean mask of the column values `x` against one condition."""
    if x.dtype == object:
        if op == "eq":
            return np.isin(x, values)
        if op == "ne":
            return ~np.isin(x, values)
        v = values[0]
        return np.array([{"lt": a < v, "le": a <= v, "gt": a > v, "ge": a >= v}[op] for a in x], dtype=bool)
    if op == "eq":
        return np.logical_or.reduce([_num_eq(x, v) for v in values]) if values else np.zeros(len(x), bool)
    if op == "ne":
        return ~np.logical_or.reduce([_num_eq(x, v) for v in values]) if values else np.ones(len(x), bool)
    with np.errstate(invalid="ignore"):
        return {"lt": x < values[0], "le": x <= values[0], "gt": x > values[0], "ge": x >= values[0]}[op]


def _tokens(expr):
    """Operands and the operators between them (runs of < > = !)."""
    operands, ops, cur, i = [], [], "", 0
    while i < len(expr):
        if expr[i] in OP_CHARS:
            j = i
            while j < len(expr) and expr[j] in OP_CHARS:
                j += 1
            operands.append(cur.strip())
            cur = ""
            ops.append(expr[i:j])
            i = j
        else:
            cur += expr[i]
            i += 1
    operands.append(cur.strip())
    return operands, ops


def parse_alternative(expr, columns, text_columns, shown=None):
    """One alternative -> list of groups of conditions (col, op, values); a row matches when every group
    holds, a group when any of its conditions holds. `text_columns`: the set of text columns.
    `shown`: the expression as written (for messages)."""
    shown = shown or expr
    operands, raw_ops = _tokens(expr)
    if not raw_ops or len(raw_ops) > 2:
        raise WhereError(f"--where '{shown}': cannot parse{SYNTAX}")
    ops = []
    for s in raw_ops:
        if s not in OPS:
            raise WhereError(f"--where '{shown}': unknown operator '{s}'{SYNTAX}")
        ops.append(OPS[s])
    if any(not s for s in operands):
        raise WhereError(f"--where '{shown}': missing operand{SYNTAX}")

    def make(col, op, rhs):
        text = col in text_columns
        if not text and ".." in rhs and op in ("eq", "ne"):
            lo_s, hi_s = rhs.split("..", 1)
            lo, hi = _number(lo_s, col, shown), _number(hi_s, col, shown)
            if op == "eq":
                return [[(col, "ge", [lo])], [(col, "le", [hi])]]
            return [[(col, "lt", [lo]), (col, "gt", [hi])]]
        values = [v.strip() for v in rhs.split(",")] if op in ("eq", "ne") else [rhs]
        if not text:
            values = [_number(v, col, shown) for v in values]
        return [[(col, op, values)]]

    where = f" in --where '{shown}'"
    if len(ops) == 1:
        if operands[0] in columns:
            return make(operands[0], ops[0], operands[1])
        if operands[1] in columns and ops[0] not in ("eq", "ne"):
            return make(operands[1], FLIP[ops[0]], operands[0])
        raise WhereError(unknown_column_message(operands[0], columns, where))
    col = operands[1]
    if col not in columns:
        raise WhereError(unknown_column_message(col, columns, where))
    up = all(o in ("lt", "le") for o in ops)
    down = all(o in ("gt", "ge") for o in ops)
    if not (up or down):
        raise WhereError(f"--where '{shown}': a range needs two < / <= (or two > / >=){SYNTAX}")
    return make(col, FLIP[ops[0]], operands[0]) + make(col, ops[1], operands[2])


def alternatives(expr):
    """The alternatives of one expression (split at |), each trimmed."""
    return [a.strip() for a in expr.split("|")]


def parse(expr, columns, text_columns):
    """One expression -> list (alternatives) of lists of condition groups."""
    alts = alternatives(expr)
    if any(not a for a in alts):
        raise WhereError(f"--where '{expr}': an empty alternative around '|'{SYNTAX}, alternatives "
                         "separated by ' | '")
    return [parse_alternative(a, columns, text_columns, expr if len(alts) == 1 else f"{a}' of '{expr}")
            for a in alts]


def select(table, exprs, degrees=True, text_columns=None, rows=None):
    """Boolean mask over the rows of `table` (dict of column -> 1-D array; its .units, when present,
    tells angles: unit "rad") where every expression in `exprs` holds. Raises WhereError.
    `text_columns` and `rows` (the row count) spare reading every column of a table that reads its
    columns when asked (only those the expressions name are then read)."""
    columns = list(table.keys())
    n = rows if rows is not None else len(next(iter(table.values()))) if columns else 0
    text = set(text_columns) if text_columns is not None else {c for c in columns if _is_text(table[c])}
    mask = np.ones(n, dtype=bool)
    cache = {}
    for expr in exprs or []:
        any_alt = np.zeros(n, dtype=bool)
        for groups in parse(expr, columns, text):
            alt = np.ones(n, dtype=bool)
            for group in groups:
                g = np.zeros(n, dtype=bool)
                for col, op, values in group:
                    if col not in cache:
                        cache[col] = _column(table, col, degrees)
                    g |= _test(cache[col], op, values)
                alt &= g
            any_alt |= alt
        mask &= any_alt
    return mask


def unheld_value_notes(table, exprs):
    """For each text value of an = / != condition that no row of `table` holds: "no row has method =
    'lmm'; did you mean 'lm'?" (or the values the column holds, when few and none is close)."""
    columns = list(table.keys())
    text = {c for c in columns if _is_text(table[c])}
    notes, said = [], set()
    for expr in exprs or []:
        for groups in parse(expr, columns, text):
            for group in groups:
                for col, op, values in group:
                    if col not in text or op not in ("eq", "ne"):
                        continue
                    held = sorted(set(_column(table, col, False)))
                    if not held:
                        continue
                    for v in values:
                        if v in held or (col, v) in said:
                            continue
                        said.add((col, v))
                        m = f"no row has {col} = '{v}'"
                        close = did_you_mean(v, held)
                        if close:
                            m += f"; did you mean '{close}'?"
                        elif len(held) <= 12:
                            m += " (values: " + ", ".join(held) + ")"
                        notes.append(m)
    return notes


def where_argv(argv):
    """A command line with each `-w EXPR` / `--where EXPR` joined into `--where=EXPR`, so that argparse
    takes an expression starting with '-' (-10<alpha1A<10) as the option's value."""
    argv = list(argv)
    for i in range(len(argv) - 1, 0, -1):
        if argv[i - 1] in ("-w", "--where"):
            argv[i - 1:i + 1] = ["--where=" + argv[i]]
    return argv
