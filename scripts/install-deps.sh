#!/usr/bin/env bash
# Installs the Debian packages dispex builds against. Idempotent: quiet and quick when
# everything is already there. Uses sudo only when not root; never prompts.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libosd-dev libembree-dev libtbb-dev
  libdeflate-dev zlib1g-dev libfftw3-dev libxxhash-dev
  libfast-float-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libpng-dev libopenexr-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3-dev pybind11-dev python3-numpy python3-pytest mypy
  libjs-three  # three.js (r111), embedded into the pages `dispex view` writes
)
if [[ "${DISPEX_WITH_FORMAT:-0}" == 1 ]]; then
  packages+=(clang-format-14)
fi
# Chromium (headless, WebGL on SwiftShader) for the `browser` tests of `make test`: the pages
# `dispex view` writes, opened in a real browser (tests/view/browser_test.py).
if [[ "${DISPEX_WITH_BROWSER:-0}" == 1 ]]; then
  packages+=(chromium)
fi
# Blender (headless) for `make test-blender`: a real renderer displacing with the UV maps.
if [[ "${DISPEX_WITH_BLENDER:-0}" == 1 ]]; then
  packages+=(blender)
fi
if [[ "${DISPEX_WITH_SLURM:-0}" == 1 ]]; then
  packages+=(slurm-wlm munge)  # make test-slurm: a one-node cluster on localhost
fi
if [[ "${DISPEX_WITH_FUZZ:-0}" == 1 ]]; then
  packages+=(clang libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

if [[ $(id -u) -eq 0 ]]; then sudo=(); else sudo=(sudo); fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
