#!/usr/bin/env bash
# The crate's public items, read from rustdoc's index (target/doc/voussoir/all.html, written
# by `cargo doc`), must equal tests/public-api.txt: an internal item made public by accident,
# or a public one removed, fails here. VSR_BLESS=1 rewrites the list after a deliberate change.
set -euo pipefail
cd "$(dirname "$0")/.."
index=target/doc/voussoir/all.html
[ -f "$index" ] || { echo "error: $index missing: run cargo doc --no-deps first" >&2; exit 1; }
items=$(grep -oE 'href="[a-z_/]*(struct|enum|fn|constant|type|trait|macro|static|union)\.[A-Za-z0-9_]+\.html"' "$index" |
  sed -E 's/^href="//; s/\.html"$//' |
  awk -F/ '{ split($NF, k, "."); path = "voussoir"; for (i = 1; i < NF; i++) path = path "::" $i;
             print k[1] " " path "::" k[2] }' | sort -k2)
if [ "${VSR_BLESS:-}" = 1 ]; then
  printf '%s\n' "$items" > tests/public-api.txt
  echo "wrote tests/public-api.txt ($(wc -l < tests/public-api.txt) items)"
  exit 0
fi
if ! diff -u tests/public-api.txt <(printf '%s\n' "$items"); then
  echo "error: the public API differs from tests/public-api.txt (above: - listed, + public now)." >&2
  echo "If the change is deliberate, run: cargo doc --no-deps && VSR_BLESS=1 bash .ci/public-api.sh" >&2
  exit 1
fi
echo "public API: $(wc -l < tests/public-api.txt) items, as listed in tests/public-api.txt"
