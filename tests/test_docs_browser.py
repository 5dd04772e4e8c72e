"""The documentation site in a real browser: headless Chromium (selenium, chromedriver)
loads every page of the built site from a local HTTP server on 127.0.0.1, with no
request beyond it (checked: every resource a page loads came from that server).

Every page: no error in the browser's console, MathJax has typeset every formula (each
``.math`` element holds a rendered ``mjx-container``, and no raw ``\\(`` or ``\\[`` TeX
is left in the text outside code), every image has loaded (``naturalWidth > 0``), every
resource came from the local server, and every code and output line fits its block at a
1400 px window (none hides behind the scroll bar at the bottom of a long block). The
search page finds pages for a query. Screenshots of the front page (wide and narrow
window) are saved to ``FILIPPOV_BROWSER_SHOTS=DIR`` or to the run's temporary folder.

The site is the ``docs_site`` fixture's (tests/conftest.py; ``FILIPPOV_DOCS_BUILD=DIR``
reads a built one). Chromium and chromedriver are Debian's packages ``chromium`` and
``chromium-driver``; without them the tests are skipped, except with
``FILIPPOV_BROWSER_TEST=1`` (set by a CI that installs them), where they fail.
"""
import contextlib
import functools
import http.server
import os
import shutil
import threading
from pathlib import Path

import pytest

HERE = "FILIPPOV_BROWSER_TEST"   # "1": a missing browser is a failure, not a skip
SHOTS = "FILIPPOV_BROWSER_SHOTS"
CHROMIUM = next(filter(None, map(shutil.which, ("chromium", "chromium-browser",
                                                "google-chrome"))), None)
CHROMEDRIVER = shutil.which("chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage", "--window-size=1400,1000")
QUERY, QUERY_HITS = "periodic orbit", {"tutorial.html", "generated/filippov.periodic_orbit.html"}

if not (CHROMIUM and CHROMEDRIVER):
    missing = "chromium" if not CHROMIUM else "chromedriver"
    message = (f"{missing} not found (Debian: apt-get install chromium chromium-driver)")
    if os.environ.get(HERE) == "1":
        pytest.fail(f"{HERE}=1 but {message}", pytrace=False)
    pytest.skip(message, allow_module_level=True)

selenium = pytest.importorskip("selenium", reason="selenium is pinned in requirements.lock")
from selenium import webdriver  # noqa: E402
from selenium.webdriver.support.ui import WebDriverWait  # noqa: E402

# run in the page once it has loaded: waits for MathJax's typesetting (when the page
# loads MathJax), then reports what the tests judge
PAGE_REPORT = """
const done = arguments[arguments.length - 1];
const report = () => {
  const body = document.body.cloneNode(true);
  body.querySelectorAll('pre, code, script, style, mjx-container, .highlight')
      .forEach(e => e.remove());
  const maths = [...document.querySelectorAll('.math')];
  const pres = [...document.querySelectorAll('pre')];
  done({
    mathjax: !!window.MathJax,
    maths: maths.length,
    typeset: maths.filter(e => e.querySelector('mjx-container')).length,
    mathjax_errors: document.querySelectorAll('mjx-merror, [data-mjx-error]').length,
    text: body.textContent,
    images: [...document.images].map(i => [i.getAttribute('src'), i.complete,
                                           i.naturalWidth]),
    wide: pres.filter(p => p.scrollWidth > p.clientWidth + 1)
              .map(p => [p.textContent.slice(0, 60), p.scrollWidth, p.clientWidth,
                         getComputedStyle(p).overflowX]),
    resources: performance.getEntriesByType('resource').map(r => r.name),
  });
};
if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
  MathJax.startup.promise.then(report, e => done({error: String(e)}));
} else { report(); }
"""


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@contextlib.contextmanager
def served(directory):
    """``directory`` served on 127.0.0.1 (a free port) while in the block: its URL."""
    handler = functools.partial(_Quiet, directory=str(directory))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}/"
    finally:
        httpd.shutdown()
        httpd.server_close()


def chromium(profile, *flags, logs=("browser",), page_load_timeout=60):
    """Headless Chromium (FLAGS and ``flags``, a new profile in ``profile``) under
    chromedriver, logging ``logs`` at every level."""
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in FLAGS + tuple(flags):
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {log: "ALL" for log in logs})
    driver = webdriver.Chrome(options=options,
                              service=webdriver.ChromeService(executable_path=CHROMEDRIVER))
    driver.set_page_load_timeout(page_load_timeout)
    driver.set_script_timeout(60)
    return driver


@pytest.fixture(scope="module")
def server(docs_site):
    with served(docs_site) as url:
        yield url


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    driver = chromium(tmp_path_factory.mktemp("chromium-profile"))
    yield driver
    driver.quit()


def site_pages(docs_site):
    return sorted(p.relative_to(docs_site).as_posix() for p in docs_site.rglob("*.html")
                  if "_sources" not in p.parts)


