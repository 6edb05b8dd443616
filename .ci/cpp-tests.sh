#!/usr/bin/env bash
# C++ tests with CGAL and OpenMesh (issue 5), run by CI and by the README's test command:
#   1. installs cmake libcgal-dev libopenmesh-dev libgtest-dev pkg-config g++ when missing
#      (.ci/apt.sh: apt-get as root or through sudo, else it stops with the line to run);
#   2. reuses the staging prefix that .ci/cmake-checks.sh installed the library into
#      (target/cmake-checks/stage; cargo is asked to bring it up to date, which is a no-op
#      when it is); without one, builds the crate once in release with cmake/ and installs it;
#   3. runs the formfind example on shared models (OFF results and printable solids that
#      test_solid reads with CGAL), builds cpp_tests/ against the installed package
#      (Release, shared library) and runs ctest --output-on-failure;
#   4. builds it again in Debug with AddressSanitizer + UndefinedBehaviorSanitizer (static
#      library) and runs ctest again (LeakSanitizer on when it works on this machine).
# Work files go to $VSR_CPP_TESTS_DIR (default target/cpp-tests).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
export CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-2}
jobs=$CARGO_BUILD_JOBS
work=${VSR_CPP_TESTS_DIR:-$root/target/cpp-tests}
checks=${VSR_CHECK_DIR:-$root/target/cmake-checks}
start=$SECONDS
step() { printf '\n== [%4ds] %s\n' "$((SECONDS - start))" "$*"; }

step "Debian packages"
# shellcheck source=.ci/apt.sh
source .ci/apt.sh
ensure_debian_packages cmake libcgal-dev libopenmesh-dev libgtest-dev pkg-config g++

step "the installed package"
mkdir -p "$work"
if [ -f "$checks/stage/lib/cmake/Voussoir/VoussoirConfig.cmake" ]; then
  stage=$checks/stage
  if [ -f "$checks/build/CMakeCache.txt" ]; then
    # The build tree of .ci/cmake-checks.sh: cargo decides (nothing to do when fresh).
    { cmake --build "$checks/build" -j "$jobs" && cmake --install "$checks/build"; } \
      >"$work/stage-refresh.log" 2>&1 || { cat "$work/stage-refresh.log"; exit 1; }
  fi
  echo "reusing $stage"
else
  stage=$work/stage
  cmake -S cmake -B "$work/voussoir-build" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$stage" >/dev/null
  cmake --build "$work/voussoir-build" -j "$jobs"
  cmake --install "$work/voussoir-build" >/dev/null
  echo "installed into $stage"
fi

if [ ! -d ../shared/data/models ]; then
  echo "note: ../shared/data/models not found; the model tests will say skipped" \
    "(fail in CI or with VSR_REQUIRE_MODELS=1)"
fi

step "formfind on shared models: OFF results and printable solids for test_solid"
formfind_dir=$work/formfind
rm -rf "$formfind_dir"
mkdir -p "$formfind_dir"
if [ -d ../shared/data/models ]; then
  # `cargo test` has built it already; on its own this builds the example once.
  cargo build --quiet --locked --example formfind
  formfind=${CARGO_TARGET_DIR:-$root/target}/debug/examples/formfind
  models=$(cd ../shared/data/models && pwd)
  # model and thickness (0.5% to 2% of its plan diagonal); cheese and hex have holes,
  # whose rims get walls too.
  for entry in "lilium 0.02" "neumunster 0.3" "cheese 0.02" "hex 0.01" "dome_with_doors 0.15"; do
    read -r m t <<<"$entry"
    "$formfind" "$models/$m.obj" --supports "$models/$m.json" \
      --out "$formfind_dir/$m.off" --solid "$t" "$formfind_dir/$m-solid.off" \
      --report "$formfind_dir/$m.json" --pictures "$formfind_dir/$m-pictures" >/dev/null
    echo "$m $t" >>"$formfind_dir/manifest.txt"
  done
  # The thickest solid formfind accepts: asked for far too much, it names the most that fits
  # (`allows at most X there`); 97% of that must still be free of self-intersections.
  mkdir -p "$formfind_dir/edge"
  for m in lilium hex four_holes three_pillar; do
    run=("$models/$m.obj" --supports "$models/$m.json" --out "$formfind_dir/edge/$m.off"
         --report "$formfind_dir/edge/$m.json" --pictures "$formfind_dir/edge/$m-pictures")
    limit=$({ "$formfind" "${run[@]}" --solid 1e6 "$formfind_dir/edge/x.off" 2>&1 >/dev/null \
                || true; } | sed -n 's/.*allows at most \([0-9.e+-]*\) there.*/\1/p')
    [ -n "$limit" ] || { echo "formfind named no largest thickness for $m" >&2; exit 1; }
    t=$(awk -v l="$limit" 'BEGIN { printf "%.6g", 0.97 * l }')
    "$formfind" "${run[@]}" --solid "$t" "$formfind_dir/edge/$m-solid.off" >/dev/null
    echo "$m $t" >>"$formfind_dir/edge/manifest.txt"
  done
  echo "wrote $formfind_dir"
fi

step "cpp_tests: Release, shared library"
cmake -S cpp_tests -B "$work/release" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$stage" -DVSR_FORMFIND_DIR="$formfind_dir" >/dev/null
cmake --build "$work/release" -j "$jobs"
step "ctest (Release)"
ctest --test-dir "$work/release" --output-on-failure -j "$jobs"

step "cpp_tests: Debug, static library, AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S cpp_tests -B "$work/asan" -DCMAKE_BUILD_TYPE=Debug -DVSR_STATIC=ON -DVSR_SANITIZE=ON \
  -DCMAKE_PREFIX_PATH="$stage" -DVSR_FORMFIND_DIR="$formfind_dir" >/dev/null
cmake --build "$work/asan" -j "$jobs"
# LeakSanitizer needs ptrace, which some containers forbid: probe it with a test binary.
leaks=1
if ! ASAN_OPTIONS=detect_leaks=1 "$work/asan/test_contract" \
     --gtest_filter=Contract.StatusNamesAndVersions >"$work/lsan-probe.log" 2>&1; then
  if grep -q "LeakSanitizer has encountered a fatal error" "$work/lsan-probe.log"; then
    leaks=0
    echo "note: LeakSanitizer does not work here (ptrace); running without leak detection"
  fi
fi
export ASAN_OPTIONS="detect_leaks=$leaks:abort_on_error=0:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
step "ctest (Debug, ASan + UBSan, detect_leaks=$leaks)"
ctest --test-dir "$work/asan" --output-on-failure -j "$jobs"

printf '\ncpp-tests: all passed in %ds\n' "$((SECONDS - start))"
