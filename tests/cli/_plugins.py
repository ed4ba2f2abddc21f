"""Running ``femkit`` in a subprocess with plugins: what the extension tests share."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run_with_plugins(cwd: Path, plugin_dir: Path, plugins: str, *args: str) -> subprocess.CompletedProcess:
    """``python -m femkit ARGS`` in ``cwd`` with ``FEMKIT_PLUGINS=plugins`` importable from
    ``plugin_dir`` (and this checkout first on the path)."""
    env = {**os.environ, "FEMKIT_PLUGINS": plugins, "OPENBLAS_NUM_THREADS": "1",
           "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([str(plugin_dir), str(ROOT),
                                          os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "femkit", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def write_yaml(directory: Path, name: str, text: str) -> str:
    """Write the dedented ``text`` as ``directory/name``; returns ``name``."""
    (directory / name).write_text(textwrap.dedent(text))
    return name
