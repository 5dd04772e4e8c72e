"""Snakemake's HTML report (report.html, `make report-html`) in a real browser: headless
Chromium (selenium, chromedriver) opens the report of the shared build from a local
HTTP server on 127.0.0.1 and walks it as a reader does, by clicking.

The report is one self-contained file: Snakemake inlines its scripts (Tailwind's "Play
CDN" script, React, vega, vega-lite, vega-embed, from the snakemake package's assets)
and every attached file as a ``data:`` URI, so it needs no network. Checked: every
request the page makes stays on the local server (the DevTools network log: any
``http(s)``/``ws(s)`` URL not on it fails; ``data:`` URIs and Chromium's own ``chrome:``
pages are not requests over the network), and Chromium resolves no other host name
(``--host-resolver-rules``), so nothing can leave the machine even if the report asked.

In every view the tests open: no error in the browser's console (one exception, below),
no raw ``\\(``/``\\[`` TeX and no LaTeX label of the paper (``fig:``, ``eq:``, ...,
report_html.INTERNAL_LABEL) in the visible text outside code, every image loaded
(``naturalWidth > 0``). The workflow view draws the rule graph (vega), the statistics
their two charts; each rule's panel opens; the search box finds a scene's four files.
Every category, subcategory and result is listed: each result of the report is reached
by clicking its row (and, for the figures, the PDF/PNG toggle), its caption opens, and
its view button shows it: a PNG figure as an image of the file's own pixel size, a PDF
in a frame of its ``data:`` URI, a dataset or scene file as a download link.
Screenshots (the front page, a figure, its caption, the statistics, a tall figure) are
saved to ``FILIPPOV_BROWSER_SHOTS=DIR`` or to the run's temporary folder, with the time
`snakemake --report` took (report-seconds.txt).

The one console error let through: Chromium asks every server for ``/favicon.ico`` on
its own when a page declares no icon (report.html declares none: checked), and our
server has none, so the console shows a 404 for it: not the report's doing. The
inlined Tailwind script warns (a warning, not an error) that cdn.tailwindcss.com should
not be used in production: that is the Play CDN script, inlined, and nothing is fetched.

The template centres a figure in a pane as high as the window, so the top of a figure
taller than the window (the tallest of the build: fig12_period_adding.png, 1000 px, in
a viewport about 860 px high) lay above the pane, out of reach of its scroll bar; the
project's stylesheet (workflow/report/report.css, ``--report-stylesheet``) centres it
"safe" instead, and test_a_tall_figure_shows_its_top holds.

The report is made here with `snakemake --report` from the `workflow_build` fixture's
build (tests/conftest.py; ``FILIPPOV_TEST_BUILD=DIR`` reuses a finished build of this
tree). Chromium and chromedriver: as tests/test_docs_browser.py (skipped without them,
a failure with ``FILIPPOV_BROWSER_TEST=1``).
"""
import json
import os
import struct
import time
from pathlib import Path

import pytest

# the same browser, the same skip-or-fail when it is missing (at import), the same flags
from test_docs_browser import SHOTS, chromium, console_errors, served

from conftest import report_args, run_snakemake
from filippov_paper.report_html import INTERNAL_LABEL
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.common.keys import Keys  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

TEX = ("\\(", "\\)", "\\[", "\\]")
# network schemes; data: URIs and chrome:// (Chromium's own pages) are no network
NETWORK = ("http:", "https:", "ws:", "wss:", "ftp:")

# the text a reader sees (shown text nodes, not code: rule code may hold anything), the
# images with their state, what is shown in the content pane
VIEW_REPORT = """
const walk = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
const shown = [];
for (let t = walk.nextNode(); t; t = walk.nextNode()) {
  const p = t.parentElement;
  if (!t.textContent.trim() || p.closest('pre, code, script, style')) continue;
  if (!p.getClientRects().length || getComputedStyle(p).visibility === 'hidden') continue;
  shown.push(t.textContent.trim());
}
const frame = document.querySelector('iframe');
return {
  text: shown.join('\\n'),
  images: [...document.images].map(i => [(i.getAttribute('src') || '').slice(0, 60),
                                         i.complete, i.naturalWidth, i.naturalHeight]),
  content: app.state.content, contentPath: app.state.contentPath || null,
  resultPath: app.state.resultPath || null, navbarMode: app.state.navbarMode,
  frame: frame ? frame.getAttribute('src') : null,
};
"""


