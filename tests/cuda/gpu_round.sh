#!/usr/bin/env bash
# One round on a GPU machine, from the repository root, with the build staged into .gpu by
# tests/cuda/stage.sh (here: tests/cuda/stage.sh build-gpu), carried as .gpu:
#   tests/cuda/gpu_round.sh [tests] [sanitize] [reports] [bench] [bench-quick] [bench-ab]
#                           [accuracy] [io] [io-ab]
# (bench-ab and io-ab also need an earlier commit's snag staged as .gpu/base/snag.)
# Logs go to $OUT (or ./out); a short table is printed last.
set -uo pipefail
out=${OUT:-out}; mkdir -p "$out"
source .gpu/env.sh
export SNAG_DATA_DIR=${SNAG_DATA_DIR:-$PWD/.gpu/extra/data}
steps=("$@"); [ ${#steps[@]} -gt 0 ] || steps=(tests sanitize reports bench)
summary=()
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$out/gpu.txt"
# alternate NAME TIMEOUT PATTERN ARGS...: `snag ARGS` of the binary staged as .gpu/base/snag
# and of this build's, alternating, twice each, into $out/NAME_{base,new}{1,2}.txt; the lines
# matching PATTERN are collected in $out/NAME_ab.txt. Nothing without a base binary.
alternate() {
  local name=$1 limit=$2 pattern=$3; shift 3
  [ -x .gpu/base/snag ] || return 0
  for r in 1 2; do
    for v in base new; do
      local bin=snag; [ $v = base ] && bin=.gpu/base/snag
      timeout "$limit" $bin "$@" >"$out/${name}_$v$r.txt" 2>"$out/${name}_$v$r.err"
      echo "== $v$r rc=$?" >>"$out/${name}_ab.txt"
      grep -E "$pattern" "$out/${name}_$v$r.txt" >>"$out/${name}_ab.txt"
    done
  done
}
ab_summary() {
  if [ -x .gpu/base/snag ]; then echo "base and new twice each: $out/$1_ab.txt"
  else echo "skipped: no .gpu/base/snag"; fi
}
tests_rc=0
for step in "${steps[@]}"; do
  t0=$(date +%s)
  # A failing test suite makes the later steps moot: stop there (device time is scarce).
  [ $tests_rc -eq 0 ] || { summary+=("$step             skipped: the CUDA tests failed"); continue; }
  case $step in
    tests)
      # Not brief: each test's time is in the log (device time is scarce; the slowest are named).
      snag_cuda_tests >"$out/cuda_tests.log" 2>&1; rc=$?
      summary+=("cuda tests        rc=$rc $(grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$out/cuda_tests.log" | tr '\n' ' ')")
      summary+=("  slowest: $(grep -E '^\[       OK \]' "$out/cuda_tests.log" | sed -E 's/.*OK \] ([^ ]+) \(([0-9]+) ms\)/\2 \1/' | sort -rn | head -4 | awk '{printf "%s %.0fs; ", $2, $1/1000}')")
      tests_rc=$rc
      grep -E '^\[  FAILED  \]' "$out/cuda_tests.log" | head -20
      SNAG_EXECUTABLE=$(command -v snag) snag_cli_tests --gtest_brief=1 >"$out/cli_tests.log" 2>&1; rc=$?
      summary+=("cli tests         rc=$rc $(grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$out/cli_tests.log" | tr '\n' ' ')")
      ;;
    sanitize)
      # memcheck: every test but the two largest; racecheck (much slower, and only shared
      # memory is its business): small tests that still run every kernel (build, refit,
      # quality, scan, narrow phase, expansion, the one-block finish, the growth and the
      # device-wide sorts of the large path).
      # CudaDeviceBuffer's test fails a cudaMalloc on purpose, which memcheck reports as an API
      # error: it runs on its own with those reports off.
      memcheck_filter='-CudaDetect.SharedDataFilesMatchTheCpu:CudaDetect.RandomSoupsWithFilterDecisionsMatchTheCpu:CudaDeviceBuffer.*'
      racecheck_filter='CudaDetect.HandBuilt*:CudaDetect.MoreResults*:CudaBackend.EmptyAndSingle*:CudaScene.ScenesMatchTheCpuAndBruteForce*'
      for tool in memcheck racecheck; do
        filter=$memcheck_filter; [ $tool = racecheck ] && filter=$racecheck_filter
        timeout ${SANITIZE_TIMEOUT:-400} compute-sanitizer --tool $tool --error-exitcode 97 snag_cuda_tests --gtest_brief=1 \
          --gtest_filter="$filter" >"$out/sanitize_$tool.log" 2>&1; rc=$?
        summary+=("$tool         rc=$rc $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/sanitize_$tool.log" | tail -1) $(grep -E '^\[  (PASSED|FAILED) ' "$out/sanitize_$tool.log" | tr '\n' ' ')")
      done
      timeout ${SANITIZE_TIMEOUT:-400} compute-sanitizer --tool memcheck --report-api-errors no \
        --error-exitcode 97 snag_cuda_tests --gtest_brief=1 --gtest_filter='CudaDeviceBuffer.*' \
        >"$out/sanitize_memcheck_oom.log" 2>&1; rc=$?
      summary+=("memcheck (OOM)   rc=$rc $(grep -E 'ERROR SUMMARY' "$out/sanitize_memcheck_oom.log" | tail -1) $(grep -E '^\[  (PASSED|FAILED) ' "$out/sanitize_memcheck_oom.log" | tr '\n' ' ')")
      ;;
    reports)
      # Every sample and shared-data file checked on both backends: the reports must agree.
      rm -rf /tmp/rep; mkdir -p /tmp/rep; n=0; bad=0
      # Each input is the arguments of one run: samples, data files, and scenes (an obstacle
      # still and moving, groups split).
      inputs=(samples/drape "samples/drape --obstacle samples/drape_sphere.obj"
              "samples/drape/drape.%04d.obj --obstacle samples/drape/drape.%04d.obj"
              $(find "$SNAG_DATA_DIR" -name '*.ply' | sort))
      [ -f samples/drape-scene.json ] && inputs+=("--scene samples/drape-scene.json")
      for input in "${inputs[@]}"; do
        n=$((n+1))
        # shellcheck disable=SC2086  # an input is several arguments
        for b in cpu cuda; do snag check $input --backend $b --out /tmp/rep/$n-$b --quiet >/dev/null 2>>"$out/reports.log"; echo "$input $b rc=$?" >>"$out/reports.log"; done
        tests/cuda/compare_reports.py "$input" /tmp/rep/$n-cpu /tmp/rep/$n-cuda >>"$out/reports.log" 2>&1 || bad=$((bad+1))
      done
      summary+=("reports           $n inputs, $(grep -c ' same$' "$out/reports.log") the same, $bad differ between cpu and cuda")
      ;;
    bench)
      snag bench gpu --data "$SNAG_DATA_DIR" >"$out/bench_gpu.txt" 2>"$out/bench_gpu.err"; rc=$?
      summary+=("bench gpu         rc=$rc")
      ;;
    accuracy)
      snag bench accuracy --data "$SNAG_DATA_DIR" --out "$out/accuracy" >"$out/bench_accuracy.txt" 2>"$out/bench_accuracy.err"; rc=$?
      summary+=("bench accuracy    rc=$rc")
      ;;
    io)
      snag bench io --data "$SNAG_DATA_DIR" ${IO_ARGS:-} >"$out/bench_io.txt" 2>"$out/bench_io.err"; rc=$?
      summary+=("bench io          rc=$rc")
      ;;
    bench-ab)
      # The quick bench of the binary staged as .gpu/base/snag (an earlier commit's) and of this
      # build's, alternating, twice each: side by side in one lease, as A/B comparisons need.
      alternate bench 200 '^(cloth|n-body)' bench gpu --data "$SNAG_DATA_DIR" --large 0 --frames 30 --cpu-frames 1
      summary+=("bench gpu (A/B)   $(ab_summary bench)")
      ;;
    io-ab)
      # snag bench io (IO_ARGS) the same way; the sequence tables' rows are collected.
      # shellcheck disable=SC2086  # IO_ARGS is several arguments
      alternate io 300 '^(Sequence|cpu |cuda )' bench io --data "$SNAG_DATA_DIR" ${IO_ARGS:-}
      summary+=("bench io (A/B)    $(ab_summary io)")
      ;;
    bench-quick)
      snag bench gpu --data "$SNAG_DATA_DIR" --large 0 --frames 30 --cpu-frames 2 >"$out/bench_gpu.txt" 2>"$out/bench_gpu.err"; rc=$?
      summary+=("bench gpu (quick) rc=$rc")
      ;;
  esac
  summary[-1]="${summary[-1]}  [$(( $(date +%s) - t0 )) s]"
done
[ -f "$out/bench_gpu.txt" ] && cat "$out/bench_gpu.txt"
[ -f "$out/bench_ab.txt" ] && cat "$out/bench_ab.txt"
[ -f "$out/io_ab.txt" ] && cat "$out/io_ab.txt"
[ -f "$out/bench_io.txt" ] && cat "$out/bench_io.txt"
printf '%s\n' "${summary[@]}"
