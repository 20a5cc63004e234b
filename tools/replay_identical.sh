#!/bin/bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The estimator's outputs, byte for byte, before and after a change that must not move
# them (a refactoring, an inlining decision):
#
#   tools/replay_identical.sh record DIR    # the reference: run before the change
#   tools/replay_identical.sh compare DIR   # after it: prints each file that differs
#
# Every BROAD recording (../shared/data/broad/*.csv.gz) and every scenario
# (build/scenario --list), plain and with the sensor errors bench/bench.py scores
# (bench/tune.py SENSOR_ERRORS: +uncal `--preset uncalibrated`, +imu the same with a
# calibrated compass), through `build/replay --log`: the angle lines (stdout) and the
# pipeline's messages (stderr) are kept apart. The scenario files themselves are
# compared too (they are the inputs). BUILD (default build) holds replay and scenario.
# With SIM=1 the firmware's own output in simavr as well (build/apm25sim on ELF, default
# BUILD/firmware.elf, SIM_SECONDS of fast, shake+uncal and tumble+uncal, default 12 s):
# the AVR-only code (inline assembly) is checked there, the host cannot run it.
# Exit status: 0 when every file is identical, 1 when one differs or is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
dir=${2:-}
if [[ ( $mode != record && $mode != compare ) || -z $dir ]]; then
    echo "usage: $0 record|compare DIR" >&2
    exit 2
fi
build=${BUILD:-build}
replay=$build/replay
scenario=$build/scenario
for t in "$replay" "$scenario"; do
    [[ -x $t ]] || { echo "$0: no $t (make all)" >&2; exit 2; }
done
data=${DATA:-../shared/data/broad}

out=$dir
[[ $mode == compare ]] && out=$(mktemp -d /tmp/replay_identical.XXXXXX)
mkdir -p "$out/scenarios" "$out/replay"

# The inputs.
declare -A variants=(["plain"]="" ["+uncal"]="--preset uncalibrated"
                     ["+imu"]="--preset uncalibrated --hard-iron 0,0,0 --soft-iron 1,1,1")
inputs=()
for f in "$data"/*.csv.gz; do
    [[ -e $f ]] && inputs+=("$f")
done
for name in $("$scenario" --list | awk '!/^#/ {print $1}'); do
    for variant in plain +uncal +imu; do
        suffix=${variant#plain}
        # shellcheck disable=SC2086
        "$scenario" "$name" ${variants[$variant]} > "$out/scenarios/$name$suffix.csv"
        inputs+=("$out/scenarios/$name$suffix.csv")
    done
done

# The outputs, two at a time (two cores).
run_one() {
    local in=$1 base
    base=$(basename "$in"); base=${base%.gz}; base=${base%.csv}
    "$replay" --trajectory "$in" --log > "$out/replay/$base.out" 2> "$out/replay/$base.log"
}
export -f run_one
export replay out
printf '%s\n' "${inputs[@]}" | xargs -P 2 -I{} bash -c 'run_one "$@"' _ {}

if [[ ${SIM:-0} == 1 ]]; then
    mkdir -p "$out/simavr"
    elf=${ELF:-$build/firmware.elf}
    sim_one() {
        "$build/apm25sim" --elf "$elf" --trajectory "$out/scenarios/$1.csv" --seconds "${SIM_SECONDS:-12}" \
            > "$out/simavr/$1.out"
    }
    export -f sim_one
    export build elf
    printf '%s\n' fast shake+uncal tumble+uncal | xargs -P 2 -I{} bash -c 'sim_one "$@"' _ {}
fi

if [[ $mode == record ]]; then
    echo "recorded $(find "$dir" -type f | wc -l) files in $dir"
    exit 0
fi
n=0; bad=0
while IFS= read -r ref; do
    rel=${ref#"$dir"/}
    n=$((n + 1))
    if ! cmp -s "$ref" "$out/$rel"; then
        echo "DIFFERS: $rel"
        bad=$((bad + 1))
    fi
done < <(find "$dir" -type f | { if [[ ${SIM:-0} == 1 ]]; then cat; else grep -v /simavr/; fi; } | sort)
extra=$(cd "$out" && find . -type f | sed 's|^\./||' | while read -r f; do [[ -e $dir/$f ]] || echo "$f"; done)
[[ -n $extra ]] && { echo "NEW (not in the reference): $extra"; bad=$((bad + 1)); }
echo "compared $n files: $bad differ"
rm -rf "$out"
[[ $bad -eq 0 ]]
