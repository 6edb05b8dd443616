#!/usr/bin/env bash
# The Python package (python/), run by .ci/test after `cargo test` (whose debug build of the
# formfind example is the Rust reference of the bit-for-bit tests):
#   1. a build venv with maturin builds the abi3 wheel (`maturin build --release`);
#   2. a fresh venv gets the wheel and pytest only (pip brings numpy): it imports, and pytest
#      runs every test, the shared models and the Rust reference required;
#   3. matplotlib and trimesh join that venv and the examples' tests run again, required.
# Work files go to $VSR_PYTHON_DIR (default target/python-checks).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
export CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-2}
work=${VSR_PYTHON_DIR:-$root/target/python-checks}
python=${PYTHON:-python3}
step() { printf '\n== %s\n' "$*"; }

# Debian's python3 has venv but not ensurepip without python3-venv.
if ! "$python" -c 'import ensurepip, venv' >/dev/null 2>&1; then
  # shellcheck source=.ci/apt.sh
  source .ci/apt.sh
  ensure_debian_packages python3-venv
fi
rm -rf "$work"
mkdir -p "$work"

step "build venv: maturin, then maturin build --release"
"$python" -m venv "$work/build-venv"
"$work/build-venv/bin/pip" install --quiet --disable-pip-version-check "maturin>=1.9.4,<2"
# The root target directory: the wheel's solver build shares what cargo already built there.
(cd python && CARGO_TARGET_DIR="$root/target" "$work/build-venv/bin/maturin" build --release \
  --locked --out "$work/wheels")

step "fresh venv: the wheel and pytest only"
"$python" -m venv "$work/venv"
"$work/venv/bin/pip" install --quiet --disable-pip-version-check "$work"/wheels/voussoir-*.whl pytest
"$work/venv/bin/pip" list --disable-pip-version-check --format=freeze
"$work/venv/bin/python" -c 'import voussoir; print("import voussoir", voussoir.__version__)'
formfind=${CARGO_TARGET_DIR:-$root/target}/debug/examples/formfind
[ -x "$formfind" ] || cargo build --locked --example formfind
# From a neutral directory, so that `voussoir` is the installed wheel, not python/voussoir.
(cd "$work" && VSR_REQUIRE_MODELS=1 VSR_FORMFIND="$formfind" \
  "$work/venv/bin/pytest" -q -p no:cacheprovider "$root/python/tests")

step "examples with matplotlib and trimesh"
"$work/venv/bin/pip" install --quiet --disable-pip-version-check matplotlib trimesh
(cd "$work" && VSR_REQUIRE_MODELS=1 VSR_REQUIRE_EXAMPLES=1 MPLBACKEND=Agg \
  "$work/venv/bin/pytest" -q -p no:cacheprovider "$root/python/tests/test_examples.py")
