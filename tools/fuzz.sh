#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang, ASan and UBSan into
# ./build-fuzz (the normal ./build is untouched), runs each for SECONDS
# (default 60) on a corpus seeded from fuzz/corpus, and prints a table:
# target, executions, exec/s, findings. Exits 1 when anything was found; the
# reproducers are in build-fuzz/findings/RUN/TARGET/ (replay one with
# `build-fuzz/fuzz/TARGET FILE`). Not part of ctest: it takes minutes.
#   bash tools/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(spec_fuzzer expression_fuzzer request_fuzzer proto_request_fuzzer proto_batch_fuzzer
                                     step_fuzzer iges_fuzzer nurbs_fuzzer obj_fuzzer ply_fuzzer)

bash tools/setup-debian.sh
# The fuzz build alone needs clang and its runtimes (libFuzzer, ASan, UBSan);
# Debian ships libFuzzer for clang 14 in libclang-rt-14-dev.
need=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "fuzz: installing ${need[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${need[@]}" >&2
fi

# SFC_FUZZ_SANITIZERS=undefined: UBSan alone, in ./build-fuzz-undefined
# (several times faster on the CAD readers; finds crashes, hangs and memory
# exhaustion, not memory errors that do not crash). Default: ASan and UBSan,
# in ./build-fuzz.
sanitizers="${SFC_FUZZ_SANITIZERS:-address,undefined}"
out=build-fuzz
[ "$sanitizers" = "address,undefined" ] || out="build-fuzz-${sanitizers//,/-}"
mkdir -p "$out"
if [ ! -f "$out/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$out" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSFC_BUILD_FUZZERS=ON -DSFC_FUZZ_SANITIZERS="$sanitizers" -DSFC_BUILD_TESTS=OFF \
    -DSFC_BUILD_BENCHMARKS=OFF > "$out/build.log" 2>&1 \
    || { cat "$out/build.log"; exit 1; }
fi
# Only the targets asked for (and the fixture writer the STEP/IGES seeds need).
build_targets=("${targets[@]}")
case " ${targets[*]} " in *" step_fuzzer "*|*" iges_fuzzer "*) build_targets+=(make_cad_fixtures) ;; esac
cmake --build "$out" -j2 --target "${build_targets[@]}" >> "$out/build.log" 2>&1 || { tail -50 "$out/build.log"; exit 1; }