@pytest.fixture(scope="module")
def report(workflow_build, tmp_path_factory):
    """report.html of the shared build, `snakemake --report` timed; its folder holds
    nothing else (the server serves only it)."""
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    out = tmp_path_factory.mktemp("report-html-browser") / "report.html"
    t0 = time.perf_counter()
    rep = run_snakemake(work, *report_args(out), timeout=900)
    seconds = time.perf_counter() - t0
    assert rep.returncode == 0, rep.stdout[-3000:] + rep.stderr[-3000:]
    return {"path": out, "work": work, "seconds": seconds}


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    folder = Path(os.environ.get(SHOTS) or tmp_path_factory.mktemp("screenshots"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@pytest.fixture(scope="module")
def server(report):
    with served(report["path"].parent) as url:
        yield url


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    """test_docs_browser's browser, with the DevTools network log and no name resolved
    but 127.0.0.1's."""
    driver = chromium(tmp_path_factory.mktemp("chromium-profile"),
                      "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1",
                      logs=("browser", "performance"), page_load_timeout=120)
    yield driver
    driver.quit()


def requests(driver) -> list[str]:
    """The URL of every request and navigation since the last call (the DevTools log).
    Navigations count as well: Debian's Chromium opens its first tab, with a new
    profile, at https://start.duckduckgo.com/ (a navigation with no request logged for
    it; --host-resolver-rules stops it here, and the logs are emptied before a test)."""
    urls = []
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message["method"] == "Network.requestWillBeSent":
            urls.append(message["params"]["request"]["url"])
        elif message["method"] in ("Network.webSocketCreated", "Page.frameStartedNavigating"):
            urls.append(message["params"]["url"])
    return urls


def errors(driver, server) -> list[str]:
    """The console's errors, less the browser's own request for /favicon.ico (see the
    module docstring)."""
    return [m for m in console_errors(driver)
            if not m.startswith(f"{server}favicon.ico - Failed to load resource")]


def view(driver) -> dict:
    return driver.execute_script(VIEW_REPORT)


def problems_in(got: dict) -> list[str]:
    found = []
    for tex in TEX:
        if tex in got["text"]:
            at = got["text"].index(tex)
            found.append(f"raw TeX {tex}: {got['text'][max(0, at - 40):at + 40]!r}")
    for m in INTERNAL_LABEL.finditer(got["text"]):
        found.append(f"LaTeX label: {got['text'][max(0, m.start() - 40):m.end() + 40]!r}")
    found += [f"image not loaded: {src}" for src, complete, width, _ in got["images"]
              if not (complete and width > 0)]
    return found


def png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", head[16:24])


def click(driver, xpath: str):
    """A click on the element, dispatched to it: the menu animates its width when its
    mode changes (transition-all), so a click at the element's place, as selenium's
    own click, can land beside it while the menu is still moving."""
    element = WebDriverWait(driver, 30).until(lambda d: d.find_element(By.XPATH, xpath))
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'}); "
                          "arguments[0].click()", element)


def settled(driver, condition: str):
    """Waits until the JavaScript expression ``condition`` is true (React renders on
    its own schedule after a click)."""
    WebDriverWait(driver, 30).until(lambda d: d.execute_script(f"return !!({condition})"))


def open_report(driver, server):
    driver.get(server + "report.html")
    settled(driver, "typeof app !== 'undefined' && document.querySelector('nav')")


def menu_item(label: str) -> str:
    return f"//nav//li/a[span[normalize-space()={json.dumps(label)}]]"


def test_the_report_loads_offline_and_cleanly(report, server, browser, shots,
                                              record_property):
    record_property("snakemake_report_seconds", round(report["seconds"], 1))
    (shots / "report-seconds.txt").write_text(f"{report['seconds']:.1f}\n")
    html = report["path"].read_text(errors="replace")
    # no icon declared: the browser's own /favicon.ico request is its doing (see above)
    assert 'rel="icon"' not in html and "rel='icon'" not in html
    browser.get_log("browser"), requests(browser)   # start with empty logs
    open_report(browser, server)
    # the workflow view: the description and the rule graph, drawn by vega
    settled(browser, "document.querySelector('#rulegraph svg, #rulegraph canvas')")
    got = view(browser)
    assert got["content"] == "rulegraph", got["content"]
    assert "Reproduction of every figure" in got["text"], got["text"][:2000]
    for label in ("Workflow", "Statistics", "About", "Datasets", "Figures", "Scene files",
                  "Reproduction report"):
        assert label in got["text"].split("\n"), (label, got["text"][:500])
    assert problems_in(got) == []
    assert browser.save_screenshot(str(shots / "report-front.png"))
    # the statistics (vega-lite charts) and the about panel (the inlined packages)
    click(browser, menu_item("Statistics"))
    settled(browser, "document.querySelector('#runtimes svg, #runtimes canvas')"
                     " && document.querySelector('#timeline svg, #timeline canvas')")
    assert problems_in(view(browser)) == []
    assert browser.save_screenshot(str(shots / "report-statistics.png"))
    click(browser, menu_item("About"))
    settled(browser, "app.state.navbarMode === 'reportinfo'")
    assert problems_in(view(browser)) == []
    # each rule's panel (the rule graph's nodes open it; its code, in <pre>, not judged)
    rules = browser.execute_script("return Object.keys(rules)")
    assert {"compute", "plot", "paper"} <= set(rules), rules
    for rule in rules:
        browser.execute_script("app.setView({navbarMode: 'ruleinfo', ruleinfo: arguments[0]})",
                               rule)
        settled(browser, "app.state.navbarMode === 'ruleinfo'")
        assert problems_in(view(browser)) == [], rule
    # the search box: every result whose path holds the term, one row each
    term = "fig05_thetalt0mfs"
    browser.execute_script("app.setView({navbarMode: 'menu'})")
    box = browser.find_element(By.XPATH, "//nav//input[@placeholder='Search...']")
    box.send_keys(term, Keys.ENTER)
    settled(browser, "app.state.navbarMode === 'searchresults'"
                     " && document.querySelector('nav table tbody tr')")
    rows = browser.execute_script("return [...document.querySelectorAll('nav table tbody tr')]"
                                  ".map(r => r.innerText)")
    hits = browser.execute_script("return Object.keys(results).filter(p => p.includes("
                                  "arguments[0]))", term)
    assert len(hits) == 4 and len(rows) == len(hits), (hits, rows)
    assert all(term in row for row in rows), rows
    assert problems_in(view(browser)) == []
    assert errors(browser, server) == []
    sent = requests(browser)
    assert server + "report.html" in sent, sent
    away = [url for url in sent if url.startswith(NETWORK) and not url.startswith(server)]
    assert away == [], away


def test_every_result_is_listed_and_shows(report, server, browser, shots):
    browser.get_log("browser"), requests(browser)
    open_report(browser, server)
    categories = browser.execute_script("return categories")
    results = browser.execute_script(
        "return Object.fromEntries(Object.entries(results).map(([p, r]) =>"
        " [p, {mime: r.mime_type, labels: r.labels, uri: r.data_uri.slice(0, 80),"
        "      n: r.data_uri.length}]))")
    work = report["work"]
    # the report has a figure for every PNG of the build (test_report_html checks the
    # full list of datasets and figures from the build's summary)
    figures = {p.relative_to(work).as_posix() for p in (work / "figures").glob("*.png")}
    assert figures and figures <= set(results), sorted(figures - set(results))
    reached, problems = set(), {}

    def check_here(where):
        got = view(browser)
        found = problems_in(got) + [f"console: {m}" for m in errors(browser, server)]
        if found:
            problems.setdefault(where, []).extend(found)
        return got

    def back_to_table(category, subcategory, value):
        """Back to the subcategory's table by the app's own call (its toggle, re-mounted,
        at its default again: clicked to ``value``)."""
        browser.execute_script("app.setView({navbarMode: 'subcategory', "
                               "category: arguments[0], subcategory: arguments[1]})",
                               category, subcategory)
        settled(browser, "document.querySelector('nav table tbody tr')")
        if value is not None:
            click(browser, f"//nav//fieldset//label[normalize-space()={json.dumps(value)}]")

    def visit_rows(category, subcategory, value):
        """Every row of the subcategory's table as shown now: its caption (the info
        button), then its view button."""
        rows = len(browser.find_elements(By.XPATH, "//nav//table/tbody/tr"))
        assert rows, (category, subcategory)
        for i in range(rows):
            row = f"(//nav//table/tbody/tr)[{i + 1}]"
            click(browser, f"{row}/td[last()]//a[2]")   # the info button: the caption
            settled(browser, "app.state.navbarMode === 'resultinfo'")
            got = check_here(f"{category}/{subcategory} row {i + 1}")
            path = got["resultPath"]
            assert path in categories[category][subcategory], (category, subcategory, path)
            reached.add(path)
            if path == "figures/fig05_thetalt0mfs.png":
                assert browser.save_screenshot(str(shots / "report-caption-fig05.png"))
            back_to_table(category, subcategory, value)
            entry, eye = results[path], f"{row}/td[last()]//a[1]"
            if entry["mime"] == "image/png":
                click(browser, eye)
                img = "document.querySelector('#app img[src^=\"data:image/png\"]')"
                settled(browser, f"{img} && {img}.complete")
                size = browser.execute_script(
                    f"const i = {img}; return [i.naturalWidth, i.naturalHeight, i.src.length]")
                assert size[2] == entry["n"], path   # this result's own data
                if tuple(size[:2]) != png_size(work / path):
                    problems.setdefault(path, []).append(
                        f"image {size[:2]}, file {png_size(work / path)}")
                if path == "figures/fig05_thetalt0mfs.png":
                    assert browser.save_screenshot(str(shots / "report-figure-fig05.png"))
            elif entry["mime"] == "application/pdf":
                click(browser, eye)
                settled(browser, "document.querySelector('iframe')")
                src = browser.execute_script("const s = document.querySelector('iframe')"
                                             ".getAttribute('src'); return [s.slice(0, 80), "
                                             "s.length]")
                assert src == [entry["uri"], entry["n"]], (path, src)
            else:   # a download link (not clicked: it would save the file)
                link = browser.execute_script(
                    "const a = document.evaluate(arguments[0], document, null, 9, null)"
                    ".singleNodeValue; const h = a.getAttribute('href');"
                    "return [h.slice(0, 80), h.length, a.getAttribute('download')]", eye)
                assert link == [entry["uri"], entry["n"], path.rsplit("/", 1)[-1]], (path, link)
            check_here(path)

    def visit_subcategory(category, subcategory):
        # a label with two values, each on half the results (PDF/PNG), is a toggle:
        # each value shows its half of the results
        values = [t.text for t in browser.find_elements(By.XPATH, "//nav//fieldset//label")]
        for value in values or [None]:
            if value is not None:
                click(browser, f"//nav//fieldset//label[normalize-space()={json.dumps(value)}]")
            visit_rows(category, subcategory, value)

    for category in sorted(categories):
        subs = sorted(categories[category])
        for subcategory in subs:
            browser.execute_script("app.setView({navbarMode: 'menu'})")
            click(browser, menu_item(category))
            if len(subs) > 1:   # a folder per subcategory
                check_here(category)
                click(browser, menu_item(subcategory))
            settled(browser, "app.state.navbarMode === 'subcategory'")
            check_here(f"{category}/{subcategory}")
            visit_subcategory(category, subcategory)
    assert problems == {}, problems
    assert reached == set(results), {"not reached": sorted(set(results) - reached)}
    sent = requests(browser)
    away = [url for url in sent if url.startswith(NETWORK) and not url.startswith(server)]
    assert away == [], away


def test_the_checks_see_tex_labels_and_broken_images():
    got = {"text": "Fig. 5\nsee fig:retmaps and \\(x\\)", "images": [["data:x", True, 0, 0]]}
    found = problems_in(got)
    assert any(f.startswith("raw TeX \\(") for f in found), found
    assert any(f.startswith("LaTeX label") and "fig:retmaps" in f for f in found), found
    assert any(f.startswith("image not loaded") for f in found), found
    assert problems_in({"text": "Fig. 5, Eq. (18), M_+ = {y = x1}", "images": []}) == []


def test_a_tall_figure_shows_its_top(report, server, browser, shots):
    work = report["work"]
    tallest = max((p.relative_to(work).as_posix() for p in (work / "figures").glob("*.png")),
                  key=lambda name: png_size(work / name)[1])
    open_report(browser, server)
    if png_size(work / tallest)[1] <= browser.execute_script("return window.innerHeight"):
        pytest.skip(f"no figure taller than the window (the tallest: {tallest})")
    browser.execute_script(
        "app.setView({content: 'img', contentPath: results[arguments[0]].data_uri})", tallest)
    img = "document.querySelector('#app img[src^=\"data:image/png\"]')"
    settled(browser, f"{img} && {img}.complete")
    # scrolled as far up as the pane goes
    top = browser.execute_script(f"const i = {img}, pane = i.closest('.overflow-auto');"
                                 "pane.scrollTop = 0;"
                                 "return [i.getBoundingClientRect().top, "
                                 "pane.getBoundingClientRect().top]")
    assert browser.save_screenshot(str(shots / "report-tall-figure.png"))
    assert top[0] >= top[1], \
        f"{tallest}: its top {top[1] - top[0]:.0f} px above the pane, out of reach"
