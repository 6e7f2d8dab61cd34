"""report.html in a real browser: headless Chromium (Debian's ``chromium``) opens it from disk, every
figure renders with a non-zero size and fills the content column, the page asks no host for anything, and a
screenshot is kept."""

import shutil
from pathlib import Path

import pytest

from simparity.comparisons.cli.main import main
from simparity.core.model.results import REPORT_HTML_FILE

ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
"""Where the screenshot is written (kept by CI as a test artifact; ignored by git)."""

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
MIN_FIGURE_PIXELS = 100
"""[CSS px] Every side of a rendered figure: a figure that failed to render collapses to 0 (or to the
height of its caption, ~15); a drawn one is hundreds of pixels wide."""
MIN_COLUMN_FRACTION = 0.9
"""Of the content column's width, every figure's rendered width at least: a figure fills the column (scaled from its
viewBox), where the SVG's own width in pt (10 in: 960 CSS px) once left it at ~70 % of it and its legend hard to read.
Less than 1 for a scrollbar or rounding."""
PAGE_WIDTH = 1400
"""[CSS px] The browser window: wider than the page's 1200 px column, as a desktop reader's."""
MIN_SCREENSHOT_BYTES = 10_000
"""A blank full-page PNG compresses to a few kilobytes; a page of text and figures is far larger."""


def _browser() -> str:
    found = next((path for name in BROWSERS if (path := shutil.which(name))), None)
    if found is None:
        pytest.skip(f"no browser to open the report: none of {', '.join(BROWSERS)} on PATH (.ci/run installs Debian's "
                    "chromium)")
    return found


@pytest.mark.slow
def test_report_renders_in_chromium_without_network(tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (a test dependency) is not installed")
    browser_path = _browser()
    run = tmp_path / "run"
    # core and the closed forms alone (MuJoCo is not what the page is checked for): still six figures, three each
    assert main(["run", "dzhanibekov", "lecture-2link-ik", "--quick", "--repeats", "0", "--jobs", "1",
                 "--engines", "core,analytic", "--out", str(run)]) == 0
    page_url = (run / REPORT_HTML_FILE).resolve().as_uri()
    requests: list[str] = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=browser_path, args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": PAGE_WIDTH, "height": 900})
        page.on("request", lambda request: requests.append(request.url))
        page.goto(page_url, wait_until="load")
        sizes = page.eval_on_selector_all(
            "figure.plot svg", "els => els.map(e => { const r = e.getBoundingClientRect(); return [r.width, r.height]; })")
        names = page.eval_on_selector_all("figure.plot", "els => els.map(e => e.dataset.name)")
        column = page.evaluate("() => { const s = getComputedStyle(document.body); "
                               "return document.body.clientWidth - parseFloat(s.paddingLeft) - parseFloat(s.paddingRight); }")
        ARTIFACTS.mkdir(exist_ok=True)
        screenshot = ARTIFACTS / "report.png"
        page.screenshot(path=str(screenshot), full_page=True)
        browser.close()
    assert len(sizes) == len(names) >= 5, names
    assert all(width > MIN_FIGURE_PIXELS and height > MIN_FIGURE_PIXELS for width, height in sizes), list(zip(names, sizes))
    narrow = [(name, width) for name, (width, _) in zip(names, sizes) if width < MIN_COLUMN_FRACTION * column]
    assert narrow == [], f"figures narrower than {MIN_COLUMN_FRACTION:.0%} of the {column:.0f} px column"
    assert requests == [page_url], f"the page asked for more than itself: {requests[1:]}"
    assert screenshot.stat().st_size > MIN_SCREENSHOT_BYTES
