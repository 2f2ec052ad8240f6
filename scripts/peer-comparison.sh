#!/bin/sh
# Whole-process comparison of `axcomp tolerance` with the NumPy peer
# (../shared/tools/mc_peer.py) on the same work: 50,000 random machines of
# the MCV 754 Quick, seed 1, straightness 0.03 mm on all six surfaces, no
# positioning or squareness errors, 50 mm grid (the peer's defaults, which
# are axcomp's). Prints the best of three wall-clock times of each, their
# ratio, and both P90s. Needs python3 with numpy and scipy.
#
# With CARRIAGE=MM both also draw the carriage side (parallelism and flatness
# of every saddle's carriage mounting faces, MM each): axcomp with
# --carriage-parallelism MM --carriage-flatness MM, and the peer's copy that
# models it, benches/reference/mc_peer_carriage.py (the peer itself does not).
#
#   [CARRIAGE=MM] scripts/peer-comparison.sh [SAMPLES] [SEED]
set -eu
samples=${1:-50000}
seed=${2:-1}
root=$(cd "$(dirname "$0")/.." && pwd)
peer="$root/../shared/tools/mc_peer.py"
set --
if [ -n "${CARRIAGE:-}" ]; then
    peer="$root/benches/reference/mc_peer_carriage.py"
    set -- --carriage-parallelism "$CARRIAGE" --carriage-flatness "$CARRIAGE"
fi
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
axcomp="$root/target/release/axcomp"
out=$(mktemp -d)
best() { sort -g "$1" | head -n 1; }
for run in 1 2 3; do
    /usr/bin/time -f "%e" -a -o "$out/axcomp.times" \
        "$axcomp" tolerance --samples "$samples" --seed "$seed" "$@" --json --quiet > "$out/axcomp.json"
    /usr/bin/time -f "%e" -a -o "$out/peer.times" \
        python3 "$peer" "$samples" "$seed" "$@" > "$out/peer.json"
done
python3 - "$out" "$(best "$out/axcomp.times")" "$(best "$out/peer.times")" <<'PY'
import json, sys
out, t_axcomp, t_peer = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
ours = json.load(open(f"{out}/axcomp.json"))["max_volumetric_um"]
peer = json.load(open(f"{out}/peer.json"))["max_volumetric_um"]
print(f"axcomp tolerance: {t_axcomp:.2f} s   mc_peer.py: {t_peer:.2f} s   (best of 3, whole process)")
print(f"speed ratio: {t_peer / t_axcomp:.1f}x")
for key in ["mean", "median", "min", "max", "p90"]:
    print(f"  {key:<6} axcomp {ours[key]:8.2f} µm   peer {peer[key]:8.2f} µm")
PY
rm -r "$out"
