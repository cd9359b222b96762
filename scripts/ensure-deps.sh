#!/usr/bin/env bash
# Installs the Debian packages nlobs needs (see docs/dependencies.md for why each is here).
# Usage: scripts/ensure-deps.sh            -> packages for build + test + demo
#        scripts/ensure-deps.sh fuzz       -> the same and clang (libFuzzer) for make fuzz
# Exit 1 with a clear message when packages are missing and cannot be installed.
set -euo pipefail

packages=(
  g++ make cmake pkg-config
  clang-format         # the formatting check CI runs (make format-check)
  ccache               # compiler cache: rebuilds and CI runs reuse unchanged units
  time                 # /usr/bin/time: scripts/compile-cost's per-unit wall time and memory
  libeigen3-dev        # linear algebra, fixed-size vectors
  libceres-dev         # ceres::Jet forward-mode AD, least-squares engine (Ceres, TinySolver)
  libsuitesparse-dev   # KLU, UMFPACK: the sparse direct linear solvers (solvers/linear/)
  libhypre-dev         # BoomerAMG: the algebraic multigrid preconditioner (solvers/linear/)
  libgoogle-glog-dev   # Ceres' logging; the CLI silences it
  libnlopt-cxx-dev     # bounded minimisation engine
  libsundials-dev      # KINSOL: reference solver compared in the same run
  petsc-dev            # PETSc SNES: reference solver (libsundials-dev depends on it already)
  libcminpack-dev      # MINPACK hybrj: reference solver of the MGH suite
  libgsl-dev           # GSL hybridsj / gnewton: reference solvers of the MGH suite
  libboost-dev         # Boost.Odeint (integration, Rosenbrock), Boost.Math, Boost.Interval
  libadolc-dev         # ADOL-C Taylor-mode AD: observability maps q_N of any model
  gnuplot-nox          # PNG plots of nlobs run --out (optional at run time)
  libcli11-dev         # command-line parsing for the nlobs CLI
  nlohmann-json3-dev   # JSON output of the CLI
  libgtest-dev         # unit tests
  libcsv-dev           # tests: an independent RFC 4180 reader parses our CSV output back
  libbenchmark-dev     # Google Benchmark
)
if [ "${1:-}" = fuzz ]; then
  packages+=(clang)    # libFuzzer and its sanitizer runtimes (make fuzz)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "nlobs: installing missing Debian packages: ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  SUDO=(sudo -n)
else
  echo "nlobs: error: missing packages (${missing[*]}) and no root or password-less sudo to install them." >&2
  echo "nlobs: install them yourself: sudo apt-get install ${missing[*]}" >&2
  exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "nlobs: error: apt-get not found; this project installs its dependencies from Debian packages." >&2
  echo "nlobs: install by hand: ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq || { echo "nlobs: error: apt-get update failed" >&2; exit 1; }
"${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" \
  || { echo "nlobs: error: apt-get install failed for: ${missing[*]}" >&2; exit 1; }
