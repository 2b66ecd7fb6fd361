#!/usr/bin/env bash
# Builds and runs the consumer project (tests/consumer) against an installed Virtual Caliper:
#   cmake --install build --prefix PREFIX && tests/consumer/run.sh PREFIX
# 1. CMake: find_package(VirtualCaliper) from PREFIX, in a temporary folder outside the build tree;
# 2. pkg-config: the same program compiled with `pkg-config --cflags --libs virtual-caliper`;
# 3. when the prefix has the Python module: python3 -m caliper create from its site folder.
# Each loads PREFIX's open female model, creates an avatar from height and weight and writes a GLB.
set -euo pipefail
if [ $# -ne 1 ] || [ ! -d "$1" ]; then
  echo "usage: $0 PREFIX   (a folder that cmake --install filled)" >&2
  exit 2
fi
prefix=$(cd "$1" && pwd)
src=$(cd "$(dirname "$0")" && pwd)
model="$prefix/share/virtual-caliper/assets/models/caliper-female.npz"
[ -f "$model" ] || { echo "consumer: $model is missing: is $prefix an installed prefix?" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "consumer: CMake project against $prefix"
cmake -S "$src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF > "$work/configure.log" ||
  { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/build/consumer" "$model" "$work/cmake.glb"
test -s "$work/cmake.glb"

echo "consumer: pkg-config (virtual-caliper.pc) against $prefix"
pcdir=$(dirname "$(find "$prefix" -name virtual-caliper.pc -print -quit)")
[ -n "$pcdir" ] && [ "$pcdir" != . ] || { echo "consumer: no virtual-caliper.pc under $prefix" >&2; exit 1; }
flags=$(PKG_CONFIG_PATH="$pcdir${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}" pkg-config --cflags --libs virtual-caliper)
# shellcheck disable=SC2086  # the flags are words
c++ -std=c++17 -O1 "$src/main.cpp" -o "$work/consumer_pc" $flags
"$work/consumer_pc" "$model" "$work/pkgconfig.glb"
test -s "$work/pkgconfig.glb"
echo "consumer: both C++ builds ran against $prefix"

# 3. The Python module, if this prefix has it (CALIPER_BUILD_PYTHON): imported from the prefix's
#    site folder by Debian's python3, finding its models in PREFIX/share.
init=$(find "$prefix" -path '*-packages/caliper/__init__.py' -print -quit)
if [ -n "$init" ]; then
  site=$(dirname "$(dirname "$init")")
  echo "consumer: python3 -m caliper from $site"
  (cd "$work" && env -u CALIPER_ASSETS PYTHONPATH="$site" /usr/bin/python3 -m caliper create \
    --sex female --height 168cm --weight 62kg --out "$work/python.glb" --quiet)
  test -s "$work/python.glb"
  (cd "$work" && env -u CALIPER_ASSETS PYTHONPATH="$site" /usr/bin/python3 -c \
    "import caliper; assert caliper.assets_dir().startswith('$prefix'), caliper.assets_dir()")
  echo "consumer: the Python module ran from $prefix"
fi
