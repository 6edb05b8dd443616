#!/usr/bin/env bash
# C ABI checks (issue 4), run by CI and by the README's test command:
#   1. include/voussoir.h compiles alone as C11 and as C++17 with -Wall -Wextra -Wpedantic -Werror;
#      include/voussoir.hpp and each adapter (voussoir/cgal.hpp, voussoir/openmesh.hpp) alone as
#      C++17 with -Wall -Wextra -Werror -pedantic, under g++ and under clang++ when there is one;
#   2. cmake/ builds the library with cargo (release) and installs it into a staging prefix;
#      the shared library has its SONAME;
#   3. examples/ (C dome, C hostile-input and assessment tests, C++ OpenMesh and CGAL
#      examples) builds against the installed package with find_package(Voussoir CONFIG
#      REQUIRED) and runs under ctest: shared library; static library with AddressSanitizer +
#      UBSan (Debug);
#   4. the C dome, the hostile-input and assessment tests and a C++ square (voussoir.hpp)
#      build with `pkg-config --cflags --libs voussoir` alone;
#   5. the hostile-input and assessment tests link against the build tree (cargo's
#      target/release, where the CMake build leaves the SONAME'd library and its
#      libvoussoir.so.1 link) with an rpath;
#   6. the Rust example (examples/dome.rs) runs.
# Needs cmake, pkg-config, a C/C++ compiler, OpenMesh and CGAL (Debian: cmake pkg-config g++
# libopenmesh-dev libcgal-dev); clang++ (Debian: clang) is optional. Work files go to $VSR_CHECK_DIR (default target/cmake-checks).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
export CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-2}
work=${VSR_CHECK_DIR:-$root/target/cmake-checks}
stage=$work/stage
jobs=${CARGO_BUILD_JOBS}

missing=()
for tool in cmake pkg-config cc c++; do
  command -v "$tool" >/dev/null || missing+=("$tool")
