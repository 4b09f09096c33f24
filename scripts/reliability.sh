#!/usr/bin/env bash
# Reliability checks (docs/reliability.md), run from the repository root after
# scripts/setup.sh; scripts/test.sh calls it when CI=true or ANIMAT_RELIABILITY=1.
#
#   asan   the whole C++ test suite built with AddressSanitizer + UndefinedBehaviorSanitizer (GCC,
#          RelWithDebInfo, build-asan/), run with ctest
#   tsan   the parallel evaluation tests built with ThreadSanitizer (clang + LLVM's libomp with its
#          Archer OMPT tool; build-tsan/), plus a canary run that must report a planted race
#   fuzz   the four libFuzzer targets of fuzz/ (clang, ASan + UBSan; build-fuzz/), each time-boxed
#          on its seed corpus
#
# Environment:
#   ANIMAT_RELIABILITY_PARTS  which parts to run (default "asan tsan fuzz")
#   ANIMAT_FUZZ_SECONDS       seconds per fuzz target (default 30)
#   ANIMAT_SOAK_GENOMES       genomes in the soak test of the sanitizer builds (default 1000)
#   ANIMAT_JOBS               build and ctest parallelism (default: nproc)
# Exits non-zero if any step fails; the last lines are a summary, one line per step.
set -uo pipefail
cd "$(dirname "$0")/.."

PARTS=${ANIMAT_RELIABILITY_PARTS:-asan tsan fuzz}
FUZZ_SECONDS=${ANIMAT_FUZZ_SECONDS:-30}
JOBS=${ANIMAT_JOBS:-$(nproc)}
export ANIMAT_SOAK_GENOMES=${ANIMAT_SOAK_GENOMES:-1000}
LLVM_LIB=/usr/lib/llvm-14/lib

# clang, its sanitizer and libFuzzer runtimes, and LLVM's OpenMP runtime (with Archer) for TSan.
ANIMAT_EXTRA_APT="clang libclang-rt-14-dev libomp-14-dev ${ANIMAT_EXTRA_APT:-}" scripts/setup.sh || exit 1

SUMMARY=()
PASSED=0
FAILED=0
START=$SECONDS

# step NAME COMMAND...: runs a step, times it, records PASS/FAIL.
step() {
  local name=$1
  shift
  local t0=$SECONDS
  echo "== reliability: $name =="
  if "$@"; then
    SUMMARY+=("$(printf 'PASS  %-22s %5d s' "$name" $((SECONDS - t0)))")
    PASSED=$((PASSED + 1))
    return 0
  fi
  SUMMARY+=("$(printf 'FAIL  %-22s %5d s' "$name" $((SECONDS - t0)))")
  FAILED=$((FAILED + 1))
  return 1
}

skip() {
  SUMMARY+=("$(printf 'FAIL  %-22s   (skipped: %s)' "$1" "$2")")
  FAILED=$((FAILED + 1))
}

# The library at -O1, the sanitizers' documented level (at -O2 an ASan + UBSan build of the suite
# took 6 to 8 times the Release compile); the test programs, where no physics runs, at -O0 through
# ANIMAT_TEST_CXX_FLAGS, which halves their compile. docs/reliability.md has the times.
configure() {  # configure BUILD_DIR COMPILER(gcc|clang) CMAKE_ARGS...
  local dir=$1 compiler=$2
  shift 2
  local cc=gcc cxx=g++
  [[ $compiler == clang ]] && cc=clang cxx=clang++
  CC=$cc CXX=$cxx cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g -DNDEBUG" "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g -DNDEBUG" \
    -DANIMAT_TEST_CXX_FLAGS=-O0 -DANIMAT_BUILD_PYTHON=OFF -DANIMAT_BUILD_BENCH=OFF "$@" >/dev/null
}

# ---- AddressSanitizer + UndefinedBehaviorSanitizer: the whole C++ suite ---------------------------
asan_build() {
  # GCC's -fsanitize=undefined leaves out float-cast-overflow (clang's includes it): add it.
  configure build-asan gcc -DANIMAT_SANITIZE=address,undefined -DANIMAT_BUILD_TESTS=ON \
    "-DCMAKE_CXX_FLAGS=-fsanitize=float-cast-overflow -fno-sanitize-recover=float-cast-overflow" &&
    cmake --build build-asan -j "$JOBS"
}
asan_tests() {
  ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$JOBS" --timeout 1500
}