# Seeds: text files as they are; protobuf text format (.txtpb) encoded to wire bytes.
declare -A message=([proto_request_fuzzer]=sfcsampler.v1.SampleRequest [proto_batch_fuzzer]=sfcsampler.v1.SampleResponse)
seed_dir() { local t="${1%_fuzzer}"; echo "fuzz/corpus/$t"; }
findings_dir="$out/findings/$(date -u +%Y%m%dT%H%M%S)"
for t in "${targets[@]}"; do
  corpus="$out/corpus/$t"
  mkdir -p "$corpus" "$findings_dir/$t"
  # STEP and IGES seeds: the project's fixtures, written by the fuzz build.
  case "$t" in
    step_fuzzer|iges_fuzzer)
      ext="${t%_fuzzer}"
      fixtures=$(mktemp -d)
      ASAN_OPTIONS=detect_leaks=0 "$out/cad/make_cad_fixtures" "$fixtures" > /dev/null
      cp "$fixtures"/*."$ext" "$corpus/"
      rm -rf "$fixtures" ;;
  esac
  src=$(seed_dir "$t")
  [ -d "$src" ] || continue
  for f in "$src"/*; do
    case "$f" in
      *.txtpb)
        protoc --proto_path=proto --encode="${message[$t]}" proto/sfcsampler/v1/sampler.proto \
          < "$f" > "$corpus/seed-$(basename "$f" .txtpb)" ;;
      *) cp "$f" "$corpus/" ;;
    esac
  done
done

# One target for `seconds`: libFuzzer stops at its first finding, so it is
# restarted (keeping the corpus) until the time is used up. It is also
# restarted every SFC_FUZZ_RUNS_PER_PROCESS executions (default 100 000), as
# the server starts a fresh check process for every CAD file: OpenCASCADE
# leaks tens of KB on many broken files, which would otherwise fill the RSS
# limit within minutes under ASan.
runs_per_process="${SFC_FUZZ_RUNS_PER_PROCESS:-100000}"
printf '%-22s %8s %12s %10s %9s %s\n' target seconds executions exec/s findings "restarts (state accumulated over the run)"
total_findings=0
for t in "${targets[@]}"; do
  dict=()
  case "$t" in spec_fuzzer|expression_fuzzer) dict=(-dict=fuzz/spec.dict) ;; esac
  # The OpenCASCADE targets run as the server does: the kernel's own signal
  # handlers turn a fault inside its readers (a null dereference on a broken
  # file) into a Standard_Failure, which Load returns as INVALID_ARGUMENT
  # (cad/internal/kernel_setup.h). ASan and libFuzzer leave SEGV, SIGBUS and
  # SIGFPE to them there (UBSan too; other checks stay on). The kernel's
  # process-wide caches are not leaks: no leak check either.
  asan="${ASAN_OPTIONS:-}"
  ubsan="${UBSAN_OPTIONS:-}"
  case "$t" in
    step_fuzzer|iges_fuzzer|nurbs_fuzzer)
      dict+=(-detect_leaks=0 -handle_segv=0 -handle_bus=0 -handle_fpe=0)
      asan="handle_segv=0:handle_sigbus=0:handle_sigfpe=0:detect_leaks=0${asan:+:$asan}"
      ubsan="handle_segv=0:handle_sigbus=0:handle_sigfpe=0${ubsan:+:$ubsan}" ;;
  esac
  log="$findings_dir/$t/fuzz.log"
  : > "$log"
  start=$(date +%s)
  execs=0
  restarts=0
  while :; do
    left=$((seconds - ($(date +%s) - start)))
    [ "$left" -gt 0 ] || break
    run_log=$(mktemp)
    # The target writes each input to last_input before running it
    # (fuzz/model_fuzz.h), so an input that deadlocks the process is kept.
    last_input="$findings_dir/$t/.last-input"
    SFC_FUZZ_LAST_INPUT="$last_input" ASAN_OPTIONS="$asan" UBSAN_OPTIONS="$ubsan" \
      "$out/fuzz/$t" -max_total_time="$left" -runs="$runs_per_process" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
      -print_final_stats=1 "${dict[@]}" -artifact_prefix="$findings_dir/$t/" \
      "$out/corpus/$t" > "$run_log" 2>&1 &
    pid=$!
    # Watchdog: a process that used no CPU for 30 s is deadlocked (a fault
    # inside malloc leaves its lock taken, and libFuzzer's own crash report
    # then waits on it), which libFuzzer's timeout cannot see. It is killed
    # and its last input kept as deadlock-SHA1.
    ticks=-1; idle=0
    while kill -0 "$pid" 2>/dev/null; do
      sleep 5
      now=$(awk '{print $14 + $15}' "/proc/$pid/stat" 2>/dev/null || echo gone)
      [ "$now" = gone ] && break
      if [ "$now" = "$ticks" ]; then idle=$((idle + 1)); else idle=0; ticks=$now; fi
      if [ "$idle" -ge 6 ]; then
        kill -9 "$pid" 2>/dev/null || true
        [ -f "$last_input" ] && cp "$last_input" "$findings_dir/$t/deadlock-$(sha1sum < "$last_input" | cut -c1-40)"
        echo "fuzz: $t deadlocked (no CPU for 30 s); killed, its last input kept" >> "$run_log"
        break
      fi
    done
    wait "$pid" 2>/dev/null || true
    # A stop whose input alone passes is state the run accumulated, not that
    # input's: OpenCASCADE leaks tens of KB on many broken files
    # (bench/parse_memory --repeat shows it), its IGES reader keeps state from
    # one file to the next, and a fault it turns into an exception can leave
    # the heap or a lock broken for later files (a crash or deadlock then); a
    # slow unit can also be a fuzzer at nice 19 starved by other work. The
    # server reads every CAD file in a fresh process. So every stop's input is
    # replayed alone in a fresh process (killed after 60 s); if it passes it
    # is set aside (in accumulated/) and the run goes on; one that fails alone
    # is a finding.
    for stop in "$findings_dir/$t"/oom-* "$findings_dir/$t"/timeout-* "$findings_dir/$t"/deadlock-* \
                "$findings_dir/$t"/crash-* "$findings_dir/$t"/slow-unit-*; do
      [ -e "$stop" ] || continue
      if ASAN_OPTIONS="$asan" UBSAN_OPTIONS="$ubsan" timeout -s KILL 60 "$out/fuzz/$t" -timeout=10 -rss_limit_mb=2048 \
           -malloc_limit_mb=1024 "${dict[@]}" "$stop" > /dev/null 2>&1; then
        mkdir -p "$findings_dir/$t/accumulated"
        mv "$stop" "$findings_dir/$t/accumulated/"
        restarts=$((restarts + 1))
      fi
    done
    n=$(sed -n 's/^stat::number_of_executed_units: *//p' "$run_log" | tail -1)
    # A run killed or aborted before its final stats: its last progress line (or none).
    [ -n "$n" ] || n=$(grep -o '^#[0-9]*' "$run_log" | tr -d '#' | sort -n | tail -1 || true)
    execs=$((execs + ${n:-0}))
    cat "$run_log" >> "$log"
    rm -f "$run_log"
    # Stop early when a target cannot even start.
    grep -q "INFO: Seed:" "$log" || { echo "fuzz: $t did not start; see $log" >&2; break; }
  done
  elapsed=$(( $(date +%s) - start ))
  findings=$(find "$findings_dir/$t" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' \
    -o -name 'timeout-*' -o -name 'oom-*' -o -name 'slow-unit-*' -o -name 'deadlock-*' \) | wc -l)
  total_findings=$((total_findings + findings))
  rate=$(awk -v e="$execs" -v s="$elapsed" 'BEGIN {printf "%d", (s > 0 ? e / s : 0)}')
  printf '%-22s %8d %12d %10d %9d %d\n' "$t" "$elapsed" "$execs" "$rate" "$findings" "$restarts"
done
if [ "$total_findings" -gt 0 ]; then
  echo "fuzz: $total_findings finding(s); reproducers and logs in $findings_dir/" >&2
  find "$findings_dir" -maxdepth 2 -type f ! -name fuzz.log ! -name .last-input >&2
  exit 1
fi
