# Shared by the bench scripts (sourced from the repository's root).

# CPU seconds (user + system) of one run of the command given; stops the script if it fails.
cpu() {
    local TIMEFORMAT='%U %S'
    local t
    t=$({ time "$@" >/dev/null 2>&1; } 2>&1) || { echo "failed: $*" >&2; exit 1; }
    awk '{printf "%.4f\n", $1 + $2}' <<<"$t"
}

# The median of the numbers given.
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

# Sets `bin` to $VIBROTRIBO_BIN, or else to the release binary (built here), and `out` to a
# scratch folder removed when the script exits.
binary_and_scratch() {
    bin=${VIBROTRIBO_BIN:-}
    if [ -z "$bin" ]; then
        cargo build --release -q -p vibrotribo-cli
        bin=${CARGO_TARGET_DIR:-target}/release/vibrotribo
    fi
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
}
