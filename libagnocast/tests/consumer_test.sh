#!/bin/sh
# Installs the library from the build tree into a scratch prefix, then builds
# and runs a tiny consumer with find_package and with pkg-config; the CMake
# consumer also generates its own message with agnocast_generate_messages()
# and links the allocation hook (agnocast::heaphook).
# usage: consumer_test.sh BUILD_DIR CONSUMER_SOURCE_DIR SCRATCH_DIR
set -eu
build=$1 source=$2 scratch=$3
rm -rf "$scratch"
mkdir -p "$scratch"
prefix=$scratch/prefix

# What libagnocast-dev and the libagnocast0 it depends on install.
for component in agnocast_runtime agnocast_library; do
  cmake --install "$build" --prefix "$prefix" --component "$component" >/dev/null
done

cmake -S "$source" -B "$scratch/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$scratch/cmake-build" >/dev/null
libdir=$(dirname "$(find "$prefix" -name 'libagnocast.so' | head -n1)")
LD_LIBRARY_PATH=$libdir "$scratch/cmake-build/consumer" | grep -q '^agnocast '
# The allocation hook, linked through its CMake target and preloaded by its file.
LD_LIBRARY_PATH=$libdir "$scratch/cmake-build/heap_consumer" | grep -qx 'heaphook active'
LD_LIBRARY_PATH=$libdir LD_PRELOAD=$libdir/libagnocast_heaphook.so "$scratch/cmake-build/consumer" | grep -q '^agnocast '

pcdir=$(dirname "$(find "$prefix" -name agnocast.pc | head -n1)")
export PKG_CONFIG_PATH=$pcdir
test "$(pkg-config --modversion agnocast)" = "$(LD_LIBRARY_PATH=$libdir "$scratch/cmake-build/consumer" | cut -d' ' -f2)"
# Exactly what pkg-config prints, the C++ standard included, plus the
# consumer's own message headers (generated for the CMake build above).
# shellcheck disable=SC2046 # pkg-config output is meant to be split
c++ -o "$scratch/consumer-pc" "$source/main.cpp" \
  -I"$scratch/cmake-build/agnocast_messages/consumer_msgs" $(pkg-config --cflags --libs agnocast)
LD_LIBRARY_PATH=$libdir "$scratch/consumer-pc" | grep -q '^agnocast '
echo "consumer builds with find_package and pkg-config"
