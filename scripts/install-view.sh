#!/usr/bin/env bash
# Pictures (`femkit view`, `result.plot()`, the notebooks): femkit's extra `view` (pyvista, VTK,
# imageio) and, on a Linux machine without a display (a server, CI), the one system package VTK
# renders off screen with: EGL (Debian/Ubuntu: libegl1, with Mesa's libgl1).
# Idempotent. Needs root (or sudo) for apt-get. Usage: bash scripts/install-view.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(uname)" = Linux ] && ! ldconfig -p | grep -q -e 'libEGL.so' -e 'libOSMesa.so'; then
    if ! command -v apt-get >/dev/null; then
        echo "install-view.sh: need EGL (or OSMesa) for off-screen rendering: install your system's libEGL" >&2
        exit 1
    fi
    sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libegl1 libgl1 >/dev/null
fi
python -m pip install -q -e ".[view]"
python -c "
import pyvista as pv
from femkit.view.core.render import plotter
p = plotter((64, 48)); p.add_mesh(pv.Sphere()); img = p.screenshot(None, return_img=True); p.close()
assert img.std() > 0, 'the off-screen picture is blank'
print('install-view.sh: off-screen pictures ready')"
