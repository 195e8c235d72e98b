"""``report.html``: every run writes one self-contained page with its PNGs, key figures and tables, never NaN.

The page of the femur scene is rendered in headless Chromium (Debian package
``chromium``, installed by ``.ci/run``), which reports whether every image
loaded and what the key-figure cards read.
"""
import base64
import csv
import html
import json
import os
import re
import shutil
import subprocess

import pytest

from ngcontact import cli
from ngcontact.output import writer
from ngcontact.output.report import Outcome, build_report
from ngcontact.output.report_html import fmt, render

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GEOMETRIES = os.path.join(ROOT, "geometries")
#: the smallest shipped scene: a manufactured plane-strain check, orders 1 only (about 2 s)
SMALL_SCENE = open(os.path.join(GEOMETRIES, "verify_elasticity.toml")).read().replace(
    "orders = [1, 2, 3]", "orders = [1]")
DATA_URI = re.compile(r"data:image/png;base64,([A-Za-z0-9+/=]+)")
NON_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


def visible_text(page: str) -> str:
    """The page's text and attributes without the embedded images' base64 (which may spell 'nan')."""
    return DATA_URI.sub("data:image/png;base64,", page)


def run(tmp_path, monkeypatch, scene_path):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("NGCONTACT_THREADS", "1")   # the page is the subject here: one core of the shared two
    out = tmp_path / "out"
    assert cli.main(["run", str(scene_path), "--out", str(out), "--quiet"]) == 0
    return out, json.loads((out / "report.json").read_text()), (out / "report.html").read_text(encoding="utf-8")


def test_a_run_writes_report_html_with_every_png_embedded_the_key_figures_and_the_tables(tmp_path, monkeypatch):
    scene_path = tmp_path / "small.toml"
    scene_path.write_text(SMALL_SCENE)
    out, rep, page = run(tmp_path, monkeypatch, scene_path)
    assert "report.html" in json.loads((out / writer.MANIFEST).read_text())["files"]
    embedded = [base64.b64decode(m) for m in DATA_URI.findall(page)]
    pngs = [n for n in rep["files"] if n.endswith(".png")]
    assert pngs, "the scene draws at least one figure"
    for name in pngs:
        assert (out / name).read_bytes() in embedded, f"{name} is not embedded byte for byte"
    assert len(embedded) == len(pngs)
    assert html.escape(rep["title"]) in page
    for effect in rep["effects"]:
        assert f'<span class="chip">{effect}</span>' in page
    cards = dict(re.findall(r'<div class="label">([^<]*)</div><div class="value figure-value">([^<]*)</div>', page))
    assert cards["verified"] == fmt(rep["results"]["verified"])
    assert cards["largest rate deviation"] == fmt(rep["results"]["max_rate_deviation"])
    assert cards["unknowns (ndof)"] == str(rep["ndof"])
    for name in (n for n in rep["files"] if n.endswith(".csv")):
        with open(out / name, newline="") as fh:
            header, first = list(csv.reader(fh))[:2]
        assert f'<h3 id="table-{name}">' in page
        assert "".join(f"<th>{h}</th>" for h in header) in page, f"{name}: header not tabulated"
        assert fmt(float(first[-1])) in page
    assert "http://" not in visible_text(page).replace('xmlns="http://www.w3.org/2000/svg"', "")
    assert not NON_FINITE.search(visible_text(page))


def macro_report(tmp_path, **results):
    png = tmp_path / "interface.png"
    png.write_bytes(b"\x89PNG fake")
    res = {"maxima": {"pressure": {"pressure": 1450934.925, "s": 0.05}},
           "strength": {"safety_factor": 4.449061732, "holds": True}, "status_counts": {"stick": 3, "open": 1}}
    res.update(results)
    return build_report(kind="macro", title='Stem <b>"fit"</b> & bone', scene={"kind": "macro"},
                        effects=("elasticity",), outcome=Outcome(results=res, plots={"interface": None}),
                        timings={"total": 1.5}, version="0")


def test_key_figures_of_a_macro_report_are_formatted_with_units_and_the_title_is_escaped(tmp_path):
    page = render(macro_report(tmp_path), str(tmp_path), ["interface.png"])
    cards = dict(re.findall(r'<div class="label">([^<]*)</div><div class="value figure-value">([^<]*)</div>', page))
    assert cards["peak pressure"] == "1.451 MPa" and cards["at s"] == "50 mm"
    assert cards["safety factor (eq. 78)"] == "4.4491" and cards["strength holds"] == "yes"
    assert cards["closed interface samples"] == "3 of 4 (0.75)"
    assert "<title>Stem &lt;b&gt;&quot;fit&quot;&lt;/b&gt; &amp; bone</title>" in page and "<b>\"fit\"" not in page


def test_the_page_names_where_the_batches_ran_and_says_nothing_of_a_run_without_batches(tmp_path):
    report = macro_report(tmp_path)
    report["compute"] = {"executor": "dask", "workers": 4, "scheduler": "tcp://10.0.0.5:8786",
                         "batches": [{"label": "loads", "members": 16, "seconds": 9.25}]}
    cards = dict(re.findall(r'<div class="label">([^<]*)</div><div class="value figure-value">([^<]*)</div>',
                            render(report, str(tmp_path), ["interface.png"])))
    assert cards["batches ran on"] == "4 Dask worker threads at tcp://10.0.0.5:8786"
    assert cards["batches"] == "loads: 16 in 9.25 s"
    report["compute"] = {"executor": "local", "workers": 2, "batches": []}
    assert "batches ran on" not in render(report, str(tmp_path), ["interface.png"])


