"""Every bundled report, written once: every link it makes leads to a file that is there, and —
in a headless Chromium, as a reader sees it — no legend covers a curve, no 3-D scene is
covered, and the play buttons cover neither the slider nor its ticks."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

pytest.importorskip("plotly")

from poinsot.app.cli import main
from poinsot.app.job import run_scenario
from poinsot.app.scenario import list_examples, load_example


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """``{name: report.html}`` of every bundled example and of ``poinsot polhodes`` (with and
    without ω0), written as the command line writes them (plotly.js shared beside them)."""
    root = tmp_path_factory.mktemp("reports")
    out = {}
    for name in list_examples():
        scenario = load_example(name)
        scenario.outputs["figures"] = False  # the PNGs are not linked; the report's are drawn
        run_scenario(scenario, root / name, plotlyjs="shared")
        out[name] = root / name / "report.html"
    for name, extra in (("polhodes", []), ("polhodes-omega0", ["--omega0", "0.01", "1", "0.01"])):
        args = ["polhodes", "--moments", "1", "2", "3", *extra, "--out", str(root / name)]
        assert main([*args, "--quiet", "--plotly-js", "shared"]) == 0
        out[name] = root / name / "report.html"
    return out


_LINK = re.compile(r"""(?:href|src)\s*=\s*["']([^"']+)["']""")


def test_every_link_of_every_report_leads_to_a_file(reports):
    checked = 0
    for name, page in reports.items():
        text = page.read_text(encoding="utf-8")
        for target in _LINK.findall(text):
            if target.startswith(("data:", "http://", "https://", "#", "javascript:")):
                continue
            assert (page.parent / target).is_file(), f"{name}: report links {target!r}"
            checked += 1
        assert "summary.json" in text or name.startswith("polhodes")
    assert checked >= len(reports)  # at least the raw numbers of each


def test_polhodes_report_links_its_own_numbers(reports):
    text = reports["polhodes-omega0"].read_text(encoding="utf-8")
    assert "href='polhodes.json'" in text and "summary.json" not in text


def test_ensemble_report_links_the_dataset_it_wrote(reports):
    page = reports["tennis-racket-ensemble"]
    assert (page.parent / "ensemble.nc").is_file()
    assert 'href="ensemble.nc"' in page.read_text(encoding="utf-8")


def test_a_data_file_not_written_is_not_linked(tmp_path):
    scenario = load_example("turntable-spin-up")
    scenario.outputs["data"] = False
    run_scenario(scenario, tmp_path / "o", plotlyjs="cdn")
    text = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert not (tmp_path / "o" / "relative.csv").exists() and "relative.csv" not in text


# --------------------------------------------------------------------------- in a browser
def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


#: Measures, once the plots are drawn, every legend box, every trace's bounding box (the union
#: of its drawn lines, fills and markers), every 3-D scene, the play buttons and the slider's
#: ticks and labels, and writes them into the page as JSON.
_MEASURE = """
<script>
function box(e) { const r = e.getBoundingClientRect();
  return [r.left, r.top, r.right, r.bottom]; }
function union(boxes) { boxes = boxes.filter(b => b[2] - b[0] > 0.5 || b[3] - b[1] > 0.5);
  if (!boxes.length) return null;
  return [Math.min(...boxes.map(b => b[0])), Math.min(...boxes.map(b => b[1])),
          Math.max(...boxes.map(b => b[2])), Math.max(...boxes.map(b => b[3]))]; }
function measure() {
  const plots = [];
  document.querySelectorAll('div.js-plotly-plot').forEach(div => {
    const legends = [...div.querySelectorAll('g')]
      .filter(g => /^legend[0-9]*$/.test(g.getAttribute('class') || ''))
      .map(g => { const bg = g.querySelector('rect.bg'); return box(bg || g); });
    const traces = [...div.querySelectorAll('g.trace')].map(t => union(
      [...t.querySelectorAll('path.js-line, path.js-fill, path.point')].map(box)))
      .filter(b => b);
    const scenes = [...div.querySelectorAll('div[id^="scene"]')].map(box);
    const buttons = [...div.querySelectorAll('g.updatemenu-button')].map(box);
    const ticks = [...div.querySelectorAll('text.slider-label, rect.slider-rail-rect')]
      .map(box);
    plots.push({id: div.id, legends, traces, scenes, buttons, ticks});
  });
  const pre = document.createElement('pre');
  pre.id = 'layout-check';
  pre.textContent = JSON.stringify(plots);
  document.body.appendChild(pre);
}
window.addEventListener('load', () => setTimeout(measure, 2500));
</script>
"""


def _overlap(a, b, tol=1.0):
    """The area (px²) that two boxes share, beyond ``tol`` px at the edges."""
    w = min(a[2], b[2]) - max(a[0], b[0]) - tol
    h = min(a[3], b[3]) - max(a[1], b[1]) - tol
    return max(w, 0) * max(h, 0)


def _measure(browser, page: Path) -> list:
    probe = page.with_name("layout-check.html")
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", _MEASURE + "</body>"),
                     encoding="utf-8")  # fmt: skip
    flags = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--window-size=1300,1500",
             "--virtual-time-budget=20000"]  # fmt: skip
    dom = subprocess.run([*flags, "--dump-dom", probe.as_uri()], capture_output=True, text=True,
                         timeout=240).stdout  # fmt: skip
    probe.unlink()
    found = re.search(r'<pre id="layout-check">(.*?)</pre>', dom, re.S)
    assert found, f"{page}: the page did not finish drawing"
    return json.loads(found.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def test_no_legend_covers_a_curve_in_a_browser(reports):
    browser = _chromium()
    if browser is None:
        if os.environ.get("CI"):
            pytest.fail("CI must install Chromium (.ci/run) for the report tests")
        pytest.skip("no Chromium on this machine")
    problems = []
    measured = 0
    for name, page in reports.items():
        if "plotly" not in page.read_text(encoding="utf-8")[:20000] and name in (
            "tennis-racket-ensemble", "turntable-spin-up", "gyroscope-on-vehicle",
            "hodograph-bound"):  # fmt: skip
            continue  # pages of PNG figures: their legends are checked in test_legends.py
        for plot in _measure(browser, page):
            measured += 1
            for legend in plot["legends"]:
                for k, trace in enumerate(plot["traces"]):
                    if _overlap(legend, trace) > 0:
                        problems.append(f"{name} {plot['id']}: a legend covers trace {k}")
                for scene in plot["scenes"]:
                    if _overlap(legend, scene) > 0:
                        problems.append(f"{name} {plot['id']}: a legend covers the 3-D scene")
            for button in plot["buttons"]:
                for tick in plot["ticks"]:
                    if _overlap(button, tick, tol=0.0) > 0:
                        problems.append(f"{name} {plot['id']}: a button covers the slider")
    assert measured > 30
    assert not problems, problems
