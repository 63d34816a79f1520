#!/usr/bin/env bash
# Runs CGAL's Generalized_map anchor benchmark and topomech's kernel benchmark back to back on the
# same Kuhn cube (k = 40 by default: 384 000 tets, 9.2 M darts) and prints the ratios.
#
#   bash scripts/bench_cgal.sh [k] [runs]      # from the project root; runs defaults to 3
#
# Needs libcgal-dev (installed here if missing, with apt-get) and the anchor source at
# ../shared/anchors/cgal/bench.cpp (not part of this repository; compiled into target/).
# Both sides time the calling thread's CPU time. Each side runs `runs` times, interleaved, and
# the median of each figure is reported.
set -euo pipefail
k="${1:-40}"
runs="${2:-3}"
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
anchor="${CGAL_BENCH_CPP:-$root/../shared/anchors/cgal/bench.cpp}"
target="${CARGO_TARGET_DIR:-$root/target}"
mkdir -p target
log="target/bench_cgal_k${k}.log"

if [ ! -f /usr/include/CGAL/Generalized_map.h ]; then
  echo "installing libcgal-dev" >&2
  apt-get install -y libcgal-dev >&2
fi
if [ ! -x target/cgal_bench ] || [ "$anchor" -nt target/cgal_bench ]; then
  echo "compiling $anchor" >&2
  g++ -O3 -DNDEBUG -DCGAL_NDEBUG -std=c++17 "$anchor" -o target/cgal_bench -lgmp -lmpfr
fi
cargo build --release --example bench_kernel >&2

: >"$log"
for r in $(seq 1 "$runs"); do
  echo "run $r/$runs: CGAL" >&2
  target/cgal_bench "$k" --no-subdiv3d | tee -a "$log" | grep -E '^\[(build\] TOTAL|count\]|initial\] is_valid|unsew:plane\] [0-9])' >&2
  echo "run $r/$runs: topomech" >&2
  "$target/release/examples/bench_kernel" "$k" --reps 1 | tee -a "$log" >&2
done

# Medians and ratios (CGAL ns/dart ÷ topomech ns/dart: > 1 means topomech is faster).
python3 - "$log" "$k" <<'PY'
import json, re, statistics, sys
text = open(sys.argv[1]).read()
def med(pattern, cast=float):
    vals = [cast(m) for m in re.findall(pattern, text)]
    return statistics.median(vals) if vals else float("nan")
cgal = {
    "build": med(r"TOTAL build \(no post attrs\)\s*:\s*[\d.]+ s\s*\([\d.]+ ns/tet, ([\d.]+) ns/dart\)"),
    "validate": med(r"\[initial\] is_valid\(\) = true\s+time [\d.]+ s\s+\(([\d.]+) ns/dart\)"),
    "count_all_cells": med(r"\[count\] count_all_cells: [\d.]+ s \(([\d.]+) ns/dart\)"),
    "unsew_plane_ns_per_op": med(r"\[unsew:plane\] \d+ x unsew<3>: [\d.]+ s total, per op mean (\d+) ns"),
    "bytes_per_dart": med(r"sizeof\(Dart\)=(\d+)"),
}
runs = [json.loads(l[5:]) for l in text.splitlines() if l.startswith("JSON ")]
tm = lambda key: statistics.median(r[key] for r in runs)
ours = {
    "build": tm("build_ns_per_dart"),
    "validate": tm("validate_ns_per_dart"),
    "count_all_cells": tm("count_all_ns_per_dart"),
    "unsew_plane_ns_per_op": tm("unsew_ns_per_op"),
    "bytes_per_dart": tm("bytes_per_dart"),
}
print(f"\n=== k={sys.argv[2]}, {len(runs)} runs each, medians (CPU time) ===")
print(f"{'figure':<28}{'CGAL':>12}{'topomech':>12}{'CGAL/topomech':>15}")
for key in cgal:
    c, t = cgal[key], ours[key]
    print(f"{key:<28}{c:>12.1f}{t:>12.1f}{c / t:>15.2f}")
print(f"{'count_by_traversal (4 dims)':<28}{'':>12}{tm('count_by_traversal_ns_per_dart'):>12.1f}")
if all("count_all_separate_ns_per_dart" in r for r in runs):
    sep = tm("count_all_separate_ns_per_dart")
    print(f"{'count 4 dims + components()':<28}{cgal['count_all_cells']:>12.1f}{sep:>12.1f}{cgal['count_all_cells'] / sep:>15.2f}")
print(f"{'count_cells O(1) (ns, wall)':<28}{'':>12}{tm('count_o1_ns'):>12.1f}")
print(f"{'orbit, every vertex':<28}{'':>12}{tm('orbit_ns_per_dart'):>12.1f}")
print(f"{'sew<3> back (ns/op)':<28}{'':>12}{tm('sew_ns_per_op'):>12.1f}")
PY
