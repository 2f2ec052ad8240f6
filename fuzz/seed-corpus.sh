#!/usr/bin/env bash
# Seeds each fuzz target's corpus with valid files (bundled and real third-party
# data) and the bad-input corpus, so the fuzzer starts from the real grammar.
set -euo pipefail
cd "$(dirname "$0")"
shared=../../shared/data
mkdir -p corpus/read_rtl corpus/read_ecmc corpus/read_api_pos corpus/read_csv corpus/read_tables corpus/read_inputs
cp ../fixtures/*.rtl ../tests/data/bad/rtl-* corpus/read_rtl/
cp "$shared"/ecmc/*/*.dat ../tests/data/bad/ecmc-* corpus/read_ecmc/
for f in "$shared"/api-xd/*.pos; do cp "$f" "corpus/read_api_pos/$(basename "$f" | tr ' ' _)"; done
cp ../tests/data/bad/pos-* corpus/read_api_pos/
cp ../tests/data/bad/csv-* corpus/read_csv/
printf 'target_mm,run,direction,deviation_um\n0,1,up,0\n100,1,up,2.5\n0,1,down,1\n100,1,down,\n' > corpus/read_csv/good.csv
mkdir -p corpus/read_fanuc
cp "$shared"/fanuc/*.TXT ../formats/fanuc/golden/* corpus/read_fanuc/
for f in ../formats/*/golden/*; do cp "$f" "corpus/read_tables/$(basename "$(dirname "$(dirname "$f")")")-$(basename "$f")"; done
cp ../fixtures/demo/truth.toml ../fixtures/machines/*.toml corpus/read_inputs/
printf '[[effect]]\nkind = "reversal"\nB_um = -3.0\n\n[[effect]]\nkind = "outlier-run"\nrun = 1\ndirection = "down"\noffset_um = 4.0\n' > corpus/read_inputs/effects.toml
printf '[EBX]\npositions_mm = [0.0, 750.0]\nvalues_urad = [0.0, 20.0]\ninterpolation = "spline"\n\n[EXOY]\nvalue_urad = 30.0\n' > corpus/read_inputs/errors.toml
printf 'position_mm,angle_urad\n0,0\n375,12.5\n750,0\n' > corpus/read_inputs/angular.csv
