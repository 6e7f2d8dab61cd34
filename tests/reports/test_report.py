"""The report of a real (small) run: Markdown led by the summary, figures written as SVG and PNG, a
self-contained HTML page that headless Chromium renders without the network, and ``simparity report`` on a copied run
with no engine importable."""

import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.scenes.library import builtin_paths
from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import REPORT_FILE, REPORT_HTML_FILE, SERIES_COLUMNS, ResultRow
from simparity.reports.content import build
from simparity.reports.tolerance_verdict import ToleranceVerdict
from simparity.reports.markdown import LINE_CHARS, to_markdown
from simparity.reports.store import read_run

DYNAMICS_SCENE = "dzhanibekov-first-flip"
"""The Dzhanibekov flip (dzhanibekov) over 3.5 s, not the quick profile's 5: through its first flip (the
middle axis's angular velocity changes sign at 2.94 s), every engine's orders as their theory says (measured: within
0.02), at 1,400 steps of its finest dt (above the 1,000 under which the quick profile adds every orientation
variant)."""
IK_SCENE = "few-targets-2link-ik"
"""The lecture's planar 2-link arm (lecture-2link-ik) with 8 random targets and every hard one: the IK section's
verdict, tables and three figures, with a fifth of the built-in scene's quick solves (its 50 random targets, each
solved iteratively by core and Pinocchio, took 6.5 of the run's 21 s of CPU)."""
CONTACT_SCENE = "first-bounces-k05"
"""ball-bounce-k05 over its first 1 s, not the 2 s to rest: its bounces at 0.45 s and 0.90 s give every engine's
measured restitution (core's backup exact at each dt, Pinocchio none: no contact), at two thirds of its cost."""
SMALLER = {DYNAMICS_SCENE: ("dzhanibekov", {"duration = 10.0": "duration = 3.5",
                                             "flips over (10 s)": "flips over (its first flip, 3.5 s)"}),
           IK_SCENE: ("lecture-2link-ik", {"count = 500": "count = 8"}),
           CONTACT_SCENE: ("ball-bounce-k05", {"duration = 2.0": "duration = 1.0",
                                               "bouncing to rest": "its first two bounces"})}
"""The run's smaller copies of built-in scenes: name -> (the built-in scene, each line part it replaces)."""
SCENES = ["iiwa-kinematics"]
"""The built-in scenes of the run, beside :data:`SMALLER`'s."""
ORDER_BAND = 0.5
"""Half the gap between neighbouring integer orders, as the shipped tolerances allow: an observed order
within it of the theoretical one confirms the theory; outside it, the theory is wrong for the scheme."""
MIN_FIGURE_BYTES = 1000
"""An SVG or PNG of an empty canvas is a few hundred bytes; a drawn figure (axes, ticks, lines) is tens of
kilobytes. Anything under this is a figure with nothing on it."""
MIN_PAGE_BYTES = 10_000
"""The page's styles and summary alone come to a few kilobytes; with its inline figures it is far larger."""