def console_errors(driver):
    return [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def test_every_page_loads_cleanly_with_its_math_typeset(docs_site, server, browser):
    pages = site_pages(docs_site)
    assert len(pages) > 20, pages
    problems, with_math = {}, 0
    browser.get_log("browser")   # start with an empty console
    for page in pages:
        browser.get(server + page)
        got = browser.execute_async_script(PAGE_REPORT)
        found = []
        if "error" in got:
            found.append(f"MathJax failed: {got['error']}")
        else:
            if got["maths"]:
                with_math += 1
                if not got["mathjax"]:
                    found.append("math but no MathJax")
            if got["typeset"] != got["maths"]:
                found.append(f"{got['maths'] - got['typeset']} of {got['maths']} formulas "
                             "not typeset")
            if got["mathjax_errors"]:
                found.append(f"{got['mathjax_errors']} MathJax errors")
            for tex in ("\\(", "\\)", "\\[", "\\]"):
                if tex in got["text"]:
                    at = got["text"].index(tex)
                    found.append(f"raw TeX {tex}: {got['text'][max(0, at - 40):at + 40]!r}")
            found += [f"image not loaded: {src}" for src, complete, width in got["images"]
                      if not (complete and width > 0)]
            found += [f"resource not from the site: {url}" for url in got["resources"]
                      if not url.startswith(server)]
            # at a 1400 px window every code and output line fits its block: none hides
            # behind a scroll bar at the bottom of a long block (and a wider one would
            # at least scroll, custom.css)
            found += [f"pre block wider than the page: {text!r} ({scroll} > {client} px, "
                      f"overflow-x {overflow})" for text, scroll, client, overflow in got["wide"]]
        found += [f"console: {message}" for message in console_errors(browser)]
        if found:
            problems[page] = found
    assert not problems, problems
    # the tutorial, the pipeline guide and the three examples have formulas
    assert with_math >= 5, with_math


def test_the_gallery_shows_a_figure_per_example(server, browser):
    # each thumbnail drawn as the browser decoded it: one different picture per script of
    # examples/, not sphinx-gallery's placeholder (the same picture under every name)
    n = len(list((Path(__file__).resolve().parents[1] / "examples").glob("*.py")))
    assert n >= 4
    browser.get(server + "auto_examples/index.html")
    thumbs = browser.execute_script("""
      return [...document.querySelectorAll('.sphx-glr-thumbcontainer img')].map(i => {
        const c = document.createElement('canvas');
        c.width = i.naturalWidth; c.height = i.naturalHeight;
        if (i.naturalWidth) c.getContext('2d').drawImage(i, 0, 0);
        return [i.getAttribute('src'), i.naturalWidth, c.toDataURL()];
      });""")
    assert len(thumbs) == n and all(width > 0 for _, width, _ in thumbs), \
        [thumb[:2] for thumb in thumbs]
    assert len({pixels for _, _, pixels in thumbs}) == n, [thumb[:2] for thumb in thumbs]


def test_search_finds_pages(server, browser):
    browser.get(server + "search.html?q=" + QUERY.replace(" ", "+"))
    # Sphinx lists the hits one at a time (a 5 ms timer each) and writes its summary
    # after the last: read the list only then, not at its first entry
    links = WebDriverWait(browser, 30).until(lambda d: d.execute_script(
        "const s = document.querySelector('#search-results .search-summary');"
        "if (!s || !/Search finished|did not match/.test(s.innerText)) return false;"
        "return [...document.querySelectorAll('#search-results ul.search li a')]"
        ".map(x => x.getAttribute('href'))"))
    hits = {link.split("?")[0].split("#")[0] for link in links}
    assert QUERY_HITS <= hits, sorted(hits)
    assert not console_errors(browser)


@pytest.mark.parametrize("width", [1400, 480])
def test_front_page_screenshot(server, browser, tmp_path_factory, width):
    folder = Path(os.environ.get(SHOTS) or tmp_path_factory.mktemp("screenshots"))
    folder.mkdir(parents=True, exist_ok=True)
    browser.set_window_size(width, 1000)
    try:
        browser.get(server + "index.html")
        # no search terms kept from an earlier search (sphinx_highlight.js stores them)
        browser.execute_script("localStorage.clear(); sessionStorage.clear()")
        browser.get(server + "index.html")
        assert browser.title.startswith("filippov")
        shot = folder / f"index-{width}px.png"
        assert browser.save_screenshot(str(shot))
        assert shot.read_bytes().startswith(b"\x89PNG") and shot.stat().st_size > 10_000
        # nothing wider than the window: no sideways scrolling of the page itself
        overflow = browser.execute_script(
            "return document.documentElement.scrollWidth - window.innerWidth")
        assert overflow <= 1, overflow
    finally:
        browser.set_window_size(1400, 1000)
    assert not console_errors(browser)