def test_the_page_says_where_each_batch_of_a_local_pool_went_and_why(tmp_path):
    report = macro_report(tmp_path)
    report["compute"] = {"executor": "local", "workers": 2, "batches": [
        {"label": "ensemble", "members": 8, "seconds": 1.5, "executor": "serial", "decision": "too small"},
        {"label": "loads", "members": 16, "seconds": 4.0, "executor": "local", "decision": "repays"}]}
    cards = dict(re.findall(r'<div class="label">([^<]*)</div><div class="value figure-value">([^<]*)</div>',
                            render(report, str(tmp_path), ["interface.png"])))
    assert cards["batches"] == "ensemble: 8 in 1.5 s (in this process); loads: 16 in 4 s (on the workers)"
    assert cards["why there"] == "ensemble: too small; loads: repays"


def test_a_non_finite_number_is_refused_and_a_failing_page_writes_nothing(tmp_path, monkeypatch):
    for bad in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="non-finite"):
            fmt(bad)
    rep = macro_report(tmp_path)
    rep["results"]["strength"]["safety_factor"] = float("nan")     # past the report's own check
    with pytest.raises(ValueError, match="non-finite"):
        render(rep, str(tmp_path), [])
    # report.html is one of the run's files: when it cannot be written, none is
    out = tmp_path / "run"

    def broken(*args):
        raise ValueError("report.html: non-finite number nan")

    monkeypatch.setattr(writer, "write_html", broken)
    outcome = Outcome(results={"value": 1.0}, tables={"curve": (["x"], [(1.0,)])})
    with pytest.raises(ValueError):
        writer.write_outputs(str(out), macro_report(tmp_path), outcome)
    assert not out.exists() and os.listdir(tmp_path) == ["interface.png"]


# ---------------------------------------------------------------- headless Chromium
PROBE = """<script>
window.addEventListener("load", function () {
  var images = Array.prototype.map.call(document.images, function (i) {
    return {alt: i.alt, loaded: i.complete && i.naturalWidth > 0, width: i.naturalWidth};
  });
  var cards = Array.prototype.map.call(document.querySelectorAll(".card"), function (c) {
    return [c.querySelector(".label").innerText, c.querySelector(".value").innerText];
  });
  var probe = document.createElement("pre");
  probe.id = "probe";
  probe.textContent = JSON.stringify({images: images, cards: cards, text: document.body.innerText});
  document.body.appendChild(probe);
});
</script>"""


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.skip("headless Chromium is not installed (Debian package 'chromium'; .ci/run installs it)")


def test_the_femur_report_renders_in_headless_chromium_with_every_image_loaded(tmp_path, monkeypatch):
    browser = chromium()
    out, rep, page = run(tmp_path, monkeypatch, os.path.join(GEOMETRIES, "femur_stem.toml"))
    probe_page = out / "probe.html"           # beside the report, so that relative links resolve alike
    probe_page.write_text(page.replace("</body>", PROBE + "</body>"), encoding="utf-8")
    dom = subprocess.run([browser, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
                          f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=2000",
                          "--dump-dom", probe_page.as_uri()],
                         capture_output=True, text=True, timeout=180, check=True).stdout
    found = re.search(r'<pre id="probe">(.*?)</pre>', dom, re.DOTALL)
    assert found, "the page's load handler did not run: " + dom[-500:]
    status = json.loads(html.unescape(found.group(1)))
    pngs = sorted(n for n in rep["files"] if n.endswith(".png"))
    assert sorted(i["alt"] for i in status["images"]) == pngs and len(pngs) >= 4
    assert all(i["loaded"] and i["width"] > 100 for i in status["images"]), status["images"]
    cards = dict(status["cards"])
    assert {"peak pressure", "safety factor (eq. 78)", "law", "closed interface samples"} <= set(cards)
    assert cards["safety factor (eq. 78)"] == fmt(rep["results"]["strength"]["safety_factor"])
    assert not [c for c in status["cards"] if NON_FINITE.search(c[1]) or not c[1].strip()], status["cards"]
    assert not NON_FINITE.search(status["text"]), "the rendered page shows a non-finite number"
    assert not NON_FINITE.search(visible_text(page)), "the page's source holds a non-finite number"


def test_a_long_csv_table_shows_its_first_rows_and_counts_them_all(tmp_path):
    from ngcontact.output.report_html import MAX_TABLE_ROWS, csv_table
    with open(tmp_path / "surface_load0.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["x", "pressure"])
        w.writerows([i, 0.5 * i] for i in range(MAX_TABLE_ROWS + 123))
    page = csv_table(str(tmp_path), "surface_load0.csv")
    assert f"the first {MAX_TABLE_ROWS} of {MAX_TABLE_ROWS + 123} rows" in page
    assert f"<td>{MAX_TABLE_ROWS - 1}</td>" in page and f"<td>{MAX_TABLE_ROWS}</td>" not in page
    (tmp_path / "short.csv").write_text("a,b\n1,2\n3,4\n")
    assert "2 rows" in csv_table(str(tmp_path), "short.csv")