def _smaller_copy(folder: Path, name: str, scene: str, changes: dict[str, str]) -> str:
    """The path of a copy, in ``folder``, of the built-in ``scene``'s file named ``name`` with ``changes`` made."""
    text = builtin_paths()[scene].read_text(encoding="utf-8")
    for old, new in {f'name = "{scene}"': f'name = "{name}"', **changes}.items():
        assert text.count(old) == 1, (scene, old)  # the built-in file changed: update SMALLER
        text = text.replace(old, new)
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A quick run of a dynamics, an IK, a kinematics and a contact scene on the default engines, with its report:
    every test here reads it (the ones that render again do so on a copy)."""
    folder = tmp_path_factory.mktemp("report")
    files = [_smaller_copy(folder, name, *SMALLER[name]) for name in SMALLER]
    out = folder / "run"
    assert main(["run", *SCENES, *files, "--quick", "--repeats", "0", "--jobs", "1", "--out", str(out)]) == 0
    return out


@pytest.mark.slow
def test_markdown_starts_with_the_summary_and_links_existing_figures(run_dir):
    text = (run_dir / REPORT_FILE).read_text()
    headings = re.findall(r"^(#+) (.*)$", text, flags=re.M)
    assert headings[0] == ("#", "simparity report") and headings[1] == ("##", "Summary")
    summary = text.split("## Summary", 1)[1].split("\n## ", 1)[0]
    assert f"[{DYNAMICS_SCENE}](#{DYNAMICS_SCENE}-dynamics)" in summary and f"[{IK_SCENE}](#{IK_SCENE}-ik)" in summary
    page = (run_dir / REPORT_HTML_FILE).read_text()
    anchor = f"{DYNAMICS_SCENE}-dynamics"
    assert f'href="#{anchor}"' in page and f'<h2 id="{anchor}">' in page   # the link lands
    assert "### Cases without a result" in summary and "### Flagged findings" in summary
    for name in re.findall(r"\]\(figures/([^)]+)\.svg\)", text):
        for suffix in (".svg", ".png"):
            assert (run_dir / "figures" / f"{name}{suffix}").stat().st_size > MIN_FIGURE_BYTES
    names = set(re.findall(r"\]\(figures/([^)]+)\.svg\)", text))
    assert {f"{DYNAMICS_SCENE}-work-precision", f"{DYNAMICS_SCENE}-convergence", f"{DYNAMICS_SCENE}-drift",
            f"{IK_SCENE}-solve-rate", f"{IK_SCENE}-residuals", f"{IK_SCENE}-fk-agreement"} <= names


def _md_section(run_dir, heading: str) -> str:
    return (run_dir / REPORT_FILE).read_text().split(f"## {heading}", 1)[1].split("\n## ", 1)[0]


def _html_rows(run_dir, anchor: str) -> list[list[str]]:
    """Every table row (header rows too) of a scene's section of report.html, as its cells' text."""
    page = (run_dir / REPORT_HTML_FILE).read_text()
    section = page.split(f'<h2 id="{anchor}">', 1)[1].split("<h2 ", 1)[0]
    return [[re.sub(r"<[^>]+>", "", cell) for cell in re.findall(r"<t[dh]>(.*?)</t[dh]>", row)]
            for row in re.findall(r"<tr>(.*?)</tr>", section)]


def _md_row(section: str, start: str) -> list[str]:
    return [cell.strip() for cell in next(line for line in section.splitlines() if line.startswith(start)).split("|")[1:-1]]


@pytest.mark.slow
def test_contact_section_shows_measured_restitution_at_every_dt_and_the_height_figure(run_dir):
    """Issue #10: a contact scene's section has the height figure (no convergence figure: no order with
    impacts), per engine the range of the restitution it measured (report.md), and per engine × integrator the
    restitution at each dt next to the requested one (report.html)."""
    section = _md_section(run_dir, f"{CONTACT_SCENE} (dynamics)")
    assert f"figures/{CONTACT_SCENE}-height.svg" in section and f"{CONTACT_SCENE}-convergence" not in section
    head = _md_row(section, "| engine |")
    core, pinocchio = _md_row(section, "| core |"), _md_row(section, "| pinocchio |")
    assert core[head.index("restitution measured")].startswith("0.5")   # backup is exact: the range starts at 0.5
    assert pinocchio[-1].startswith("n/a") and "ok" not in pinocchio[-1]  # no contact in Pinocchio: every case n/a
    rows = _html_rows(run_dir, f"{CONTACT_SCENE}-dynamics")
    assert "requested restitution 0.5" in (run_dir / REPORT_HTML_FILE).read_text()
    header = next(row for row in rows if len(row) > 2 and row[2].startswith("restitution at dt"))
    assert sum(cell.startswith("restitution at dt") for cell in header) == 3   # the quick profile's three time steps
    backup = next(row for row in rows if row[:2] == ["core", "backup"] and len(row) == len(header))
    assert backup[2:5] == ["0.5"] * 3   # exact at every dt
    euler = next(row for row in rows if row[:2] == ["pinocchio", "euler"] and len(row) == len(header))
    assert euler[-1] == "n/a"


@pytest.mark.slow
def test_scene_sections_lead_with_a_verdict_and_a_row_per_engine(run_dir):
    """Issue #26: report.md's scene section says its verdict in one line, then has one row per engine (core first,
    ground truths left out) naming its most accurate scheme and its cheapest within each error budget; the row per
    engine × integrator (with its force evaluations per simulated second) is in report.html."""
    section = _md_section(run_dir, f"{DYNAMICS_SCENE} (dynamics)")
    assert section.splitlines()[1].startswith("- **Verdict**: most accurate: core ")
    assert "Reference: `analytic:exact`" in section
    head = _md_row(section, "| engine |")
    assert head[:3] == ["engine", "most accurate [rad]", "cheapest at error ≤ 0.001 (force evals/s; wall ms/s)"]
    engines = [line.split("|")[1].strip() for line in section.splitlines() if line.startswith("| ")][1:]
    assert engines == ["core", "mujoco", "pybullet", "pinocchio"]    # the user's engine first, no ground truth
    assert _md_row(section, "| mujoco |")[1].startswith("rk4 @ ")      # MuJoCo's most accurate is its RK4
    rows = _html_rows(run_dir, f"{DYNAMICS_SCENE}-dynamics")
    header = next(row for row in rows if row[:4] == ["engine", "integrator", "best dt [s]", "error [rad]"])
    rk4 = next(row for row in rows if row[:2] == ["mujoco", "rk4"] and len(row) == len(header))
    assert rk4[header.index("order (theory)")].endswith("(4)")   # the order column shows RK4's theory
    # RK4 evaluates the forces 4 times a step: 4 / dt per simulated second at its best dt
    assert float(rk4[header.index("evaluations [1/s]")]) == pytest.approx(4 / float(rk4[2]), rel=1e-2)


@pytest.mark.slow
def test_markdown_lines_stay_short(run_dir):
    """Issue #26: no line of report.md is longer than LINE_CHARS characters."""
    lines = (run_dir / REPORT_FILE).read_text().splitlines()
    assert max(len(line) for line in lines) <= LINE_CHARS


