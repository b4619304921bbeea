#!/usr/bin/env bash
# Side-by-side of vibrotribo and Siconos 4.4 (Debian's python3-siconos, run with the system
# Python) on the default and chatter cases: impact-time and closing-speed errors against
# vibrotribo's events, CPU per period, and what fails. Installs python3-siconos with apt-get
# when it is missing and it can; otherwise says why and exits 0 (this is a benchmark, not a
# test). Extra arguments go to siconos_bench.py (--periods, --repeats, --steps).
# Usage: bench/siconos/run.sh [ARGS]    Output: a Markdown table on stdout.
set -euo pipefail
cd "$(dirname "$0")/../.."
py=/usr/bin/python3
if ! "$py" -c 'import siconos.kernel' 2>/dev/null; then
    if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
        echo "installing python3-siconos with apt-get" >&2
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q python3-siconos >&2 ||
            { echo "skipped: apt-get could not install python3-siconos" >&2; exit 0; }
    else
        echo "skipped: Siconos (python3-siconos) is not installed and apt-get cannot install it here" >&2
        exit 0
    fi
fi
if ! "$py" -c 'import siconos.kernel' 2>/dev/null; then
    echo "skipped: python3-siconos is installed but $py cannot import siconos.kernel" >&2
    exit 0
fi
command -v gcc >/dev/null || { echo "skipped: gcc is needed to compile the force plugin" >&2; exit 0; }
bin=${VIBROTRIBO_BIN:-}
if [ -z "$bin" ]; then
    cargo build --release -q -p vibrotribo-cli
    bin=${CARGO_TARGET_DIR:-target}/release/vibrotribo
fi
exec "$py" bench/siconos/siconos_bench.py --bin "$bin" "$@"
