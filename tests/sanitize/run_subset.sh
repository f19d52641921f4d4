#!/usr/bin/env bash
# The CI-sized sanitizer subset: configures a build of its own with AddressSanitizer and
# UndefinedBehaviorSanitizer (-DKINESWEEP_SANITIZE=address,undefined, -O1 -g, assertions on), builds
# kinesweep and the fast GoogleTest executables of the model, IK, methods, study parser and store, and
# runs them, the three fuzz corpus checks (study, URDF, results files) and kinesweep on small shipped
# studies (run, resume of the finished file, info, query, sensitivity). Any sanitizer report ends the
# process that made it with a non-zero status (-fno-sanitize-recover=all, halt_on_error); the script
# then names what failed and exits 1.
#   usage: tests/sanitize/run_subset.sh [BUILD_DIR]   (default: build-sanitize in the source tree)
#   environment: CC, CXX (the compilers; default cmake's choice), KS_SANITIZE (default
#   address,undefined), KS_JOBS (parallel build jobs, default 2), KS_CMAKE_ARGS (more cmake options),
#   KS_EXTRA_TARGETS (more targets to build, e.g. fuzz_results with KS_CMAKE_ARGS=-DKINESWEEP_FUZZ=ON)
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$src/build-sanitize}
jobs=${KS_JOBS:-2}
launcher=()
if command -v ccache > /dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache); fi

tests=(test_kinematics test_dynamics test_ik test_ik_cycle test_quintic_path test_trajectory
       test_trajectory_bounds test_sample_metrics test_study test_study_guards test_store test_store_rows
       test_store_histories test_store_landscapes)
checks=(study_corpus_check urdf_corpus_check results_corpus_check)

start=$(date +%s)
# shellcheck disable=SC2086  # KS_CMAKE_ARGS: options split at spaces
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DKINESWEEP_SANITIZE="${KS_SANITIZE:-address,undefined}" \
  -DKINESWEEP_TESTS=ON "${launcher[@]}" ${KS_CMAKE_ARGS:-} > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
mv "$build.configure.log" "$build/sanitize_configure.log"
cmake --build "$build" -j"$jobs" --target kinesweep "${tests[@]}" "${checks[@]}" ${KS_EXTRA_TARGETS:-}
built=$(date +%s)

# halt_on_error: the first report ends the process. The tests whose readers follow a live writer
# (StoreConcurrent.*, in test_store) need the HDF5 leak suppression tests/CMakeLists.txt explains.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:strict_init_order=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export LSAN_OPTIONS=suppressions=$src/tests/lsan_hdf5.supp:fast_unwind_on_malloc=0
failed=()
step() {  # step NAME COMMAND...: run, log to $build/sanitize_logs/NAME.log, record a failure
  local name=$1 log="$build/sanitize_logs/$1.log"
  shift
  local t0=$SECONDS
  if "$@" > "$log" 2>&1; then
    echo "ok      $name ($((SECONDS - t0)) s)"
  else
    echo "FAILED  $name ($((SECONDS - t0)) s): $log"
    grep -m 5 -E 'ERROR: (Address|Leak)Sanitizer|runtime error:|FAILED|error:' "$log" || tail -n 5 "$log"
    failed+=("$name")
  fi
}
mkdir -p "$build/sanitize_logs"
work="$build/sanitize_runs"
rm -rf "$work" && mkdir -p "$work"
for t in "${tests[@]}"; do step "$t" "$build/tests/$t"; done
step study_corpus_check bash -c "cd '$src/studies' && '$build/tests/study_corpus_check' '$src'/studies/*.toml '$src'/tests/fuzz/found/*.toml"
step urdf_corpus_check bash -c "'$build/tests/urdf_corpus_check' '$src'/studies/robots/*.urdf '$src'/tests/fuzz/urdf_bad/*.urdf '$src'/tests/fuzz/found/*.urdf"
step results_corpus_seeds sh "$src/tests/fuzz/make_results_seeds.sh" "$build/kinesweep" "$work/seeds"
step results_corpus_check bash -c "'$build/tests/results_corpus_check' '$work/seeds' '$src/tests/format3/mixed_v3.h5' \$(ls '$src'/tests/fuzz/found/*.h5 2>/dev/null)"
ks="$build/kinesweep"
for study in thesis_table4 examples_lhs ik_scara; do
  step "run_$study" "$ks" run "$src/studies/$study.toml" -o "$work/$study.h5" -q
  step "resume_$study" "$ks" run "$src/studies/$study.toml" -o "$work/$study.h5" -q --resume
  step "info_$study" "$ks" info "$work/$study.h5"
  step "query_$study" "$ks" query "$work/$study.h5" --columns all --format csv --limit 200
  step "group_$study" "$ks" query "$work/$study.h5" --group-by block --agg count
done
step query_history "$ks" query "$work/ik_scara.h5" --run 7 --history all
step sensitivity_grid_design "$ks" sensitivity "$work/seeds/grid_design.h5" --bootstrap 50 --format json
step query_optimization "$ks" query "$work/seeds/optimization.h5" --optimization 1b_polish

end=$(date +%s)
echo "sanitizer subset (${KS_SANITIZE:-address,undefined}): build $((built - start)) s, runs $((end - built)) s, ${#failed[@]} failed"
if ((${#failed[@]})); then
  echo "failed: ${failed[*]}"
  exit 1
fi
