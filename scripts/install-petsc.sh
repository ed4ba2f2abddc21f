#!/usr/bin/env bash
# Scale-out set-up: PETSc + MPI for femkit's `--backend petsc`.
#
# PETSc from PyPI is a source build (far too slow here), so this uses Debian's packages
# (python3-petsc4py: PETSc 3.18 with hypre BoomerAMG and MUMPS; python3-mpi4py; Open MPI),
# which are built for Debian's own interpreter /usr/bin/python3, and makes a virtual
# environment `.venv-petsc` (next to this repository's pyproject.toml) that
#   - sees Debian's site packages (--system-site-packages),
#   - finds petsc4py through a .pth file (Debian installs it under /usr/lib/petscdir),
#   - has numpy<2 (Debian's petsc4py is compiled against numpy 1.x),
#   - has femkit installed editable from this checkout with its dependencies.
# Idempotent: a second run checks and returns in a few seconds.
# Needs root (or sudo) for apt-get. Usage: bash scripts/install-petsc.sh
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
venv="$root/.venv-petsc"
py=/usr/bin/python3
t0=$(date +%s)

need_apt=0
for pkg in python3-petsc4py python3-mpi4py openmpi-bin python3-venv python3-pip; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || need_apt=1
done
if [ "$need_apt" = 1 ]; then
    sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends \
        python3-petsc4py python3-mpi4py openmpi-bin python3-venv python3-pip >/dev/null
fi

# Debian's petsc4py lives outside sys.path: find it (real-scalar build), fail loudly if absent.
petsc_py=""
for d in /usr/lib/petscdir/petsc3.*/x86_64-linux-gnu-real/lib/python3/dist-packages \
         /usr/lib/petscdir/petsc3.*/*-linux-gnu-real/lib/python3/dist-packages; do
    if [ -d "$d/petsc4py" ]; then petsc_py="$d"; break; fi
done
if [ -z "$petsc_py" ]; then
    echo "install-petsc.sh: petsc4py not found under /usr/lib/petscdir/petsc3.*/*-linux-gnu-real/lib/python3/dist-packages" >&2
    exit 1
fi

if [ ! -x "$venv/bin/python" ]; then
    "$py" -m venv --system-site-packages "$venv"
fi
site=$("$venv/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
echo "$petsc_py" > "$site/femkit-petsc4py.pth"

# numpy<2 for Debian's petsc4py; every femkit dependency resolved against it (pip picks the
# newest release of each that supports numpy 1.x on this Python).
constraints="$venv/constraints.txt"
echo "numpy<2" > "$constraints"
stamp="$venv/.femkit-installed"
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
    "$venv/bin/python" -m pip install -q --disable-pip-version-check -c "$constraints" "numpy<2"
    "$venv/bin/python" -m pip install -q --disable-pip-version-check -c "$constraints" -e "$root"
    touch "$stamp"
fi

# Prove it: petsc4py, mpi4py and femkit import together, with numpy 1.x and hypre/MUMPS present.
"$venv/bin/python" - <<'PY'
import numpy, femkit
from petsc4py import PETSc
from mpi4py import MPI
assert int(numpy.__version__.split(".")[0]) < 2, numpy.__version__
ver = ".".join(map(str, PETSc.Sys.getVersion()))
pcs = ("hypre", "gamg", "mumps")
print(f"PETSc {ver}, numpy {numpy.__version__}, mpi4py {MPI.Get_library_version().split(',')[0]}, "
      f"femkit from {femkit.__file__}")
PY
echo "install-petsc.sh: .venv-petsc ready in $(( $(date +%s) - t0 )) s"
