#!/bin/sh
# Peak memory (maximum resident set size) and output size of the two long runs that stream:
# 30 days of free motion at 0.1 s (25 920 000 samples) and the tilt transfer functions on
# 10^7 frequencies. Needs GNU time (/usr/bin/time -v). Writes into a temporary directory,
# removed at the end. Usage: scripts/bench/long_runs_memory.sh [path/to/tiltnoise]
set -eu
bin=${1:-target/release/tiltnoise}
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
measure() {
    /usr/bin/time -v "$bin" "$@" >/dev/null 2>time.txt
    printf '%s\n' "tiltnoise $*"
    grep -E 'Maximum resident set size|Elapsed' time.txt
    ls -l -- *.h5 *.csv 2>/dev/null | awk '{print "  " $5 " bytes  " $9}'
    rm -f -- *.h5 *.csv *.png
}
measure simulate --duration 2592000 --save sim.h5 --save asd.csv --save fig3.png --save-time t.png
measure tf --freq 1e-4:10000000:30 --save tf.h5 --save tf.csv
