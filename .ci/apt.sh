#!/usr/bin/env bash
# Sourced by .ci/test and .ci/cpp-tests.sh: `ensure_debian_packages PKG...` installs the Debian
# packages among PKG that are missing, with apt-get as root, through sudo for another user when
# sudo exists, and otherwise stops at once with the exact command to run, so that a test run
# never fails halfway for want of a package.

ensure_debian_packages() {
  if ! command -v dpkg-query >/dev/null; then
    echo "note: not a Debian system; make sure these are installed: $*" >&2
    return 0
  fi
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "Debian packages present: $*"
    return 0
  fi
  local install=(apt-get install -y --no-install-recommends "${missing[@]}")
  local as=(env) how="as root"
  if [ "$(id -u)" -ne 0 ]; then
    if ! command -v sudo >/dev/null; then
      echo "missing Debian packages: ${missing[*]}" >&2
      echo "run as root, then try again:  apt-get update && ${install[*]}" >&2
      exit 1
    fi
    as=(sudo env) how="with sudo"
  fi
  echo "installing ${missing[*]} ($how)"
  "${as[@]}" apt-get update
  "${as[@]}" DEBIAN_FRONTEND=noninteractive "${install[@]}"
}
