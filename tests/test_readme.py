"""README.md's Python example and first command must keep working (docs cannot rot)."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def test_readme_opens_with_install_run_and_install_test_commands():
    block = re.search(r"```bash\n(.*?)```", README, re.S).group(1).strip().splitlines()
    assert block[0].startswith("python -m pip install -e .") and "femkit solve cases/" in block[0]
    assert block[1] == 'python -m pip install -e ".[test]" && python -m pytest'
    case = block[0].split("femkit solve ")[1].strip()
    assert (ROOT / case).is_file()


def test_readme_python_example_runs(tmp_path):
    code = re.search(r"```python\n(.*?)```", README, re.S).group(1)
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    # the example prints: converged iterations reason true_residual
    last = proc.stdout.strip().splitlines()[-1].split()
    assert last[0] == "True" and last[2] == "converged"
