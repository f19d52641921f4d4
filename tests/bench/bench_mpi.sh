#!/usr/bin/env bash
# Distributed-sweep benchmark: wall time of one study, single process vs mpirun with 1 and 2 ranks,
# 1 and 2 TBB threads per rank. Prints one line per combination (the figures of the README).
# usage: tests/bench/bench_mpi.sh BUILD_DIR [HISTORIES]     (HISTORIES: none (default) | every=5 | full)
set -euo pipefail
KS="$(cd "${1:?usage: bench_mpi.sh BUILD_DIR [HISTORIES]}" && pwd)/kinesweep"
HIST="${2:-none}"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
cat > "$TMP/bench.toml" <<'TOML'
[study]
name = "bench_mpi"

[[block]]
name = "weighted"
kind = "trajectory"
method = "local_weighted"
[block.axes]
alpha1A = { from = -20, to = 30, step = 0.25 }
k = { from = 0, to = 1, count = 11 }

[[block]]
name = "lm_basin"
kind = "ik"
problem = "scara"
method = "lm"
lambda = 0.1
[block.axes]
q0_1 = { from = -180, to = 180, count = 151 }
q0_2 = { from = -180, to = 180, count = 151 }
TOML
MPI=(mpirun --oversubscribe --allow-run-as-root --bind-to none)
t() {  # label, command...
  local label="$1"; shift
  rm -f "$TMP"/out.h5*
  local s e
  s=$(date +%s.%N)
  "$@" "$TMP/bench.toml" -o "$TMP/out.h5" -q --histories "$HIST" > "$TMP/log" 2>&1 || { cat "$TMP/log"; exit 1; }
  e=$(date +%s.%N)
  printf '%-34s %7.2f s   %s\n' "$label" "$(echo "$e - $s" | bc)" "$(grep -o 'sweep .*merge [0-9.]* s' "$TMP/log" || true)"
}
echo "study: 2211 trajectory + 22801 ik runs, histories=$HIST, $(nproc) cores"
t "single process, 1 thread" "$KS" run --threads 1
t "single process, 2 threads" "$KS" run --threads 2
t "mpirun -np 1, 1 thread/rank" "${MPI[@]}" -np 1 "$KS" run --threads 1
t "mpirun -np 1, 2 threads/rank" "${MPI[@]}" -np 1 "$KS" run --threads 2
t "mpirun -np 2, 1 thread/rank" "${MPI[@]}" -np 2 "$KS" run --threads 1
t "mpirun -np 2, 2 threads/rank" "${MPI[@]}" -np 2 "$KS" run --threads 2
