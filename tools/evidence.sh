#!/usr/bin/env bash
# Reproduces docs/EVIDENCE.md's material: the discrepancy protocol (fast or
# full setting) and the pictures of the paper's Figs. 9-14.
#   bash tools/evidence.sh [fast|full|pictures]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/tools/build.sh"
sfc="$root/build/client/sfcsampler"
out="$root/docs/evidence"
mkdir -p "$out"
setting="${1:-fast}"
if [ "$setting" != pictures ]; then
  mkdir -p "$out/eval-$setting"
  "$sfc" eval --setting "$setting" --out-dir "$out/eval-$setting" | tee "$out/eval-$setting/table.txt"
fi

r() { "$sfc" render --size 600 "$@"; }
# Fig. 9: the unit square with densities 1, u, u + v (3000 points).
r --surface plane --density uniform --count 3000 --what param-samples --title "unit square, density 1" -o "$out/fig09-square-1.png"
r --surface plane --density expr:u --count 3000 --what param-samples --title "density u" -o "$out/fig09-square-u.png"
r --surface plane --density expr:u+v --count 3000 --what param-samples --title "density u + v" -o "$out/fig09-square-u+v.png"
# Figs. 10-12: uniform and |K| densities and the adaptive curve.
for spec in "monkey_saddle 3000 30,35" "eight 10000 30,20" "whitney 6000 60,30"; do
  set -- $spec
  r --surface "$1" --count "$2" --view "$3" --what samples --title "$1, uniform, $2 points" -o "$out/fig-$1-uniform.png"
  r --surface "$1" --density gaussian:floor=0.01 --count "$2" --view "$3" --what samples --title "$1, density |K|, $2 points" -o "$out/fig-$1-curvature.png"
  r --surface "$1" --density gaussian:floor=0.01 --count 200 --view "$3" --what curve --title "$1, adaptive curve (|K|)" -o "$out/fig-$1-curve.png"
done
# Figs. 13-14: the superellipsoid, uniform curve of depth 7 against the
# adaptive curve, and the power-law reparameterisation.
r --surface superellipsoid --tolerance 1e-9 --depth-cap 7 --count 1 --what curve --view 30,25 --title "superellipsoid, uniform curve, depth 7" -o "$out/fig13-superellipsoid-uniform.png" 2>/dev/null
r --surface superellipsoid --count 1 --tolerance 0.1 --what curve --view 30,25 --title "superellipsoid, adaptive curve" -o "$out/fig13-superellipsoid-adaptive.png"
r --surface superellipsoid:reparam=1 --tolerance 1e-9 --depth-cap 7 --count 1 --what curve --view 30,25 --title "reparameterised, uniform curve, depth 7" -o "$out/fig14-superellipsoid-reparam.png" 2>/dev/null
r --surface superellipsoid --count 20000 --what samples --view 30,25 --title "superellipsoid, 20000 points" -o "$out/fig13-superellipsoid-samples.png"
echo "evidence written to $out"
