"""``python benchmarks/report_stage.py DIR`` without a finished study is one clear line and a non-zero exit."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_report_stage_without_results_says_run_make_fragility_first(tmp_path):
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "report_stage.py"), str(tmp_path / "reports")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert done.returncode != 0
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1, done.stderr
    assert "cube.nc" in done.stderr and "make fragility" in done.stderr
