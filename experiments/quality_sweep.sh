#!/usr/bin/env bash
# Sweeps mesh2d over the bundled examples and the shared glyphs, levels 4-8, tri/quad/mixed, and
# prints one line per run: file, level, kind, elements, min/max angle, the same away from input
# corners sharper than 20 deg (triangles) and the quad angle range there, validity, area error,
# BE-to-curve Hausdorff distance / diagonal.
# Usage: experiments/quality_sweep.sh [BUILD_DIR] [OUT_DIR]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build}/febemesh
out=${2:-$root/results/quality_sweep}
mkdir -p "$out"
levels=${LEVELS:-"4 5 6 7 8"}
kinds=${KINDS:-"tri quad mixed"}
printf "%-32s %5s %6s %9s %8s %8s %8s %15s %6s %10s %10s %s\n" file level kind elements min_ang max_ang min_away quad_away valid area_err hausdorff status
for f in "$root"/examples/*.json "$root"/../shared/data/2d/*.svg; do
  for level in $levels; do
    for kind in $kinds; do
      name=$(basename "$f"); d="$out/${name%.*}-L$level-$kind"
      if "$bin" mesh2d "$f" -o "$d" --level "$level" --elements "$kind" --quiet --no-figures >/dev/null 2>"$d.err"; then
        python3 - "$d/report.json" "$name" "$level" "$kind" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
q = r["quality"]; c = r["counts"]
qa = q.get("quad_angle_range_away_from_sharp_corners_deg")
quad = "%.1f-%.1f" % tuple(qa) if qa else "-"
print("%-32s %5s %6s %9d %8.2f %8.2f %8.2f %15s %6s %10.2e %10.2e ok" % (sys.argv[2], sys.argv[3], sys.argv[4], c["fe_elements"],
      q["min_angle_deg"], q["max_angle_deg"], q["min_angle_away_from_sharp_corners_deg"], quad, r["validation"]["valid"],
      r["fidelity"]["area_rel_error"], r["fidelity"]["hausdorff_rel"]))
PY
      else
        printf "%-32s %5s %6s FAILED: %s\n" "$name" "$level" "$kind" "$(head -c 300 "$d.err")"
      fi
    done
  done
done
