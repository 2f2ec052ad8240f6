#!/usr/bin/env bash
# The cases of diagnose's speed table: the demo's truth (fixtures/demo/truth.toml)
# with `count = N` targets and, as benches/diagnose.rs has it, a periodic error of
# 47 mm new in the re-test; the first test, a LinuxCNC table from it (every 5 mm
# above 256 targets, the controller's limit), and the re-test with the table
# applied. Then each case is timed as a whole process with /usr/bin/time:
# `diagnose` and `report --diagnose`.
#
# Two re-tests of each size: `at` the first test's targets (independent
# per-target levels), and `between` them (N − 1 targets at the midpoints, whose
# levels share the prediction's uncertainty: a correlated covariance).
#
#   scripts/diagnose-speed.sh DIR [N ...]     (default N: 16 50 100 200 250 1000 10000)
#   CASES="between" scripts/diagnose-speed.sh DIR 1000   (default CASES: at between)
#
# AXCOMP names the binary (default target/release/axcomp).
set -euo pipefail
dir=${1:?usage: scripts/diagnose-speed.sh DIR [N ...]}
shift
counts=("$@")
[ ${#counts[@]} -gt 0 ] || counts=(16 50 100 200 250 1000 10000)
axcomp=${AXCOMP:-target/release/axcomp}
read -r -a cases <<< "${CASES:-at between}"
truth=fixtures/demo/truth.toml
mkdir -p "$dir"
for n in "${counts[@]}"; do
  for kind in "${cases[@]}"; do
    case_dir="$dir/$n-$kind"
    rm -rf "$case_dir"
    mkdir -p "$case_dir"
    sed "s/^count = 16$/count = $n/" "$truth" > "$case_dir/truth.toml"
    printf '\n[[effect]]\nkind = "periodic"\nperiod_mm = 47.0\namplitude_um = 1.2\nphase_rad = 1.0\ntests = ["after"]\n' >> "$case_dir/truth.toml"
    if [ "$kind" = between ]; then
        # The demo's axis is 0 … 750 mm: the midpoints of its N targets.
        half=$(awk -v n="$n" 'BEGIN { printf "%.17g", 750 / (2 * (n - 1)) }')
        last=$(awk -v n="$n" 'BEGIN { printf "%.17g", 750 - 750 / (2 * (n - 1)) }')
        printf '\n[cycle.after]\nstart_mm = %s\nend_mm = %s\ncount = %s\n' "$half" "$last" $((n - 1)) >> "$case_dir/truth.toml"
    fi
    step=()
    [ "$n" -le 256 ] || step=(--step 5)
    "$axcomp" synth -q --truth "$case_dir/truth.toml" -o "$case_dir/before.rtl" --seed 2026
    "$axcomp" convert "$case_dir/before.rtl" --controller linuxcnc -o "$case_dir/X.tbl" -q "${step[@]}" >/dev/null
    "$axcomp" synth -q --truth "$case_dir/truth.toml" -o "$case_dir/before2.rtl" --seed 2026 \
        --table "$case_dir/X.tbl" --o2 "$case_dir/after.rtl"
  done
done
for n in "${counts[@]}"; do
  for kind in "${cases[@]}"; do
    c="$dir/$n-$kind"
    for command in diagnose report; do
        if [ $command = diagnose ]; then
            args=(diagnose --after "$c/after.rtl" --before "$c/before.rtl" --table "$c/X.tbl")
        else
            rm -f "$c/report.html"
            args=(report "$c/before.rtl" --after "$c/after.rtl" --table "$c/X.tbl" --diagnose -o "$c/report.html")
        fi
        /usr/bin/time -f "$n $kind $command wall %e s cpu %U+%S s" "$axcomp" "${args[@]}" >/dev/null
    done
  done
done
