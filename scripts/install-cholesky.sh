#!/usr/bin/env bash
# The optional sparse Cholesky solver (`method: cholesky`): scikit-sparse (CHOLMOD) built against
# Debian's SuiteSparse, with OpenBLAS (the reference BLAS makes the supernodal factorisation
# ~2.5x slower), and Intel oneMKL (binary wheels) for its engine 'pardiso' (MKL PARDISO).
# Installs femkit's extras `cholesky` and `pardiso` into the current Python.
# Idempotent. Needs root (or sudo) for apt-get. Usage: bash scripts/install-cholesky.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if ! [ -e /usr/include/suitesparse/cholmod.h ]; then
    if ! command -v apt-get >/dev/null; then
        echo "install-cholesky.sh: need SuiteSparse (CHOLMOD) headers: install libsuitesparse-dev" >&2
        exit 1
    fi
    sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libsuitesparse-dev libopenblas0-pthread >/dev/null
fi
python -m pip install -q -e ".[cholesky,pardiso,fast]"
python -c "from femkit.solvers.cholesky import available; assert available(), 'scikit-sparse did not import'; print('install-cholesky.sh: CHOLMOD ready')"
python -c "from femkit.solvers.pardiso import available; assert available(), 'MKL mkl_rt did not load'; print('install-cholesky.sh: PARDISO ready')"
