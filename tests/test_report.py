"""The report of a real (small) run: Markdown led by the summary, figures written as SVG and PNG, a
self-contained HTML page, and ``simparity report`` on a copied run with no engine importable."""

import re
import shutil
import subprocess
import sys
import textwrap

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import REPORT_FILE, REPORT_HTML_FILE, SERIES_COLUMNS, ResultRow
from simparity.reports.content import ToleranceVerdict, build
from simparity.reports.markdown import to_markdown
from simparity.reports.store import read_run

SCENES = ["dzhanibekov", "lecture-2link-ik", "iiwa-kinematics", "ball-bounce-k05"]
ORDER_BAND = 0.5
"""Half the gap between neighbouring integer orders, as the shipped tolerances allow: an observed order
within it of the theoretical one confirms the theory; outside it, the theory is wrong for the scheme."""
MIN_FIGURE_BYTES = 1000
"""An SVG or PNG of an empty canvas is a few hundred bytes; a drawn figure (axes, ticks, lines) is tens of
kilobytes. Anything under this is a figure with nothing on it."""
MIN_PAGE_BYTES = 10_000
"""The page's styles and summary alone come to a few kilobytes; with its inline figures it is far larger."""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A quick run of a dynamics, an IK, a kinematics and a contact scene on the default engines."""
    out = tmp_path_factory.mktemp("report") / "run"
    assert main(["run", *SCENES, "--quick", "--repeats", "0", "--jobs", "1", "--out", str(out)]) == 0
    return out


@pytest.mark.slow
def test_markdown_starts_with_the_summary_and_links_existing_figures(run_dir):
    text = (run_dir / REPORT_FILE).read_text()
    headings = re.findall(r"^(#+) (.*)$", text, flags=re.M)
    assert headings[0] == ("#", "simparity report") and headings[1] == ("##", "Summary")
    summary = text.split("## Summary", 1)[1].split("\n## ", 1)[0]
    assert "[dzhanibekov](#dzhanibekov-dynamics)" in summary and "[lecture-2link-ik](#lecture-2link-ik-ik)" in summary
    page = (run_dir / REPORT_HTML_FILE).read_text()
    assert 'href="#dzhanibekov-dynamics"' in page and '<h2 id="dzhanibekov-dynamics">' in page   # the link lands
    assert "### Cases without a result" in summary and "### Flagged findings" in summary
    for name in re.findall(r"\]\(figures/([^)]+)\.svg\)", text):
        for suffix in (".svg", ".png"):
            assert (run_dir / "figures" / f"{name}{suffix}").stat().st_size > MIN_FIGURE_BYTES
    names = set(re.findall(r"\]\(figures/([^)]+)\.svg\)", text))
    assert {"dzhanibekov-work-precision", "dzhanibekov-convergence", "dzhanibekov-drift",
            "lecture-2link-ik-solve-rate", "lecture-2link-ik-residuals", "lecture-2link-ik-fk-agreement"} <= names


@pytest.mark.slow
def test_contact_section_shows_measured_restitution_at_every_dt_and_the_height_figure(run_dir):
    """Issue #10: a contact scene's section has the height figure (no convergence figure: no order with
    impacts) and a table of the restitution each engine measured at each dt next to the requested one."""
    section = (run_dir / REPORT_FILE).read_text().split("## ball-bounce-k05 (dynamics)", 1)[1].split("\n## ", 1)[0]
    assert "figures/ball-bounce-k05-height.svg" in section and "ball-bounce-k05-convergence" not in section
    assert "requested restitution 0.5" in section
    header = next(line for line in section.splitlines() if line.startswith("| engine | integrator | restitution"))
    dts = re.findall(r"restitution at dt ([0-9.e-]+)", header)
    assert len(dts) == 3   # the quick profile's three time steps
    backup = next(line for line in section.splitlines() if line.startswith("| core | backup |"))
    assert [cell.strip() for cell in backup.split("|")[3:6]] == ["0.5"] * 3   # exact at every dt
    pinocchio = next(line for line in section.splitlines() if line.startswith("| pinocchio | euler |"))
    assert pinocchio.rstrip(" |").endswith("n/a")


@pytest.mark.slow
def test_compact_table_names_reference_units_and_theoretical_order(run_dir):
    section = (run_dir / REPORT_FILE).read_text().split("## dzhanibekov (dynamics)", 1)[1].split("\n## ", 1)[0]
    assert "Reference: `analytic:exact`" in section
    assert "| engine | integrator | best dt [s] | error [rad] | cost [s/s] |" in section
    rk4 = next(line for line in section.splitlines() if line.startswith("| mujoco | rk4 |"))
    assert rk4.split("|")[7].strip().endswith("(4)")   # the order column shows RK4's theory


@pytest.mark.slow
def test_theoretical_orders_are_the_ones_observed(run_dir):
    """The order each engine claims for its integrators (drawn as the convergence plot's slope) matches the
    order measured on the Dzhanibekov flip, wherever an order was fitted; every engine claims some."""
    table, info = read_run(run_dir)
    theory = info.theoretical_orders
    assert {"core", "mujoco", "pybullet", "pinocchio"} <= set(theory)
    fitted = table[(table["scene"] == "dzhanibekov") & (table["metric"] == "order_orientation")
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


_NO_ENGINES = textwrap.dedent("""
    import sys
    class Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("mujoco", "pybullet", "pybullet_data", "pinocchio"):
                raise ImportError(f"{name} blocked by the test")
    sys.meta_path.insert(0, Block())
    from simparity.comparisons.cli.main import main
    sys.exit(main(["report", sys.argv[1]]))
""")


@pytest.mark.slow
def test_report_regenerates_a_copied_run_with_no_engine_importable(run_dir, tmp_path):
    copy = tmp_path / "copied"
    shutil.copytree(run_dir, copy)
    shutil.rmtree(copy / "figures")
    for name in (REPORT_FILE, REPORT_HTML_FILE):
        (copy / name).unlink()
    done = subprocess.run([sys.executable, "-c", _NO_ENGINES, str(copy)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (copy / REPORT_FILE).read_text() == (run_dir / REPORT_FILE).read_text()
    assert (copy / "figures" / "dzhanibekov-drift.svg").read_text() == (run_dir / "figures" / "dzhanibekov-drift.svg").read_text()
    assert (copy / REPORT_HTML_FILE).stat().st_size > MIN_PAGE_BYTES


@pytest.mark.slow
def test_report_removes_the_figures_an_earlier_rendering_left(run_dir, tmp_path):
    """A figure no longer drawn (its scene's rows removed from results.csv) does not outlive the re-rendering; every
    figure the report links is there, and a file that is not a figure is left alone."""
    copy = tmp_path / "copied"
    shutil.copytree(run_dir, copy)
    table = pd.read_csv(copy / "results.csv")
    table[table.scene != "dzhanibekov"].to_csv(copy / "results.csv", index=False)
    (copy / "figures" / "notes.txt").write_text("mine", encoding="utf-8")
    assert main(["report", str(copy)]) == 0
    left = {p.name for p in (copy / "figures").iterdir()}
    assert not any(name.startswith("dzhanibekov-") for name in left) and "notes.txt" in left
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