@pytest.mark.slow
def test_theoretical_orders_are_the_ones_observed(run_dir):
    """The order each engine claims for its integrators (drawn as the convergence plot's slope) matches the
    order measured on the Dzhanibekov flip, wherever an order was fitted; every engine claims some."""
    table, info = read_run(run_dir)
    theory = info.theoretical_orders
    assert {"core", "mujoco", "pybullet", "pinocchio"} <= set(theory)
    fitted = table[(table["scene"] == DYNAMICS_SCENE) & (table["metric"] == "order_orientation")
                   & (table["status"] == "ok")]
    checked = 0
    for _, row in fitted.iterrows():
        claimed = theory.get(row["engine"], {}).get(row["integrator"])
        if claimed is not None:
            assert abs(row["value"] - claimed) <= ORDER_BAND, (row["engine"], row["integrator"], row["value"], claimed)
            checked += 1
    assert {e for e in fitted["engine"] if e in theory} == {"core", "mujoco", "pybullet", "pinocchio"} and checked >= 10


@pytest.mark.slow
def test_html_is_self_contained(run_dir):
    """Every figure inline as SVG, no script, no stylesheet link, nothing fetched from a host."""
    page = (run_dir / REPORT_HTML_FILE).read_text()
    figures = sorted(p.stem for p in (run_dir / "figures").glob("*.svg"))
    assert page.count('<figure class="plot"') == len(figures) > 0
    assert "<script" not in page and "<link" not in page and "<img" not in page
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:|//)""", page)
    assert not re.search(r"url\(\s*['\"]?(https?:|//)", page)
    assert "<details>" in page   # the full tables, folded


CHECKOUT = Path(__file__).resolve().parents[2]
"""The folder tests/ is in (the no-engine subprocess below imports tests.reports.undrawn from it)."""
ARTIFACTS = CHECKOUT / "test-artifacts"
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
def test_report_renders_in_chromium_without_network(run_dir):
    """Headless Chromium (Debian's ``chromium``) opens report.html from disk: every figure renders with a non-zero
    size and fills the content column, the page asks no host for anything, and a screenshot is kept."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (a test dependency) is not installed")
    browser_path = _browser()
    page_url = (run_dir / REPORT_HTML_FILE).resolve().as_uri()
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


COMPARED_FIGURE = f"{DYNAMICS_SCENE}-drift"
"""The figure test_report_regenerates_a_copied_run_with_no_engine_importable compares with the run's own: the one
figure its re-rendering saves (every figure is still made by its figure function there; saving them all would draw
seven more no assertion reads)."""

_NO_ENGINES = textwrap.dedent("""
    import sys
    class Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("mujoco", "pybullet", "pybullet_data", "pinocchio"):
                raise ImportError(f"{name} blocked by the test")
    sys.meta_path.insert(0, Block())
    sys.path.insert(0, sys.argv[2])
    from simparity.comparisons.cli.main import main
    from tests.reports.undrawn import undrawn_figures
    with undrawn_figures(frozenset(sys.argv[3:])):
        sys.exit(main(["report", sys.argv[1]]))