done
[ -f /usr/include/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh ] || missing+=("OpenMesh headers")
[ -f /usr/include/CGAL/Surface_mesh.h ] || missing+=("CGAL headers")
if [ ${#missing[@]} -gt 0 ]; then
  echo "cmake-checks: missing ${missing[*]}; on Debian: apt-get install -y cmake pkg-config g++ libopenmesh-dev libcgal-dev" >&2
  exit 1
fi
rm -rf "$work"
mkdir -p "$work"
step() { printf '\n== %s\n' "$*"; }

step "header alone: C11 and C++17, -Wall -Wextra -Wpedantic -Werror"
printf '#include <voussoir.h>\nint main(void) { return vsr_abi_version() == VSR_ABI_VERSION ? 0 : 1; }\n' >"$work/header.c"
cp "$work/header.c" "$work/header.cpp"
cc -std=c11 -Wall -Wextra -Wpedantic -Werror -I include -fsyntax-only "$work/header.c"
c++ -std=c++17 -Wall -Wextra -Wpedantic -Werror -I include -fsyntax-only "$work/header.cpp"
echo ok

step "C++ headers alone: C++17, -Wall -Wextra -Werror -pedantic, g++ and clang++"
cxx_compilers=(g++)
clangxx=$(command -v clang++ || compgen -c clang++- | sort -V | tail -n 1 || true)
if [ -n "$clangxx" ] && command -v "$clangxx" >/dev/null; then
  cxx_compilers+=("$clangxx")
else
  echo "note: no clang++ found; checking the C++ headers with g++ only (Debian: apt-get install clang)"
fi
for header in voussoir.hpp voussoir/cgal.hpp voussoir/openmesh.hpp; do
  printf '#include <%s>\nint main() { return voussoir::abi_compatible() ? 0 : 1; }\n' "$header" \
    >"$work/alone.cpp"
  for cxx in "${cxx_compilers[@]}"; do
    "$cxx" -std=c++17 -Wall -Wextra -Werror -pedantic -I include -fsyntax-only "$work/alone.cpp"
    echo "$header: $cxx ok"
  done
done

step "cmake/: cargo release build, install into $stage"
cmake -S cmake -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$stage" >/dev/null
cmake --build "$work/build" -j "$jobs"
cmake --install "$work/build"
soname=$(readelf -d "$stage/lib/libvoussoir.so.1" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[ "$soname" = "libvoussoir.so.1" ] || { echo "SONAME is '$soname'" >&2; exit 1; }
echo "SONAME $soname"

step "examples/ against the installed package: find_package(Voussoir), shared library"
cmake -S examples -B "$work/examples" -DCMAKE_PREFIX_PATH="$stage" >/dev/null
cmake --build "$work/examples" -j "$jobs"
ctest --test-dir "$work/examples" --output-on-failure

step "examples/ against the installed package: static library, ASan + UBSan (Debug)"
cmake -S examples -B "$work/examples-asan" -DCMAKE_PREFIX_PATH="$stage" \
  -DCMAKE_BUILD_TYPE=Debug -DVSR_STATIC=ON -DVSR_SANITIZE=ON >/dev/null
cmake --build "$work/examples-asan" -j "$jobs"
ctest --test-dir "$work/examples-asan" --output-on-failure

step "pkg-config --cflags --libs voussoir"
export PKG_CONFIG_PATH="$stage/lib/pkgconfig"
pkg-config --modversion voussoir
flags=$(pkg-config --cflags --libs voussoir)
libdir=$(pkg-config --variable=libdir voussoir)
mkdir -p "$work/pkgconfig"
for prog in examples/c/dome.c tests/c/hostile.c tests/c/assess.c tests/c/warm.c; do
  exe="$work/pkgconfig/$(basename "$prog" .c)"
  # shellcheck disable=SC2086
  cc -std=c11 -Wall -Wextra -Wpedantic -Werror "$prog" -o "$exe" $flags -lm -Wl,-rpath,"$libdir"
  "$exe" >"$exe.log" || { cat "$exe.log"; exit 1; }
  tail -n 1 "$exe.log"
done
# The C++ header from the same flags: a square of 4 triangles form found through voussoir.hpp.
cat >"$work/pkgconfig/square.cpp" <<'CPP'
#include <voussoir.hpp>
#include <iostream>
int main() {
    const voussoir::Mesh mesh({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0.3},
                              {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4}, {0, 1, 2, 3});
    const voussoir::Result result = voussoir::form_find(mesh);
    std::cout << "voussoir.hpp: " << result.termination_message() << "\n";
    return result.termination().converged() ? 0 : 1;
}
CPP
# shellcheck disable=SC2086
c++ -std=c++17 -Wall -Wextra -Wpedantic -Werror "$work/pkgconfig/square.cpp" -o "$work/pkgconfig/square" \
  $flags -Wl,-rpath,"$libdir"
"$work/pkgconfig/square"

step "the build tree: -L target/release -lvoussoir with an rpath"
tree=${CARGO_TARGET_DIR:-$root/target}/release
mkdir -p "$work/tree"
cc -std=c11 -Wall -Wextra -Wpedantic -Werror -I include tests/c/hostile.c -o "$work/tree/hostile" \
  -L "$tree" -lvoussoir -lm -Wl,-rpath,"$tree"
readelf -d "$work/tree/hostile" | grep -q 'Shared library: \[libvoussoir.so.1\]' \
  || { echo "the build tree's library lacks the SONAME libvoussoir.so.1" >&2; exit 1; }
"$work/tree/hostile" >"$work/tree/hostile.log" || { cat "$work/tree/hostile.log"; exit 1; }
tail -n 1 "$work/tree/hostile.log"
cc -std=c11 -Wall -Wextra -Wpedantic -Werror -I include tests/c/assess.c -o "$work/tree/assess" \
  -L "$tree" -lvoussoir -lm -Wl,-rpath,"$tree"
"$work/tree/assess" >"$work/tree/assess.log" || { cat "$work/tree/assess.log"; exit 1; }
tail -n 1 "$work/tree/assess.log"

step "Rust example: cargo run --example dome"
cargo run --quiet --locked --example dome | tail -n 3

printf '\ncmake-checks: all passed\n'