# ---- ThreadSanitizer: parallel evaluation ---------------------------------------------------------
tsan_build() {
  configure build-tsan clang -DANIMAT_SANITIZE=thread -DANIMAT_BUILD_TESTS=ON &&
    cmake --build build-tsan -j "$JOBS" --target test_reliability test_evolution
}
tsan_tests() {
  # TSan sees the accesses of instrumented code: ours. libomp, Box2D and libstdc++ are Debian's
  # uninstrumented builds, so their internal accesses are ignored (ignore_noninstrumented_modules=1,
  # which libomp itself asks for), and Archer, LLVM's OMPT tool, supplies OpenMP's barrier semantics
  # to TSan. Box2D's lazily-initialised globals are covered by the warm-up contract, not by TSan
  # (docs/reliability.md).
  local env=(OMP_TOOL_LIBRARIES="$LLVM_LIB/libarcher.so" ARCHER_OPTIONS=verbose=0 ANIMAT_SOAK_GENOMES=400
    TSAN_OPTIONS="halt_on_error=1 abort_on_error=1 ignore_noninstrumented_modules=1 second_deadlock_stack=1")
  env "${env[@]}" build-tsan/test_reliability \
    --gtest_filter='ParallelEvaluation.*:Soak.*:ResourceBounds.DevelopmentNeverExceedsMaxCells' || return 1
  env "${env[@]}" build-tsan/test_evolution \
    --gtest_filter='EndToEnd.RealRunIsIdenticalOnOneAndTwoThreads:Evolution.DeterministicForAnyThreadCountAndSeed' || return 1
  # The canary: a planted race in a fitness function must be reported, else this setup is blind.
  local out
  out=$(env "${env[@]}" ANIMAT_TSAN_CANARY=1 build-tsan/test_reliability --gtest_filter='TsanCanary.*' 2>&1)
  if [[ $? -ne 0 && $out == *"ThreadSanitizer: data race"* ]]; then
    echo "TSan canary: the planted race was reported (as it must be)"
  else
    echo "TSan canary: the planted race was NOT reported; the ThreadSanitizer run cannot be trusted"
    echo "$out" | tail -20
    return 1
  fi
}

# ---- libFuzzer, time-boxed ------------------------------------------------------------------------
FUZZ_TARGETS=(genome_json config_toml checkpoint evaluate)
fuzz_build() {
  configure build-fuzz clang -DANIMAT_SANITIZE=address,undefined -DANIMAT_BUILD_FUZZ=ON -DANIMAT_BUILD_TESTS=OFF &&
    cmake --build build-fuzz -j "$JOBS" --target "${FUZZ_TARGETS[@]/#/fuzz_}"
}
fuzz_run() {
  local t=$1 max_len=4096 dict=fuzz/dict/json.dict
  [[ $t == config_toml ]] && max_len=8192 dict=fuzz/dict/toml.dict
  [[ $t == checkpoint ]] && max_len=16384
  mkdir -p "build-fuzz/corpus/$t" build-fuzz/artifacts
  # -timeout: an input running longer is a hang; -rss_limit_mb: a leak or unbounded allocation.
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "build-fuzz/fuzz/fuzz_$t" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -max_len=$max_len \
    -dict=$dict -print_final_stats=1 -artifact_prefix="build-fuzz/artifacts/$t-" \
    "build-fuzz/corpus/$t" "fuzz/corpus/$t" >"build-fuzz/fuzz_$t.log" 2>&1; then
    grep -E "^stat::(number_of_executed_units|new_units_added)" "build-fuzz/fuzz_$t.log" | tr '\n' ' '
    echo
    return 0
  fi
  echo "fuzz_$t FAILED; the end of build-fuzz/fuzz_$t.log:"
  grep -vE "^#[0-9]+ +(NEW|REDUCE|pulse)" "build-fuzz/fuzz_$t.log" | tail -60
  echo "Reproduce: build-fuzz/fuzz/fuzz_$t build-fuzz/artifacts/$t-<crash file>; then add it as a regression"
  echo "test in tests/cpp/test_reliability.cpp (FuzzRegressions.*)."
  return 1
}

for part in $PARTS; do
  case $part in
    asan)
      if step asan-build asan_build; then step asan-ctest asan_tests; else skip asan-ctest "build failed"; fi
      ;;
    tsan)
      if step tsan-build tsan_build; then step tsan-parallel-tests tsan_tests; else skip tsan-parallel-tests "build failed"; fi
      ;;
    fuzz)
      if step fuzz-build fuzz_build; then
        for t in "${FUZZ_TARGETS[@]}"; do step "fuzz-$t" fuzz_run "$t"; done
      else
        for t in "${FUZZ_TARGETS[@]}"; do skip "fuzz-$t" "build failed"; done
      fi
      ;;
    *)
      echo "reliability: unknown part '$part' (expected asan, tsan, fuzz)" >&2
      FAILED=$((FAILED + 1))
      ;;
  esac
done

echo
echo "== reliability summary ($((SECONDS - START)) s in all; fuzz ${FUZZ_SECONDS} s per target) =="
for line in "${SUMMARY[@]}"; do echo "  $line"; done
echo "reliability: $PASSED passed, $FAILED failed"
[[ $FAILED -eq 0 ]]