""")


@pytest.mark.slow
def test_report_regenerates_a_copied_run_with_no_engine_importable(run_dir, tmp_path):
    copy = tmp_path / "copied"
    shutil.copytree(run_dir, copy)
    shutil.rmtree(copy / "figures")
    for name in (REPORT_FILE, REPORT_HTML_FILE):
        (copy / name).unlink()
    done = subprocess.run([sys.executable, "-c", _NO_ENGINES, str(copy), str(CHECKOUT), COMPARED_FIGURE],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (copy / REPORT_FILE).read_text() == (run_dir / REPORT_FILE).read_text()
    figure = f"figures/{COMPARED_FIGURE}.svg"
    assert (copy / figure).read_text() == (run_dir / figure).read_text()
    assert (copy / REPORT_HTML_FILE).stat().st_size > MIN_PAGE_BYTES


KEPT_SCENE = CONTACT_SCENE
"""The scene test_report_removes_the_figures_an_earlier_rendering_left keeps: the one with the fewest figures (two),
so the re-rendering draws little while the six figures of the other scenes are left to remove."""


@pytest.mark.slow
def test_report_removes_the_figures_an_earlier_rendering_left(run_dir, tmp_path):
    """Figures no longer drawn (their scenes' rows removed from results.csv) do not outlive the re-rendering; every
    figure the report links is there, and a file that is not a figure is left alone."""
    copy = tmp_path / "copied"
    shutil.copytree(run_dir, copy)
    table = pd.read_csv(copy / "results.csv", keep_default_na=False, dtype=str)  # as written: "n/a" is a status
    table[table.scene == KEPT_SCENE].to_csv(copy / "results.csv", index=False)
    assert any(p.name.startswith(f"{DYNAMICS_SCENE}-") for p in (copy / "figures").iterdir())   # there to be removed
    (copy / "figures" / "notes.txt").write_text("mine", encoding="utf-8")
    assert main(["report", str(copy)]) == 0
    left = {p.name for p in (copy / "figures").iterdir()}
    assert not any(name.startswith(f"{DYNAMICS_SCENE}-") for name in left) and "notes.txt" in left
    assert all(name.startswith(f"{KEPT_SCENE}-") for name in left - {"notes.txt"})   # no other scene's either
    linked = set(re.findall(r"\]\(figures/([^)]+\.svg)\)", (copy / REPORT_FILE).read_text()))
    assert linked and linked <= left


def _findings(verdict, tmp_path) -> str:
    rows = [ResultRow("s", "core", "rk4", 0.01, metric, 1e-6, "rad", "analytic:exact", "ok")
            for metric in ("orientation_error_max", "time_per_step")]
    series = pd.DataFrame(columns=list(SERIES_COLUMNS))
    blocks, _ = build(pd.DataFrame([r.as_dict() for r in rows]), RunInfo(), series, verdict, tmp_path)
    text = to_markdown(blocks)
    return text.split("### Flagged findings", 1)[1].split("###", 1)[0]


def test_tolerance_findings_say_what_was_held_to_a_bound(tmp_path):
    """A run nothing was held to never reads as passing; violations and unbounded metrics are counted."""
    assert "nothing checked: no bound matches" in _findings(ToleranceVerdict(0, 7), tmp_path)
    mixed = _findings(ToleranceVerdict(3, 2, ("s core rk4 dt=0.01 x: 1, bound <= 0.5 (why)",)), tmp_path)
    assert "1 of 3 checked metrics" in mixed and "2 without a bound" in mixed
    assert "all 3 checked metrics inside their bounds" in _findings(ToleranceVerdict(3, 0), tmp_path)
    assert "not checked in this report" in _findings(None, tmp_path)
