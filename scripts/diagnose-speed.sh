#!/usr/bin/env bash
# The cases of diagnose's speed table: the demo's truth (fixtures/demo/truth.toml)
# with `count = N` targets and, as benches/diagnose.rs has it, a periodic error of
# 47 mm new in the re-test; the first test, a LinuxCNC table from it (every 5 mm
# above 256 targets, the controller's limit), and the re-test with the table
# applied. Then each case is timed as a whole process with /usr/bin/time:
# `diagnose` and `report --diagnose`.
#
#   scripts/diagnose-speed.sh DIR [N ...]     (default N: 16 50 100 200 250 1000 10000)
#
# AXCOMP names the binary (default target/release/axcomp).
set -euo pipefail
dir=${1:?usage: scripts/diagnose-speed.sh DIR [N ...]}
shift
counts=("$@")
[ ${#counts[@]} -gt 0 ] || counts=(16 50 100 200 250 1000 10000)
axcomp=${AXCOMP:-target/release/axcomp}
truth=fixtures/demo/truth.toml
mkdir -p "$dir"
for n in "${counts[@]}"; do
    case_dir="$dir/$n"
    rm -rf "$case_dir"
    mkdir -p "$case_dir"
    sed "s/^count = 16$/count = $n/" "$truth" > "$case_dir/truth.toml"
    printf '\n[[effect]]\nkind = "periodic"\nperiod_mm = 47.0\namplitude_um = 1.2\nphase_rad = 1.0\ntests = ["after"]\n' >> "$case_dir/truth.toml"
    step=()
    [ "$n" -le 256 ] || step=(--step 5)
    "$axcomp" synth -q --truth "$case_dir/truth.toml" -o "$case_dir/before.rtl" --seed 2026
    "$axcomp" convert "$case_dir/before.rtl" --controller linuxcnc -o "$case_dir/X.tbl" -q "${step[@]}"
    "$axcomp" synth -q --truth "$case_dir/truth.toml" -o "$case_dir/before2.rtl" --seed 2026 \
        --table "$case_dir/X.tbl" --o2 "$case_dir/after.rtl"
done
for n in "${counts[@]}"; do
    c="$dir/$n"
    for command in diagnose report; do
        if [ $command = diagnose ]; then
            args=(diagnose --after "$c/after.rtl" --before "$c/before.rtl" --table "$c/X.tbl")
        else
            rm -f "$c/report.html"
            args=(report "$c/before.rtl" --after "$c/after.rtl" --table "$c/X.tbl" --diagnose -o "$c/report.html")
        fi
        /usr/bin/time -f "$n $command wall %e s cpu %U+%S s" "$axcomp" "${args[@]}" >/dev/null
    done
done
