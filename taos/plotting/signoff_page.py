"""The flight sign-off page (``signoff.html``) of a :class:`taos.flight.signoff.SignOff`.

Rendering only. The page opens with the verdict in words, states whether the requirements are
notional, then gives the pass/fail table (each case, each requirement: limit, value, margin,
where it binds), the requirements and the provenance, and the interactive Nichols chart (Plotly,
the plotly.js bundle inline: works offline) of the first failing case (else the first case).
"""

from __future__ import annotations

import html


def _h(x) -> str:
    return html.escape(str(x))


def _n(x) -> str:
    return "–" if x is None else f"{x:.4g}"   # (JSON null: no value, or unbounded; "where" says which)


def _limit(x) -> str:
    return f"[{x[0]:.4g}, {x[1]:.4g}]" if isinstance(x, (list, tuple)) else f"{x:.4g}"


_CSS = """body{font:14px/1.45 system-ui,sans-serif;margin:24px auto;max-width:1150px;color:#1d1f23}
h1{font-size:22px}h2{font-size:18px;margin-top:28px;border-bottom:1px solid #ccd}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccd;padding:3px 8px;text-align:right}
th{background:#eef}td:first-child,th:first-child,td.l{text-align:left}.note{color:#555;font-size:12px}
.verdict{font-size:15px;padding:8px 12px;border-left:4px solid}.verdict.pass{border-color:#1a7f37}
.verdict.fail{border-color:#c62828}.pass{color:#1a7f37}.fail{color:#c62828}tr.fail td{background:#fdecea}
.notional{background:#fff4d6;border:1px solid #e0b84c;padding:4px 10px;display:inline-block}"""


def render_signoff_html(so) -> str:
    """The page of ``so`` (a :class:`taos.flight.signoff.SignOff`)."""
    from . import interactive as ia

    d = so.to_dict()
    req = d["requirements"]
    cls = "pass" if so.passed else "fail"
    rows = []
    for c in d["cases"]:
        for k in c["checks"]:
            ok = "pass" if k["pass"] else "fail"
            rows.append(f"<tr class='{ok}'><td>{_h(c['case'])}</td><td class='l'>{_h(k['requirement'])}</td>"
                        f"<td>{_limit(k['limit'])} {_h(k['unit'])}</td><td>{_n(k['value'])}</td><td>{_n(k['margin'])}</td>"
                        f"<td><b>{'pass' if k['pass'] else 'FAIL'}</b></td><td class='l'>{_h(k['where'])}</td></tr>")
    verdicts = "".join(f"<tr><td>{_h(c['case'])}</td><td class='l'>{_h(c['lco_verdict'])}</td></tr>" for c in d["cases"])
    reqrows = "".join(f"<tr><td>{_h(k)}</td><td>{_h(v)}</td></tr>" for k, v in req.items())
    shown = next((c for c in so.cases if not c.passed), so.cases[0])
    nichols = ia.page_html(ia.nichols_figure(shown.report.prediction,
                                             title=f"Nichols chart, case {shown.label}"), "nichols")
    notional = ('<p class="notional"><b>NOTIONAL requirements</b>: illustrative limits, not a program\'s '
                'stated requirements.</p>' if so.requirements.notional else "")
    prov = d["provenance"]
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Flight sign-off: {_h(req['name'])}</title><style>{_CSS}</style>
{ia.plotly_script()}</head>
<body>
<h1>Flight sign-off: {_h(req['name'])}</h1>
<p id="signoff-verdict" class="verdict {cls}"><b>{_h(so.text())}</b></p>
{notional}
<h2>Pass/fail by case and requirement</h2>
<table id="signoff-table"><tr><th>case</th><th>requirement</th><th>limit</th><th>value</th><th>margin</th><th>result</th>
<th>where it binds</th></tr>{''.join(rows)}</table>
<p class="note">{_h(d['margin_definition'])}. Gain margins are the low-frequency margins of the loop with the TVC
describing function, L0 N(A, ·), signed (negative: the loop already lacks that much gain at that amplitude);
phase margins the smallest over the gain crossovers; the LCO limits apply to every self-sustained cycle
(describing function and, when run, the time domain).</p>
<h2>Limit-cycle verdict by case</h2><table>{verdicts}</table>
<h2>Requirements</h2><table>{reqrows}</table>
<h2>Nichols chart</h2>
{nichols}
<p class="note">Interactive: hover a locus for its frequency, gain and phase; drag to zoom, double-click to reset.</p>
<p class="note">taos {_h(prov.get('package_version', ''))}; model {_h(prov.get('model_file', ''))}
(sha256 {_h(str(prov.get('model_sha256', ''))[:12])}…).</p>
</body></html>
"""
