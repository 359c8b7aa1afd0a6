"""The interactive Green Run report (issue 29 point 3): Plotly plots embedded in the page with the
plotly.js bundle inline (no script from the network), opened by headless Chromium with the network
blocked; a real mouse move over a point of the Bode plot shows its values in a hover label, which
must read the numbers of the report's HDF5 (another output of the same run)."""

from __future__ import annotations

import json
import re
import subprocess

import h5py
import numpy as np
import pytest

from tests.conftest import MODELS
from tests.test_report import SHORT_PROFILE as PROFILE
from tests.test_viewer import CHROMIUM_FLAGS, chromium

pytestmark = pytest.mark.slow


#: moves the mouse over point ``POINT`` of the linear piston-gain curve of the pitch Bode plot
#: (a real ``mousemove`` on the plot's drag layer, at the point's pixel position) and writes what
#: the page shows in its hover label, and which plots were drawn, into <pre id="hover-probe">
PROBE = """<script>
window.addEventListener('load', function () {
  var out = document.createElement('pre'); out.id = 'hover-probe'; document.body.appendChild(out);
  setTimeout(function () {
    try {
      var gd = document.getElementById('bode-pitch');
      var tr = gd._fullData.filter(function (t) { return t.name === 'linear' && t.xaxis === 'x' && t.yaxis === 'y'; })[0];
      var x = tr.x[POINT], y = tr.y[POINT];
      var xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
      var drag = gd.querySelector('.nsewdrag[data-subplot="xy"]');
      var box = drag.getBoundingClientRect();
      drag.dispatchEvent(new MouseEvent('mousemove', {clientX: box.left + xa.d2p(x), clientY: box.top + ya.d2p(y),
                                                      bubbles: true, view: window}));
      setTimeout(function () {
        out.textContent = JSON.stringify({
          plotly: typeof Plotly, drawn: Array.from(document.querySelectorAll('.js-plotly-plot')).map(function (d) {
            return d.id + ':' + d.querySelectorAll('.main-svg .scatterlayer .trace').length; }),
          hover: Array.from(gd.querySelectorAll('.hoverlayer .hovertext')).map(function (e) { return e.textContent; })});
      }, 400);
    } catch (e) { out.textContent = JSON.stringify({error: String(e)}); }
  }, 600);
});
</script>"""
POINT = 20


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """``taos greenrun`` run in this process (these tests read the page it writes, not the
    process: tests/test_report.py runs the console script)."""
    from taos.cli import main

    tmp = tmp_path_factory.mktemp("interactive")
    prof = tmp / "short.toml"
    prof.write_text(PROFILE)
    out = tmp / "report"
    assert main([str(a) for a in ("greenrun", MODELS / "rs25_hotfire.toml", "--profile", prof, "--out", out,
                                  "--data", MODELS / "data" / "greenrun_hotfire_synthetic.csv", "--quiet")]) == 0
    return out


def _without_plotly_bundle(page: str) -> str:
    i = page.index('<script type="text/javascript">')
    return page[:i] + page[page.index("</script>", i):]


def test_page_embeds_plotly_once_and_loads_nothing_from_the_network(report):
    page = (report / "index.html").read_text()
    assert page.count("<script type=\"text/javascript\">/**\n* plotly.js") == 1   # the bundle, inline, once
    assert "<script src" not in page.lower() and "<link" not in page.lower()
    rest = _without_plotly_bundle(page)
    assert "cdn.plot.ly" not in rest and "require(" not in rest
    assert set(re.findall(r"https?://[^\s\"'()<>&\\]+", rest)) <= {"http://www.w3.org/1999/xhtml"}
    for div in ("bode-pitch", "bode-yaw", "timehist"):
        assert f'id="{div}"' in page
    # the static figures stay (print, the documentation's pictures): four PNGs, in a closed section
    static = page[page.index('<details id="static-figures">'):]
    assert len(re.findall(r'<img [^>]*src="data:image/png;base64,', static)) == 4
    # the verdict in words comes first
    assert page.index('id="spec-verdict"') < page.index('id="bode-pitch"')


def test_browser_opens_the_report_offline_and_reads_a_hover_value(report, tmp_path):
    page = (report / "index.html").read_text()
    i = page.rindex("</body>")
    probe = tmp_path / "probe.html"
    probe.write_text(page[:i] + PROBE.replace("POINT", str(POINT)) + page[i:])
    args = [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1200,1300",
            "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9",   # offline
            "--virtual-time-budget=6000", "--dump-dom", probe.as_uri()]
    r = subprocess.run(args, capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="hover-probe">(.*?)</pre>', r.stdout, re.S)
    assert m, f"no probe output (exit {r.returncode}): {r.stderr[-800:]}"
    got = json.loads(m.group(1).replace("&amp;", "&").replace("&lt;", "<").replace("&gt;", ">"))
    assert "error" not in got, got
    assert got["plotly"] == "object"                          # the inline bundle ran without a network
    drawn = dict(d.split(":") for d in got["drawn"])
    assert set(drawn) == {"bode-pitch", "bode-yaw", "timehist"} and all(int(n) >= 4 for n in drawn.values())
    with h5py.File(report / "greenrun.h5") as h5:
        f = float(h5["freqresp/pitch/linear/freq_hz"][POINT])
        gain = 20 * np.log10(abs(h5["freqresp/pitch/linear/piston"][POINT]))
    assert len(got["hover"]) == 1, got["hover"]
    text = got["hover"][0]
    assert text.startswith("linear") and f"f = {f:.4g} Hz" in text, text
    assert f"piston gain = {gain:.2f} dB" in text, text
