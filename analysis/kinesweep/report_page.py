"""The HTML of kinesweep.report: the page skeleton (style, table of contents, the script that draws
the figures and records JavaScript errors), tables and figure placeholders. Plotly's JavaScript is
embedded (gzip in base64, with each figure's data), so the page works offline. Run with /usr/bin/python3."""
import html
import json
import math

import numpy as np

STYLE = """
body { font-family: system-ui, 'DejaVu Sans', sans-serif; margin: 0 auto; max-width: 1400px; padding: 0 16px 40px;
       color: #1d2330; background: #ffffff; }
h1 { font-size: 1.5em; margin: 18px 0 4px; } h2 { font-size: 1.25em; margin: 0 0 8px; border-bottom: 2px solid #3b6fb6;
       padding-bottom: 3px; } h3 { font-size: 1.05em; margin: 16px 0 4px; }
section { margin: 22px 0; }
nav ul { margin: 4px 0; padding-left: 20px; columns: 2; } nav a { color: #2b5c9e; }
.sub { color: #555c6b; margin: 0 0 10px; }
.caption { color: #3a4150; font-size: 0.9em; margin: 4px 0 12px; max-width: 1100px; }
.capped { color: #9a4b00; font-weight: 600; }
.scroll { overflow-x: auto; max-width: 100%; }
table { border-collapse: collapse; font-size: 0.86em; margin: 4px 0 8px; }
th, td { border: 1px solid #c9cfda; padding: 3px 7px; text-align: right; white-space: nowrap; }
th { background: #e8eef8; position: sticky; top: 0; } td.s, th.s { text-align: left; }
tr:nth-child(even) td { background: #f6f8fc; }
pre.study { background: #f4f6fa; border: 1px solid #d5dbe6; padding: 8px 10px; font-size: 0.82em; max-height: 420px;
            overflow: auto; }
.plot { width: 100%; min-height: 200px; }
#ks-status { display: none; }
body.only > header, body.only > nav { display: none; }
"""

# Runs first (before plotly's script): records errors and console.error calls, for the reader of a
# broken page and for the tests (written into #ks-status once the figures are drawn).
ERROR_COLLECTOR = """
window.ksErrors = [];
window.addEventListener('error', function (e) { window.ksErrors.push(String(e.message || e)); });
window.addEventListener('unhandledrejection', function (e) { window.ksErrors.push('rejection: ' + String(e.reason)); });
(function () { var ce = console.error; console.error = function () {
  window.ksErrors.push(Array.prototype.map.call(arguments, String).join(' ')); return ce.apply(console, arguments); }; })();
"""

# Shows only the section named by '#only=ID' (for screenshots of one section); inflates plotly's
# bundle and runs it; then draws every figure from its data island and writes the outcome into
# #ks-status (data-ready="1"). Plotly and the figures' JSON are stored gzip-compressed in base64
# (script elements of type application/gzip), inflated by the browser's DecompressionStream.
LOADER = """
(function () {
  var m = /^#only=([\\w-]+)$/.exec(window.location.hash);
  if (m) {
    document.body.classList.add('only');
    document.querySelectorAll('body > section').forEach(function (s) { s.style.display = s.id === m[1] ? '' : 'none'; });
  }
  function inflate(id) {
    var bin = atob(document.getElementById(id).textContent.trim());
    var bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Response(new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'))).text();
  }
  var drawn = 0;
  function report() {
    var st = document.getElementById('ks-status');
    st.textContent = JSON.stringify({plots: drawn, errors: window.ksErrors});
    st.setAttribute('data-ready', '1');
  }
  function draw(div) {
    return inflate(div.id + '-data').then(function (text) {
      var spec = JSON.parse(text);
      spec.config = Object.assign({displaylogo: false, responsive: true,
                                   modeBarButtonsToRemove: ['sendDataToCloud']}, spec.config || {});
      return Plotly.newPlot(div, spec.data, spec.layout, spec.config);
    }).then(function () { drawn += 1; }, function (e) { window.ksErrors.push('figure ' + div.id + ': ' + e); });
  }
  var plots = Array.prototype.filter.call(document.querySelectorAll('div.plot'), function (div) {
    var sec = div.closest('section');
    return !(sec && sec.style.display === 'none');
  });
  if (!plots.length) { report(); return; }
  if (typeof DecompressionStream === 'undefined') {
    window.ksErrors.push('this browser lacks DecompressionStream (Chrome 80, Firefox 113, Safari 16.4 have it): no figures');
    report();
    return;
  }
  inflate('plotly-js').then(function (code) {
    var s = document.createElement('script');
    s.text = code;
    document.head.appendChild(s);
    return Promise.all(plots.map(draw));
  }).then(report, function (e) { window.ksErrors.push('plotly: ' + e); report(); });
})();
"""


# zlib level of the figures' data: 6 takes half the time of 9 for about 1 % more bytes (a 3.8 MB
# landscape figure: 0.27 s, 1.256 MB against 0.51 s, 1.245 MB).
FIGURE_LEVEL = 6


def gzip_island(element_id, text, level=9):
    """A script element holding `text` gzip-compressed in base64 (inflated by LOADER)."""
    return island(element_id, gzip_base64(text, level))


