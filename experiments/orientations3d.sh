#!/usr/bin/env bash
# Meshes a closed surface in each of the cube's 24 orientations (issue 6: does the mesh depend on
# how the part is given?) and prints one markdown table row per orientation: how the first
# lattice's run ended (it stood, or how it was degraded, from the progress lines), the mesh that
# stands (tetrahedra, smallest dihedral angle, volume error, the lattice draw and the runs made)
# and the user seconds. The orientations are exact: each vertex's coordinates permuted and
# negated (determinant +1), written with every digit, so o00 is the surface as given.
# Usage: experiments/orientations3d.sh SURFACE.off LEVEL [BUILD_DIR] [OUT_DIR]
#   ORIENTATIONS="00 05 13" runs only those; ARGS="--draw-below 15" passes more options to every
#   run. Session 34's tables (README, "Lattice draws") come from it: fandisk, anchor, spool at
#   level 5, fandisk and rotor at level 4, one thread, two sweeps at a time.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
surface=${1:?usage: orientations3d.sh SURFACE.off LEVEL [BUILD_DIR] [OUT_DIR]}
level=${2:?usage: orientations3d.sh SURFACE.off LEVEL [BUILD_DIR] [OUT_DIR]}
bin=${3:-$root/build}/febemesh
name=$(basename "$surface" .off)
out=${4:-$root/results/orientations3d/$name-L$level}
read -r -a args <<< "${ARGS:-}"
[ -x /usr/bin/time ] || { echo "orientations3d: needs GNU time (/usr/bin/time)" >&2; exit 1; }
mkdir -p "$out"
python3 - "$surface" "$out" <<'PY' || exit 1
import itertools, sys
src, out = sys.argv[1:]
lines = [l for l in open(src).read().split('\n') if l.strip() and not l.startswith('#')]
if lines[0].strip() != 'OFF':
    sys.exit(f"orientations3d: {src}: not an OFF file")
nv, nf = map(int, lines[1].split()[:2])
vertices = [list(map(float, lines[2 + i].split()[:3])) for i in range(nv)]
faces = lines[2 + nv:2 + nv + nf]
k = 0
for perm in itertools.permutations(range(3)):
    for signs in itertools.product([1, -1], repeat=3):
        # The permutation's parity times the signs: +1 for a rotation (a reflection would turn
        # the surface inside out, which mesh3d also accepts, but it is not an orientation).
        inversions = sum(1 for i in range(3) for j in range(i + 1, 3) if perm[i] > perm[j])
        if (-1) ** inversions * signs[0] * signs[1] * signs[2] != 1:
            continue
        with open(f"{out}/o{k:02d}.off", "w") as f:
            f.write(f"OFF\n{nv} {nf} 0\n")
            for v in vertices:
                f.write(' '.join(repr(signs[i] * v[perm[i]] + 0.0) for i in range(3)) + '\n')
            f.write('\n'.join(faces) + '\n')
        k += 1
PY
orientations=${ORIENTATIONS:-$(seq -f "%02g" 0 23 | tr '\n' ' ')}
echo "| orientation | first lattice | tets | min dihedral (deg) | volume error | draw (runs) | user s |"
echo "|---|---|---|---|---|---|---|"
for o in $orientations; do
  d="$out/o$o"
  rm -rf "$d"
  /usr/bin/time -f "%U" -o "$d.time" "$bin" mesh3d "$out/o$o.off" -o "$d" --level "$level" --threads 1 \
    "${args[@]}" >/dev/null 2>"$d.log"
  python3 - "$d" "o$o" <<'PY'
import json, re, sys
d, o = sys.argv[1:]
log = open(d + ".log").read()
user = open(d + ".time").read().split()[-1]
first = "stood"
m = re.search(r"\] (.*?): once more with the lattice shifted", log)
if m:
    first = m.group(1)[:80].replace("|", "/")
try:
    r = json.load(open(d + "/report.json"))
    opt = r["options"]
    print(f"| {o} | {first} | {r['counts']['tetrahedra']} | {r['quality']['min_dihedral_deg']:.2f} | "
          f"{100 * r['fidelity']['volume_rel_error']:.2f}% | {opt['lattice_draw']} ({opt['lattice_draws_run'] + 1}) | {user} |")
except (OSError, ValueError, KeyError):
    last = log.strip().splitlines()[-1][:120].replace("|", "/") if log.strip() else "no output"
    print(f"| {o} | {first} | refused: {last} | | | | {user} |")
PY
done
