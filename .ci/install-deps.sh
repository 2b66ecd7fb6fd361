#!/usr/bin/env bash
# Installs everything The Virtual Caliper needs from Debian 12 packages (run as root), plus the
# Khronos glTF validator and the reference VRM loader from the npm registry (pinned in
# tests/gltf/package-lock.json and tests/vrm/package-lock.json).
# Safe to run again: apt and npm skip what is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build pkg-config git clang clang-format clang-tidy libclang-rt-14-dev
  libeigen3-dev zlib1g-dev libminizip-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libassimp-dev libgtest-dev libgmock-dev libbenchmark-dev python3 python3-numpy python3-scipy
  python3-dev libpython3.11-dev python3-pytest pybind11-dev libcli11-dev libcsv-dev
  libgl-dev libglx-dev libglfw3-dev libxrandr-dev libx11-dev libxrender-dev x11proto-dev
  libglm-dev libimgui-dev libosmesa6-dev libmeshoptimizer-dev libopenxr-dev libopenxr-loader1
  libopenal-dev libavformat-dev libavcodec-dev libswscale-dev libavutil-dev
  xvfb xauth nodejs
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
# Some nodejs builds bundle npm; Debian's own nodejs needs the separate npm package.
if ! command -v npm >/dev/null 2>&1; then
  apt-get install -y -qq --no-install-recommends npm >/dev/null
fi
if [ -f tests/gltf/package.json ] && [ ! -d tests/gltf/node_modules/gltf-validator ]; then
  echo "install-deps: installing the Khronos glTF validator (npm ci)"
  (cd tests/gltf && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ -f tests/vrm/package.json ] && [ ! -d tests/vrm/node_modules/@pixiv/three-vrm ]; then
  echo "install-deps: installing the reference VRM loader @pixiv/three-vrm (npm ci)"
  (cd tests/vrm && npm ci --no-audit --no-fund --loglevel=error)
fi
echo "install-deps: all dependencies present"
