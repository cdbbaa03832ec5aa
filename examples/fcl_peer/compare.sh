#!/usr/bin/env bash
# Proxima's pair_queries and FCL 0.7 (every BV type) on the same mesh pairs and poses, one
# after the other in this run; prints each engine's rows and, per query, Proxima's mean and
# median against the best FCL tree's. See README.md in this folder.
set -euo pipefail
cd "$(dirname "$0")/../.."
D=${PROXIMA_DATA:-../shared/data}
F=examples/fcl_peer
OUT=${OUT:-target/fcl}
mkdir -p "$OUT"
g++ -O3 -DNDEBUG -std=c++17 -I/usr/include/eigen3 $F/fcl_pairs.cpp -lfcl -lccd -o "$OUT/fcl_pairs"
cargo build --release --example pair_queries
PAIRS=(
  "bunny-fandisk|$D/meshes/stanford-bunny.obj|$D/meshes/fandisk.obj|$D/poses/bunny_fandisk.txt|--scale1 10 --scale2 0.3 --center"
  "env-rob|$D/meshes/env.obj|$D/meshes/rob.obj|$F/poses/env_rob.txt|"
  "tray-spot|$F/meshes/tray.obj|$D/meshes/spot.obj|$F/poses/tray_spot.txt|--center"
  "plate-bunny|$F/meshes/plate.obj|$D/meshes/stanford-bunny.obj|$F/poses/plate_bunny.txt|--scale2 10 --center"
)
for pair in "${PAIRS[@]}"; do
  IFS='|' read -r name m1 m2 poses options <<< "$pair"
  # shellcheck disable=SC2086
  target/release/examples/pair_queries "$m1" "$m2" "$poses" $options 2>/dev/null \
    | tail -n +2 | sed "s/^/$name\tproxima\t/" > "$OUT/$name.tsv"
  for bv in obbrss rss kios obb aabb; do
    # shellcheck disable=SC2086
    "$OUT/fcl_pairs" "$m1" "$m2" "$poses" $options --bv $bv 2>/dev/null \
      | tail -n +2 | sed "s/^/$name\tfcl-$bv\t/" >> "$OUT/$name.tsv"
  done
done
cat "$OUT"/*.tsv > "$OUT/all.tsv"
python3 - "$OUT/all.tsv" <<'PY'
import sys, collections
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])]
by = collections.defaultdict(dict)
for pair, engine, query, n, mean, median, *_ in rows:
    by[(pair, query)][engine] = (float(mean), float(median))
print("pair\tquery\tproxima mean/median us\tFCL best mean/median us (tree)\tspeed-up mean/median")
for (pair, query), engines in by.items():
    if query == "distance_warm" or "proxima" not in engines:
        continue
    fcl = {e: t for e, t in engines.items() if e.startswith("fcl")}
    best_mean = min(fcl.items(), key=lambda e: e[1][0])
    best_median = min(fcl.items(), key=lambda e: e[1][1])
    ours = engines["proxima"]
    print(f"{pair}\t{query}\t{ours[0]:.2f} / {ours[1]:.2f}\t"
          f"{best_mean[1][0]:.2f} ({best_mean[0][4:]}) / {best_median[1][1]:.2f} ({best_median[0][4:]})\t"
          f"{best_mean[1][0] / ours[0]:.2f}x / {best_median[1][1] / ours[1]:.2f}x")
PY