def gzip_base64(text, level=9):
    import base64
    import gzip
    return base64.b64encode(gzip.compress(text.encode("utf-8"), compresslevel=level, mtime=0)).decode("ascii")


def island(element_id, data):
    """The script element of gzip_island from its base64 data (compressed already)."""
    return f'<script type="application/gzip" id="{esc(element_id)}">{data}</script>'


def esc(s):
    return html.escape(str(s), quote=True)


def fmt(v, digits=6):
    """A table cell's text: NaN as an en dash, integers as such, floats to `digits` significant digits."""
    if v is None:
        return "–"
    if isinstance(v, (str, bytes)):
        return v.decode() if isinstance(v, bytes) else v
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if not math.isfinite(v):
        return "–"
    return f"{v:.{digits}g}"


def exact(v):
    """The cell's value at full precision, for the data-v attribute (readers and tests compare it)."""
    if isinstance(v, (str, bytes)):
        return v.decode() if isinstance(v, bytes) else v
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v))


def header(name, unit):
    return f"{name} [{unit}]" if unit else name


def table(columns, rows, css_id=None, text_columns=()):
    """An HTML table: columns = [(name, unit)], rows = lists of values. Every cell carries its exact
    value in data-v; text columns (names) are left-aligned."""
    out = [f'<div class="scroll"><table{f" id={chr(34)}{esc(css_id)}{chr(34)}" if css_id else ""}>', "<thead><tr>"]
    for name, unit in columns:
        cls = ' class="s"' if name in text_columns else ""
        out.append(f'<th{cls} data-col="{esc(name)}">{esc(header(name, unit))}</th>')
    out.append("</tr></thead><tbody>")
    for row in rows:
        out.append("<tr>")
        for (name, _), v in zip(columns, row):
            cls = ' class="s"' if name in text_columns else ""
            out.append(f'<td{cls} data-v="{esc(exact(v))}">{esc(fmt(v))}</td>')
        out.append("</tr>")
    out.append("</tbody></table></div>")
    return "".join(out)


class Rounded(list):
    """A list that _clean passes as it is: JSON-ready already (floats rounded to at most 7 significant
    digits, None for NaN, nested plain lists), e.g. a figure's hover values at 5 digits."""


def _floats(values):
    """A list of Python floats to 7 significant digits, NaN and infinities as None."""
    isfinite = math.isfinite
    return [float(f"{v:.7g}") if isfinite(v) else None for v in values]


def _clean(o):
    t = type(o)
    if t is Rounded:
        return o
    if t is float:
        return float(f"{o:.7g}") if math.isfinite(o) else None
    if t is list or t is tuple:
        if all(type(v) is float for v in o):  # the common case, without a call per number
            return _floats(o)
        return [_clean(v) for v in o]
    if t is dict:
        return {str(k): _clean(v) for k, v in o.items()}
    if t is str or t is int or t is bool or o is None:
        return o
    if isinstance(o, np.ndarray):
        if o.dtype.kind == "f" and o.ndim >= 1:
            flat = _floats(o.ravel().tolist())
            for n in reversed(o.shape[1:]):  # nested as tolist() would (rows of the last axis first)
                flat = [flat[i:i + n] for i in range(0, len(flat), n)]
            return flat
        return _clean(o.tolist())
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    if isinstance(o, (float, np.floating)):
        o = float(o)
        return float(f"{o:.7g}") if math.isfinite(o) else None
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, np.bool_):
        return bool(o)
    return o


def figure(fid, fig, caption, title=None):
    """A figure placeholder, its data island (the JSON of data and layout, plain plotly dicts, NaN ->
    null; gzip in base64) and its caption. Floats are kept to 7 significant digits."""
    text = json.dumps(_clean(fig), allow_nan=False, separators=(",", ":"))
    h = f"<h3>{esc(title)}</h3>" if title else ""
    return (f'{h}<div class="plot" id="{esc(fid)}"></div>{gzip_island(fid + "-data", text, FIGURE_LEVEL)}'
            f'<p class="caption">{caption}</p>')


def page(title, subtitle, sections, plotly_js, plotly_base64=None):
    """The whole page: sections = [(id, heading, body html)], in order; the table of contents lists them.
    plotly_base64: plotly_js compressed already (gzip_base64), e.g. from a cache."""
    toc = "".join(f'<li><a href="#{esc(sid)}">{esc(head)}</a></li>' for sid, head, _ in sections)
    body = "".join(f'<section id="{esc(sid)}"><h2>{esc(head)}</h2>{html_}</section>' for sid, head, html_ in sections)
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{esc(title)}</title><style>{STYLE}</style>"
            f"<script>{ERROR_COLLECTOR}</script>"
            f"{island('plotly-js', plotly_base64) if plotly_base64 else gzip_island('plotly-js', plotly_js)}</head><body>"
            f"<header><h1>{esc(title)}</h1><p class=\"sub\">{subtitle}</p></header>"
            f"<nav><strong>Contents</strong><ul>{toc}</ul></nav>{body}"
            "<pre id=\"ks-status\" data-ready=\"0\"></pre>"
            f"<script>{LOADER}</script></body></html>\n")
