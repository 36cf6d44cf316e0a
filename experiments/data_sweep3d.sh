#!/usr/bin/env bash
# Sweeps mesh3d over the closed surfaces of ../shared/data/3d (issue 6's bar: every one at levels
# 4-6 gives a valid mesh) and prints one markdown table row per run: surface, level, kind, status
# (valid / invalid / refused), elements, tetrahedra, smallest dihedral angle, volume error,
# BE-to-surface Hausdorff distance / diagonal, CPU seconds and peak memory (GNU time), and for a
# refused run the first words of its reason. open-cylinder.off is left out (it must be refused,
# tests/cli checks that).
# Usage: experiments/data_sweep3d.sh [BUILD_DIR] [OUT_DIR]
#   LEVELS="4 5 6" KINDS="tet hex" SURFACES="sphere966 anchor" THREADS=1 narrow it down;
#   ARGS="--buffer 0" passes more options to every run;
#   SURFACE_DIR=dir sweeps the closed surfaces there instead (.off, .stl, .obj, .ply; e.g.
#   examples/3d, the bundled machined parts);
#   KEEP=0 removes each run's folder once its row is printed (level 6 meshes are 0.1-1 GB);
#   the exit status is 1 when any run is not valid (the regression tests dim3_data_levels_SURFACE,
#   tests/CMakeLists.txt, one per surface, run it at levels 4-6 in both kinds).
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build}/febemesh
out=${2:-$root/results/data_sweep3d}
data=${FEBEMESH_DATA_DIR:-"$root/../shared/data"}
levels=${LEVELS:-"4 5 6"}
kinds=${KINDS:-"tet"}
threads=${THREADS:-1}
keep=${KEEP:-1}
read -r -a args <<< "${ARGS:-}"
dir=${SURFACE_DIR:-"$data/3d"}
# A surface's file: NAME.off, .stl, .obj or .ply in $dir.
file_of() { for e in off stl obj ply; do [ -f "$dir/$1.$e" ] && { echo "$dir/$1.$e"; return; }; done; echo "$dir/$1.off"; }
surfaces=${SURFACES:-$(cd "$dir" && ls *.off *.stl *.obj *.ply 2>/dev/null | grep -v '^open-' | sed 's/\.[a-z]*$//' | sort -u | tr '\n' ' ')}
[ -x /usr/bin/time ] || { echo "data_sweep3d: needs GNU time (/usr/bin/time)" >&2; exit 1; }
mkdir -p "$out"
failed=0
echo "| surface | level | kind | status | elements | tets | min dihedral (deg) | volume error | Hausdorff / diag | CPU s | peak MB | note |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for s in $surfaces; do
  for level in $levels; do
    for kind in $kinds; do
      d="$out/$s-L$level-$kind"
      rm -rf "$d"
      /usr/bin/time -f "%U %S %M" -o "$d.time" "$bin" mesh3d "$(file_of "$s")" -o "$d" --level "$level" \
        --elements "$kind" --threads "$threads" --allow-invalid "${args[@]}" >/dev/null 2>"$d.err"
      read -r user sys peak_kb < <(tail -n 1 "$d.time")
      python3 - "$d/report.json" "$s" "$level" "$kind" "$user" "$sys" "$peak_kb" "$d.err" <<'PY' > "$d.row"
import json, os, sys
path, s, level, kind, user, sys_t, peak_kb, err = sys.argv[1:]
cpu = float(user) + float(sys_t)
mb = int(peak_kb) / 1024
if not os.path.exists(path):
    lines = [l for l in open(err).read().splitlines() if "error" in l]
    why = (lines[-1] if lines else "no report").split(": ", 2)[-1][:90].replace("|", "/")
    print(f"| {s} | {level} | {kind} | refused | - | - | - | - | - | {cpu:.1f} | {mb:.0f} | {why} |")
    sys.exit(0)
r = json.load(open(path))
c, q, f, v = r["counts"], r["quality"], r["fidelity"], r["validation"]
notes = [k for k in ("buffer_rule_dropped", "buffer_rule_fallback", "feature_snapping_dropped", "facing_projection", "thickness_refined", "thickness_after_refusal", "thickness_early", "thin_parts_coarse", "surface_uniform", "frame_turned", "frame_refused")
         if r["options"].get(k)]
if r["options"].get("level_raised"):
    notes.append(f"level_raised {r['options']['level_raised']}")
if r["options"].get("lattice_draws_run"):
    notes.append(f"lattice_draw {r['options']['lattice_draw']} ({r['options']['lattice_draws_run'] + 1} runs)")
status = "valid" if v["valid"] else "invalid"
print(f"| {s} | {level} | {kind} | {status} | {q['n_elements']} | {c['tetrahedra']} | {q['min_dihedral_deg']:.2f} | "
      f"{100 * f['volume_rel_error']:.2f}% | {f['hausdorff_rel']:.2e} | {cpu:.1f} | {mb:.0f} | {', '.join(notes)} |")
PY
      grep -q "| valid |" "$d.row" || failed=1
      cat "$d.row"
      [ "$keep" = 0 ] && rm -rf "$d" "$d.time" "$d.err" "$d.row"
    done
  done
done
exit $failed
