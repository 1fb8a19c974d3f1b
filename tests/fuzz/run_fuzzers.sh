#!/bin/sh
# Builds the loader fuzz targets with clang-14's libFuzzer + AddressSanitizer
# (outside the gcc CMake build) and runs each for a bounded time.
# Usage: tests/fuzz/run_fuzzers.sh [seconds per target, default 30]
set -eu
secs=${1:-30}
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${FUZZ_OUT:-$root/build-fuzz}
mkdir -p "$out"
# Line tables are all a crash report's stack trace needs (file:line), and cheaper than -g.
flags="-std=c++20 -O1 -gline-tables-only -fno-omit-frame-pointer -DSAHARA_VERSION=\"fuzz\" -I$root/src -I/usr/include/opencv4"
# OBJ numbers are read in double, as in the CMake build (CMakeLists.txt gives the define
# to the OBJ sources only; here it reaches every loader source, where only those two use it).
flags="$flags -DTINYOBJLOADER_USE_DOUBLE"
libs="-ltinyobjloader_double -ltinygltf -ldraco -lmeshoptimizer -lOpenImageIO -lOpenImageIO_Util -ldl"
# Every OBJ and glTF source by pattern, so a loader split into a new file is linked too.
srcs="$(ls "$root"/src/io/obj_*.cpp "$root"/src/io/gltf_*.cpp | tr '\n' ' ')
      $root/src/io/model_loader.cpp $root/src/io/mesh_utils.cpp $root/src/io/image_bytes.cpp
      $root/src/io/files.cpp $root/src/base/log.cpp $root/src/base/pending_file.cpp"
# The image codec is linked in (not loaded as a plugin): the fuzzers reach it directly.
srcs="$srcs $root/src/io/image_io.cpp $root/src/io/image_codec.cpp $root/src/io/image_codec_oiio.cpp"

# The loader sources are the same in both targets: compile them once, as many at a
# time as there are cores (fuzzer-no-link: coverage instrumentation without a main).
echo "== compiling the loader sources"
mkdir -p "$out/obj"
# (The flags go through the environment: unquoted, they split into words and keep
# the literal quotes of SAHARA_VERSION, as on the link lines below.)
# shellcheck disable=SC2086,SC2016
printf '%s\n' $srcs | FUZZ_FLAGS="$flags" xargs -P "$(nproc)" -I{} sh -c \
    'clang++-14 $FUZZ_FLAGS -fsanitize=fuzzer-no-link,address -c "$1" -o "$2/obj/$(basename "$1" .cpp).o"' _ {} "$out"
objs=$(for s in $srcs; do printf '%s/obj/%s.o ' "$out" "$(basename "$s" .cpp)"; done)

status=0
for target in obj gltf; do
    echo "== building fuzz_$target"
    # shellcheck disable=SC2086
    clang++-14 $flags -fsanitize=fuzzer,address -o "$out/fuzz_$target" "$root/tests/fuzz/fuzz_$target.cpp" $objs $libs
    corpus="$out/corpus_$target"
    mkdir -p "$corpus"
    cp -n "$root/tests/fuzz/corpus_$target"/* "$corpus"/ 2>/dev/null || true
    echo "== running fuzz_$target for ${secs}s"
    if "$out/fuzz_$target" "$corpus" -max_total_time="$secs" -max_len=16384 -rss_limit_mb=2048 -timeout=10 \
        -artifact_prefix="$out/crash_${target}_" -print_final_stats=1 2>"$out/fuzz_$target.log"; then
        echo "fuzz_$target: no crash ($(grep -E '^stat::number_of_executed_units' "$out/fuzz_$target.log" | awk '{print $2}') runs," \
             "corpus $(ls "$corpus" | wc -l) files)"
    else
        status=1
        echo "fuzz_$target: FAILED, see $out/fuzz_$target.log and $out/crash_${target}_*"
        grep -E "ERROR|SUMMARY" "$out/fuzz_$target.log" | head -5
    fi
done
exit $status
