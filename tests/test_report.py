"""The report of a real (small) run: Markdown led by the summary, figures written as SVG and PNG, a
self-contained HTML page, and ``simparity report`` on a copied run with no engine importable."""

import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from simparity.comparisons.cli import main
from simparity.core.results import REPORT_FILE, REPORT_HTML_FILE

SCENES = ["dzhanibekov", "lecture-2link-ik", "iiwa-kinematics"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    """A quick run of a dynamics, an IK and a kinematics scene on core, analytic and MuJoCo."""
    out = tmp_path_factory.mktemp("report") / "run"
    assert main(["run", *SCENES, "--quick", "--repeats", "0", "--jobs", "1", "--engines", "core,analytic,mujoco",
                 "--out", str(out)]) == 0
    return out


def test_markdown_starts_with_the_summary_and_links_existing_figures(run_dir):
    text = (run_dir / REPORT_FILE).read_text()
    headings = re.findall(r"^(#+) (.*)$", text, flags=re.M)
    assert headings[0] == ("#", "simparity report") and headings[1] == ("##", "Summary")
    summary = text.split("## Summary", 1)[1].split("\n## ", 1)[0]
    assert "[dzhanibekov](#scene-dzhanibekov)" in summary and "[lecture-2link-ik]" in summary
    assert "### Cases without a result" in summary and "### Flagged findings" in summary
    for name in re.findall(r"\]\(figures/([^)]+)\.svg\)", text):
        for suffix in (".svg", ".png"):
            assert (run_dir / "figures" / f"{name}{suffix}").stat().st_size > 1000
    names = set(re.findall(r"\]\(figures/([^)]+)\.svg\)", text))
    assert {"dzhanibekov-work-precision", "dzhanibekov-convergence", "dzhanibekov-drift",
            "lecture-2link-ik-solve-rate", "lecture-2link-ik-residuals", "lecture-2link-ik-fk-agreement"} <= names


def test_compact_table_names_reference_units_and_theoretical_order(run_dir):
    section = (run_dir / REPORT_FILE).read_text().split("## dzhanibekov (dynamics)", 1)[1].split("\n## ", 1)[0]
    assert "Reference: `analytic:exact`" in section
    assert "| engine | integrator | best dt [s] | error [rad] | cost [s/s] |" in section
    rk4 = next(line for line in section.splitlines() if line.startswith("| mujoco | rk4 |"))
    assert rk4.split("|")[7].strip().endswith("(4)")   # the order column shows RK4's theory


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
    from simparity.comparisons.cli import main
    sys.exit(main(["report", sys.argv[1]]))
""")


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
    assert (copy / REPORT_HTML_FILE).stat().st_size > 10_000
