#!/usr/bin/env bash
# Single entry point of the DEM calibration toolkit. Run ./run.sh --help.
# Each command first installs what is missing (Debian packages), quietly when all is present.
set -euo pipefail
cd "$(dirname "$(readlink -f "$0")")"

PY=/usr/bin/python3          # Debian's interpreter: the one YADE runs on (never the first python3 on PATH)
DEB_PACKAGES="yade python3-numpy python3-scipy python3-pandas python3-matplotlib python3-yaml python3-pytest python3-distributed python3-sklearn python3-emcee git"   # distributed: the Dask executor; sklearn, emcee: the calibration's response models and posteriors (pycal/stats)

usage() {
  cat <<'USAGE'
usage: ./run.sh COMMAND [ARGS]

  calibrate [ARGS]   the main job: calibrate the shipped example material (zinc ore study,
                     configs/calibrations/); results and report under runs/
  test [PYTEST ARGS] run the test suite (unit layer + short YADE physics layer)
  pycal ARGS         same as /usr/bin/python3 -m pycal ARGS (./run.sh pycal --help lists them)
  bench [NAME]       run the benchmarks in bench/ (figures go to bench/README.md by hand);
                     bench liggghts_cross ARGS: the export checked in LIGGGHTS (installs liggghts)
  install            only install the dependencies
  --help             this text

Every command installs what is missing first (apt-get; as root or through sudo).
USAGE
}

missing_packages() {
  local p
  for p in $DEB_PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || printf '%s ' "$p"
  done
}

ensure_deps() {
  local missing sudo=""
  missing=$(missing_packages)
  [ -z "$missing" ] && return 0
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "run.sh: need root or sudo to install: $missing" >&2; exit 1; }
    sudo="sudo"
  fi
  echo "run.sh: installing Debian packages: $missing" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $missing >/dev/null
  missing=$(missing_packages)
  [ -z "$missing" ] || { echo "run.sh: could not install: $missing" >&2; exit 1; }
}

cmd="${1:---help}"
[ $# -gt 0 ] && shift
case "$cmd" in
  -h|--help|help) usage ;;
  install) ensure_deps ;;
  test)
    ensure_deps
    export OMP_NUM_THREADS=1
    # scipy's L-BFGS-B (Fortran) prints "ascent direction in projection" unasked; unbuffered, it goes out while
    # pytest captures the test's output, instead of after pytest's summary line at exit (numbers unchanged)
    export GFORTRAN_UNBUFFERED_PRECONNECTED=y
    exec "$PY" -m pytest -q -p no:cacheprovider tests "$@" ;;
  pycal)
    ensure_deps
    exec "$PY" -m pycal "$@" ;;
  calibrate)
    ensure_deps
    exec "$PY" -m pycal calibrate "$@" ;;
  bench)
    if [ "${1:-}" = "liggghts_cross" ]; then   # the cross-code check of the export: only it needs LIGGGHTS
      shift
      DEB_PACKAGES="$DEB_PACKAGES liggghts"
      ensure_deps
      exec "$PY" bench/liggghts_cross.py "$@"
    fi
    ensure_deps
    exec "$PY" bench/run_bench.py "$@" ;;
  *) echo "run.sh: unknown command '$cmd'" >&2; usage >&2; exit 2 ;;
esac
